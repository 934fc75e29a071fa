#include "derive/dynamics.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iterator>
#include <optional>
#include <set>
#include <stdexcept>
#include <utility>

#include "runtime/thrust_law.hpp"
#include "runtime/rigid_body_state.hpp"
#include "derive/effects/effect_catalogue.hpp"
#include "derive/exact_number.hpp"
#include "derive/kinematics.hpp"
#include "output/numbers.hpp"
#include "output/sinks.hpp"
#include "derive/symbolic_functions.hpp"

namespace quadgen {
using namespace GiNaC;

namespace {

std::string tex_of(const std::string& name) {
  // "motor_gain.A" -> "\mathrm{motor\_gain.A}"; short names keep math italics.
  static const std::map<std::string, std::string> greek = {
      {"rho", "\\rho"}, {"kappa", "\\kappa"}, {"c_w", "c_w"}, {"c_t", "c_t"}, {"g", "g"},
      {"mass", "m"},    {"p", "p"},           {"q", "q"},     {"r", "r"}};
  auto it = greek.find(name);
  if (it != greek.end()) return it->second;
  return "\\mathrm{" + output::latex_math_text(name) + "}";
}

Variable make_variable(const std::string& name, const std::string& unit, const std::string& doc) {
  Variable v;
  v.name = name;
  v.sym = symbol(name, tex_of(name));
  v.unit = unit;
  v.dim = parse_unit(unit).dim;
  v.doc = doc;
  return v;
}


// A value outside [lower, upper] to 6 digits, or to more where 6 would read as inside.
std::string outside_text(double x, double lower, double upper) {
  char buf[32];
  for (int digits = 6; digits <= 17; ++digits) {
    std::snprintf(buf, sizeof buf, "%.*g", digits, x);
    const double shown = std::strtod(buf, nullptr);
    if (!(shown >= lower && shown <= upper)) break;
  }
  return buf;
}

// The vehicle file's `derived:` entry for a quantity, against what the blocks give.
void check_derived_bounds(const Vehicle& v, const std::string& name, const std::string& unit, double value,
                          const Parameter& declared) {
  if (value >= declared.lower && value <= declared.upper) return;
  const std::string where = declared.line > 0 ? ":" + std::to_string(declared.line) : "";
  throw VehicleError(v.source_path + where + ": derived quantity " + name + ": the blocks give " +
                     outside_text(value, declared.lower, declared.upper) + " " + unit +
                     ", outside its bounds [" + shortest_text(declared.lower) + ", " + shortest_text(declared.upper) +
                     "]" + unit_slip(v, name, value, declared));
}

// The rotor speed a command asks for: the motor map a0 + a1 u + a2 u^2, turned about its
// speed at the pivot command by `slope` when the vehicle file gives one. A stand's map holds
// the stand's battery sag in its slope; the slope at the airframe's operating point can
// then be fitted without moving the speed there, on which the speed-proportional effects
// (rotor drag, blade flapping) and the thrust constant rest.
// `pivot`: the constant motor_pivot, or nothing without a slope.
ex commanded_rotor_speed(const ModelContext& c, const ex& u, const std::optional<ex>& pivot) {
  const auto map = [&](const ex& x) { return runtime::motor_map(c.p("motor_a0"), c.p("motor_a1"), c.p("motor_a2"), x); };
  if (!pivot) return map(u);
  return map(*pivot) + c.p("motor_slope") * (map(u) - map(*pivot));
}

// The thirteen rigid-body states' units and meanings, in runtime::rigid_body's order.
constexpr const char* kStateUnitsAndMeanings[runtime::rigid_body::kNumStates][2] = {
    {"m", "position x, world"},     {"m", "position y, world"},     {"m", "position z (up), world"},
    {"m/s", "velocity x, world"},   {"m/s", "velocity y, world"},   {"m/s", "velocity z, world"},
    {"1", "attitude quaternion w"}, {"1", "attitude quaternion x"}, {"1", "attitude quaternion y"},
    {"1", "attitude quaternion z"}, {"rad/s", "body rate about x"}, {"rad/s", "body rate about y"},
    {"rad/s", "body rate about z"}};

// The vehicle file's scalar keys and the model's names for them (the motor map's terms carry
// "motor_"). `slope` is optional and comes with its pivot.
constexpr std::pair<const char*, const char*> kScalarParameters[] = {
    {"g", "g"},         {"rho", "rho"},     {"c_w", "c_w"},     {"c_t", "c_t"},        {"kappa", "kappa"},
    {"a0", "motor_a0"}, {"a1", "motor_a1"}, {"a2", "motor_a2"}, {"slope", "motor_slope"}};

// The values of kDerivedQuantities (model/vehicle.hpp), in its order.
std::vector<double> derived_values(const MassProperties& mp) {
  const auto& J = mp.inertia_cog_value;
  return {mp.mass_value,     mp.cog_value[0],   mp.cog_value[1],   mp.cog_value[2], J[0][0],
          J[1][1],           J[2][2],           J[0][1],           J[0][2],         J[1][2],
          mp.areas_value[0], mp.areas_value[1], mp.areas_value[2]};
}

// The rigid body's states, in the runtime's order (runtime/rigid_body_state.hpp), and the
// kinematic quantities built from them.
void declare_rigid_body(ModelContext& c) {
  using namespace runtime::rigid_body;
  std::vector<ex> s;
  for (int i = 0; i < kNumStates; ++i)
    s.push_back(c.add_state(kStateNames[i], kStateUnitsAndMeanings[i][0], kStateUnitsAndMeanings[i][1]));
  const auto block3 = [&](int first) { return vec3(s[first], s[first + 1], s[first + 2]); };
  c.position = block3(kPosition);
  c.velocity = block3(kVelocity);
  c.q = quaternion(s[kAttitude], s[kAttitude + 1], s[kAttitude + 2], s[kAttitude + 3]);
  c.omega = block3(kBodyRate);
  c.R = rotation_from_quaternion(c.q);
  c.measured_q = c.q;
  c.air_velocity_world = c.velocity;
  c.extra_body_force = vec3(0, 0, 0);
  c.extra_body_torque = vec3(0, 0, 0);
}

// The vehicle file's scalar parameters, then the mass properties derived from the blocks as
// parameters with those nominal values, so that a fit may free them and the generated code
// precomputes J^-1 once. Declared bounds must hold the value the blocks give: a fit would
// start outside them.
void declare_parameters(ModelContext& c, const MassProperties& mp) {
  for (const auto& [key, name] : kScalarParameters) {
    if (!c.vehicle.params.count(key)) continue;  // slope: optional, with its pivot
    ParameterSpec spec = param(c.vehicle, key);  // the record without its file line
    spec.name = name;
    c.add_param(spec);
  }
  auto derived = [&](const std::string& name, const std::string& unit, double value, const std::string& doc) {
    if (!std::isfinite(value))  // blocks of 1e200 kg or m: the integrals overflow a double
      throw VehicleError(c.vehicle.source_path + ": derived quantity " + name + " is not finite (" + shortest_text(value) +
                         " " + unit + "): a block's mass or size is too large to compute with");
    auto it = c.vehicle.derived_overrides.find(name);
    if (it != c.vehicle.derived_overrides.end()) {
      const bool given = c.vehicle.derived_given.count(name) > 0;  // the file's value, not the blocks'
      if (given) value = it->second.nominal;
      else check_derived_bounds(c.vehicle, name, unit, value, it->second);
      c.add_param(name, unit, value, it->second.lower, it->second.upper, it->second.fit,
                  given ? doc + " (given in the vehicle file, not the blocks')" : doc);
    } else
      c.add_param(name, unit, value, value, value, false, doc);
  };
  const std::vector<double> values = derived_values(mp);
  static_assert(std::size(kDerivedQuantities) == 13, "derived_values lists thirteen values");
  for (size_t i = 0; i < values.size(); ++i)
    derived(kDerivedQuantities[i].name, kDerivedQuantities[i].unit, values[i], kDerivedQuantities[i].meaning);
  c.cog = vec3(c.p("cog_x"), c.p("cog_y"), c.p("cog_z"));
}

// Each rotor's geometry as constants and its speed as the motor map commands it; the
// effects' per-rotor factors start neutral.
void declare_rotors(ModelContext& c) {
  std::optional<ex> pivot;
  if (c.vehicle.params.count("slope"))
    pivot = c.add_constant("motor_pivot", "1", param(c.vehicle, "pivot").nominal,
                           "command about which motor_slope turns the motor map");
  for (size_t i = 0; i < c.vehicle.rotors.size(); ++i) {
    const Rotor& r = c.vehicle.rotors[i];
    const std::string n = r.name;
    // A rotor's numbers are named "<rotor>.x" ..., an effect's parameters "<effect>.x": a rotor
    // named after an effect would share names with its parameters (a red-team review: the
    // derivation read cog_offset.y - cog_offset.y for a rotor's y and the CoG offset's, and
    // `--set cog_offset.z` was answered for the wrong one). Refused with every model, so that
    // no diagnosis stops when its search reaches the effect.
    if (effect_named(n))
      throw VehicleError(c.vehicle.source_path + (r.line > 0 ? ":" + std::to_string(r.line) : "") + ": rotor name '" + n +
                         "' is the name of an effect, whose parameters are named '" + n +
                         ".<name>' as the rotor's position is: rename the rotor (e.g. '" + n + "_rotor')");
    c.rotor_disc_area.push_back(c.add_constant(n + ".A_p", "m^2", r.disc_area, "thrust-law area of rotor " + n + " (its disc_area)"));
    c.rotor_radius.push_back(c.add_constant(n + ".r_p", "m", r.radius, "propeller radius of rotor " + n));
    // One statement each: the order of a call's arguments is unspecified, and it is the
    // order of the constants in the model (GCC declared z, y, x; another compiler x, y, z).
    const ex x = c.add_constant(n + ".x", "m", r.position[0], "rotor " + n + " position x");
    const ex y = c.add_constant(n + ".y", "m", r.position[1], "rotor " + n + " position y");
    const ex z = c.add_constant(n + ".z", "m", r.position[2], "rotor " + n + " position z");
    c.rotor_position.push_back(vec3(x, y, z));
    const ex u = c.model.inputs[i].sym;
    const ex w = commanded_rotor_speed(c, u, pivot);
    c.commanded_speed.push_back(w);
    c.rotor_speed.push_back(w);
    c.thrust_scale.push_back(1);
    c.thrust_speed_loss.push_back(0);
    c.lag_factor.push_back(1);
  }
}

// States, inputs (one command per rotor), parameters and rotors, in the order the generated
// code numbers them.
void declare_base(ModelContext& c, const MassProperties& mp) {
  declare_rigid_body(c);
  for (const Rotor& r : c.vehicle.rotors)
    c.add_input("u_" + r.name, "1", "motor command of rotor " + r.name + ", throttle fraction 0 to 1 (not clamped here)");
  declare_parameters(c, mp);
  declare_rotors(c);
}

// J^-1 = adj(J) / det(J) written out. GiNaC's matrix::inverse() normalises its result,
// and the shape of a normalised expression depends on GiNaC's internal term order
// (symbol serial numbers and address-based hash seeds), which would make generated code
// differ between runs.
matrix inverse_by_adjugate(const matrix& J) {
  auto cof = [&](int i, int j) {
    const int r0 = (i + 1) % 3, r1 = (i + 2) % 3, c0 = (j + 1) % 3, c1 = (j + 2) % 3;
    return J(r0, c0) * J(r1, c1) - J(r0, c1) * J(r1, c0);
  };
  const ex det = J(0, 0) * cof(0, 0) + J(0, 1) * cof(0, 1) + J(0, 2) * cof(0, 2);
  matrix inv(3, 3);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) inv(i, j) = cof(j, i) / det;
  return inv;
}

matrix inertia_matrix(const ModelContext& c) {
  const ex xx = c.p("J_xx"), yy = c.p("J_yy"), zz = c.p("J_zz");
  const ex xy = c.p("J_xy"), xz = c.p("J_xz"), yz = c.p("J_yz");
  return matrix(3, 3, lst{xx, xy, xz, xy, yy, yz, xz, yz, zz});
}

// Rotor i's thrust at rotor speed w: the thrust law (runtime/thrust_law.hpp) with what the
// effects did to it, a factor (a motor gain, ground effect) and a speed lost to inflow.
ex rotor_thrust(const ModelContext& c, size_t i, const ex& w) {
  const ex k = runtime::rotor_thrust_coefficient<ex>(c.p("c_t"), c.p("rho"), c.rotor_disc_area[i], c.rotor_radius[i]);
  return c.thrust_scale[i] * k * w * (w - c.thrust_speed_loss[i]);
}

// Rotor i's moment about the CoG from its thrust: the thrust's moment on its arm, and the
// reaction torque, which opposes the spin (a ccw rotor, seen from above, pushes the body
// along -z).
matrix rotor_torque(const ModelContext& c, size_t i, const ex& thrust) {
  const int reaction = -spin_sign(c.vehicle.rotors[i]);
  const matrix arm = c.rotor_position[i].sub(c.cog);
  return cross(arm, vec3(0, 0, thrust)).add(vec3(0, 0, reaction * c.p("kappa") * thrust));
}

// Frame drag per body axis, 1/2 c_w rho A v|v|, on the air-relative velocity (body axes).
matrix frame_drag(const ModelContext& c, const ex (&v_air_body)[3]) {
  const char* areas[] = {"A_x", "A_y", "A_z"};
  matrix drag(3, 1);
  for (int k = 0; k < 3; ++k)
    drag(k, 0) = -numeric(1, 2) * c.p("c_w") * c.p("rho") * c.p(areas[k]) * v_air_body[k] * abs_value(v_air_body[k]);
  return drag;
}

// The report's equations (SymbolicModel::named_equations): the same physics as assemble()
// below, built once more with each earlier quantity as a named symbol. The symbols' names
// are those of the effect formulas (omega_<rotor>, v_ax), so both read alike.
void write_named_equations(const ModelContext& c, const matrix& v_air_body) {
  auto& out = c.model.named_equations;
  const auto& rotors = c.vehicle.rotors;
  out.push_back({"v_a", v_air_body, ""});
  // An effect's factor of a thrust (inflow's climb rate through the disc, ground effect) stays
  // written out: GiNaC multiplies a number into the sum v_a is, so it cannot be found again there.
  std::vector<ex> thrust;
  for (size_t i = 0; i < rotors.size(); ++i) {
    const std::string n = output::latex_math_text(rotors[i].name);
    const symbol w("omega_" + rotors[i].name, "\\omega_{\\mathrm{" + n + "}}");
    out.push_back({"\\omega_{\\mathrm{" + n + "}}", c.rotor_speed[i], ""});
    out.push_back({rotor_thrust_name(rotors[i].name), rotor_thrust(c, i, w), ""});
    thrust.push_back(symbol("F_" + rotors[i].name, rotor_thrust_name(rotors[i].name)));
  }
  for (size_t i = 0; i < rotors.size(); ++i)
    out.push_back({"\\tau_{\\mathrm{" + output::latex_math_text(rotors[i].name) + "}}", rotor_torque(c, i, thrust[i]), ""});
  const ex va[3] = {symbol("v_ax", "v_{a,x}"), symbol("v_ay", "v_{a,y}"), symbol("v_az", "v_{a,z}")};
  out.push_back({"F_{drag}", frame_drag(c, va), ""});
  const bool extra_force = !c.extra_body_force.is_zero_matrix(), extra_torque = !c.extra_body_torque.is_zero_matrix();
  out.push_back({"F_{body}", 0, "e_z \\sum_i F_i + F_{drag}" + std::string(extra_force ? " + \\Delta F_{body}" : "")});
  out.push_back({"\\tau", 0, "\\sum_i \\tau_i" + std::string(extra_torque ? " + \\Delta \\tau" : "")});
}

struct BodyLoads {
  matrix force, torque;  // body frame, about the CoG
};

// The rotors' thrust and torque, the frame drag and the effects' extra force and torque,
// each recorded among the model's named intermediates.
BodyLoads body_loads(ModelContext& c) {
  SymbolicModel& m = c.model;
  const auto& rotors = c.vehicle.rotors;
  matrix force_body = c.extra_body_force;
  matrix torque = c.extra_body_torque;
  ex total_thrust = 0;
  for (size_t i = 0; i < rotors.size(); ++i) {
    const Rotor& r = rotors[i];
    const ex thrust = rotor_thrust(c, i, c.rotor_speed[i]);
    m.intermediates.push_back({rotor_thrust_name(r.name), thrust});
    total_thrust += thrust;
    torque = torque.add(rotor_torque(c, i, thrust));
  }
  force_body = force_body.add(vec3(0, 0, total_thrust));
  const matrix v_air_body = c.R.transpose().mul(c.air_velocity_world);
  const ex va[3] = {v_air_body(0, 0), v_air_body(1, 0), v_air_body(2, 0)};
  const matrix drag = frame_drag(c, va);
  force_body = force_body.add(drag);
  m.intermediates.push_back({"F_{drag}", drag});
  m.intermediates.push_back({"F_{body}", force_body});
  m.intermediates.push_back({"\\tau", torque});
  write_named_equations(c, v_air_body);
  return {force_body, torque};
}

// Translation: the world acceleration of the body origin at angular acceleration `w_dot`. The
// CoG obeys m a_cg = R F_b − m g e_z; the origin is offset from it by −c, so
// a_o = a_cg − R(ω̇ × c + ω × (ω × c)).
matrix origin_acceleration(ModelContext& c, const matrix& force_body, const matrix& w_dot) {
  const matrix transport = cross(w_dot, c.cog).add(cross(c.omega, cross(c.omega, c.cog)));
  const matrix accel_body = force_body.mul_scalar(1 / c.p("mass")).sub(transport);
  return c.R.mul(accel_body).sub(vec3(0, 0, c.p("g")));
}

// What a log measures of the state: the position and the attitude as logged.
void declare_pose_outputs(ModelContext& c) {
  SymbolicModel& m = c.model;
  const char* out[][3] = {{"x", "m", "position x"}, {"y", "m", "position y"}, {"z", "m", "position z"},
                          {"qw", "1", "logged attitude w"}, {"qx", "1", "logged attitude x"},
                          {"qy", "1", "logged attitude y"}, {"qz", "1", "logged attitude z"}};
  m.h = matrix(7, 1);
  for (int i = 0; i < 7; ++i) {
    m.outputs.push_back(make_variable(out[i][0], out[i][1], out[i][2]));
    m.h(i, 0) = i < 3 ? c.position(i, 0) : c.measured_q(i - 3, 0);
  }
}

// Closes the equations once every effect has had its say.
void assemble(ModelContext& c) {
  SymbolicModel& m = c.model;
  const BodyLoads loads = body_loads(c);
  // Rotation about the centre of gravity: J dω/dt = τ − ω × Jω.
  const matrix J = inertia_matrix(c);
  const matrix Jinv = inverse_by_adjugate(J);
  const matrix omega_dot = Jinv.mul(loads.torque.sub(cross(c.omega, J.mul(c.omega))));
  const matrix accel_world = origin_acceleration(c, loads.force, omega_dot);
  const matrix q_dot = quaternion_rate(c.q, c.omega);

  const size_t n = m.states.size();
  m.f = matrix(n, 1);
  namespace rb = runtime::rigid_body;
  for (unsigned i = 0; i < 3; ++i) {
    m.f(rb::kPosition + i, 0) = c.velocity(i, 0);
    m.f(rb::kVelocity + i, 0) = accel_world(i, 0);
    m.f(rb::kBodyRate + i, 0) = omega_dot(i, 0);
  }
  for (unsigned i = 0; i < 4; ++i) m.f(rb::kAttitude + i, 0) = q_dot(i, 0);
  for (unsigned i = 0; i < c.extra_rates.size(); ++i) m.f(rb::kNumStates + i, 0) = c.extra_rates[i];
  for (const ex& w : c.rotor_speed)
    for (size_t i = 0; i < n; ++i)
      if (w.is_equal(m.states[i].sym)) m.rotor_speed_states.push_back(i);

  m.omega_dot = {symbol("omegadot_x"), symbol("omegadot_y"), symbol("omegadot_z")};
  const matrix accel_split = origin_acceleration(c, loads.force, vec3(m.omega_dot[0], m.omega_dot[1], m.omega_dot[2]));
  m.f_split = m.f;
  for (unsigned i = 0; i < 3; ++i) m.f_split(rb::kVelocity + i, 0) = accel_split(i, 0);
  declare_pose_outputs(c);
}

}  // namespace

// A total far beyond what its bounds expect is most often a unit slip in the blocks: masses
// in grams written as kilograms scale the mass and the inertia by 1000, sizes and positions
// in millimetres written as metres the inertia and the areas by a million. Said with the
// block that gives most of the mass, or, where one block a thousandth as heavy would put the
// mass within its bounds, with that block; "" otherwise. `expected`: the bounds' geometric mean.
std::string unit_slip(const Vehicle& v, const std::string& name, double value, const Parameter& declared) {
  if (!(declared.lower > 0) || !(value > 0)) return "";
  const double ratio = value / std::sqrt(declared.lower * declared.upper);
  const auto near = [&](double factor) { return ratio > factor / 3 && ratio < factor * 3; };
  const bool inertia = name.rfind("J_", 0) == 0, area = name.rfind("A_", 0) == 0;
  if ((inertia || area) && near(1e6))
    return " (about a million times the bounds: block sizes or positions in millimetres written as metres?)";
  // One block in grams among blocks in kilograms: the total within the bounds with that block
  // a thousandth (a newcomer's trial, helper-143: a battery of 7.1 "kg" was pointed at the
  // bounds' line alone).
  // Only where the total is far beyond the bounds (three times the upper or more): a total
  // just over them is no slip of a thousand.
  if (name == "mass" && value >= 3 * declared.upper)
    for (const auto& b : v.blocks)
      if (const double fixed = value - b.mass + b.mass / 1000; fixed >= declared.lower && fixed <= declared.upper)
        return " (block '" + output::printable(b.name) + "'" + (b.line > 0 ? " at line " + std::to_string(b.line) : "") +
               " has " + shortest_text(b.mass) + " kg: in grams? With " + output::six_digits(b.mass / 1000) +
               " kg the mass would be within its bounds)";
  if ((name != "mass" && !inertia) || !near(1e3)) return "";
  const Block* heaviest = nullptr;
  for (const auto& b : v.blocks)
    if (!heaviest || b.mass > heaviest->mass) heaviest = &b;
  std::string said = " (about 1000 times the bounds: masses in grams written as kilograms?";
  if (heaviest)
    said += " The heaviest block, '" + output::printable(heaviest->name) + "'" +
            (heaviest->line > 0 ? " at line " + std::to_string(heaviest->line) : "") + ", has " +
            shortest_text(heaviest->mass) + " kg";
  return said + ")";
}


symbol ModelContext::add_param(const ParameterSpec& spec) {
  Variable v;
  static_cast<ParameterSpec&>(v) = spec;
  v.sym = symbol(spec.name, tex_of(spec.name));
  model.params.push_back(v);
  return v.sym;
}
symbol ModelContext::add_param(const std::string& name, const std::string& unit, double nominal,
                               double lower, double upper, bool fit, const std::string& doc) {
  return add_param(ParameterSpec{name, unit, parse_unit(unit).dim, nominal, lower, upper, fit, doc, ""});
}
symbol ModelContext::add_state(const std::string& name, const std::string& unit, const std::string& doc) {
  model.states.push_back(make_variable(name, unit, doc));
  return model.states.back().sym;
}
symbol ModelContext::add_input(const std::string& name, const std::string& unit, const std::string& doc) {
  model.inputs.push_back(make_variable(name, unit, doc));
  return model.inputs.back().sym;
}
symbol ModelContext::add_constant(const std::string& name, const std::string& unit, double value,
                                  const std::string& doc) {
  Variable v = make_variable(name, unit, doc);
  v.nominal = v.lower = v.upper = value;
  model.constants.push_back(v);
  return v.sym;
}
ex ModelContext::p(const std::string& name) const { return model.params[model.param_index(name)].sym; }

std::string SymbolicModel::effect_list(const std::string& separator) const {
  std::string out;
  for (const auto& e : effects) out += (out.empty() ? "" : separator) + e;
  return out;
}

size_t SymbolicModel::state_index(const std::string& n) const {
  for (size_t i = 0; i < states.size(); ++i)
    if (states[i].name == n) return i;
  throw std::out_of_range("no state " + n);
}
size_t SymbolicModel::param_index(const std::string& n) const {
  for (size_t i = 0; i < params.size(); ++i)
    if (params[i].name == n) return i;
  throw std::out_of_range("no parameter " + n);
}
size_t SymbolicModel::input_index(const std::string& n) const {
  for (size_t i = 0; i < inputs.size(); ++i)
    if (inputs[i].name == n) return i;
  throw std::out_of_range("no input " + n);
}
const ex& SymbolicModel::intermediate(const std::string& n) const {
  for (const auto& [name, e] : intermediates)
    if (name == n) return e;
  throw std::out_of_range("no intermediate " + n);
}
lst SymbolicModel::nominal_substitution() const {
  lst l;
  for (const auto& p : params) l.append(p.sym == exact(p.nominal));
  return l;
}
lst SymbolicModel::constant_substitution() const {
  lst l;
  for (const auto& c : constants) l.append(c.sym == exact(c.nominal));
  return l;
}

// df/dv = ∂f_split/∂v + Σ_k ∂f_split/∂ω̇_k · dω̇_k/dv, with dω̇_k/dv the Jacobian's own rows
// 10-12 (computed first: those rows do not contain ω̇), and ω̇ put back into the small
// partial derivatives only.
void differentiate(SymbolicModel& m) {
  const lst constants = m.constant_substitution();
  const matrix f = ex_to<matrix>(ex(m.f_split).subs(constants)), h = ex_to<matrix>(ex(m.h).subs(constants));
  exmap omega_dot_value;
  for (int k = 0; k < 3; ++k) omega_dot_value[m.omega_dot[k]] = f(10 + k, 0);
  matrix dfdw(f.rows(), 3);  // ∂f_i/∂ω̇_k, ω̇ put back
  for (unsigned i = 0; i < f.rows(); ++i)
    for (int k = 0; k < 3; ++k) dfdw(i, k) = f(i, 0).diff(m.omega_dot[k]).subs(omega_dot_value);
  auto jac = [&](const std::vector<Variable>& vars) {
    matrix J(f.rows(), vars.size());
    for (size_t j = 0; j < vars.size(); ++j) {
      for (unsigned i = 10; i < 13; ++i) J(i, j) = f(i, 0).diff(vars[j].sym);
      for (unsigned i = 0; i < f.rows(); ++i) {
        if (i >= 10 && i < 13) continue;
        ex d = f(i, 0).diff(vars[j].sym).subs(omega_dot_value);
        for (unsigned k = 0; k < 3; ++k)
          if (!dfdw(i, k).is_zero()) d += dfdw(i, k) * J(10 + k, j);
        J(i, j) = d;
      }
    }
    return J;
  };
  auto plain_jac = [](const matrix& g, const std::vector<Variable>& vars) {
    matrix J(g.rows(), vars.size());
    for (unsigned i = 0; i < g.rows(); ++i)
      for (size_t j = 0; j < vars.size(); ++j) J(i, j) = g(i, 0).diff(vars[j].sym);
    return J;
  };
  m.dfdx = jac(m.states);
  m.dfdu = jac(m.inputs);
  m.dfdp = jac(m.params);
  m.dhdx = plain_jac(h, m.states);
  m.dhdp = plain_jac(h, m.params);
}

// An effect's own formula: the effect applied alone to a fresh base model, each intermediate
// quantity it changes written as an equation. Shown in body axes: R is the identity and the
// air velocity the symbols v_a (so a drag term reads -k (sum of w) v_a,x, not a page of
// quaternion products). Per-rotor quantities are shown for the first rotor; the others are alike.
SymbolicModel::EffectFormula effect_formula(const Vehicle& v, const MassProperties& mp, const Effect& e) {
  SymbolicModel scratch;
  ModelContext c{v, scratch};
  declare_base(c, mp);
  c.R = matrix(3, 3, lst{1, 0, 0, 0, 1, 0, 0, 0, 1});
  // One declarator each (a call's argument order is the compiler's; GCC created z first).
  const symbol v_az("v_az", "v_{a,z}"), v_ay("v_ay", "v_{a,y}"), v_ax("v_ax", "v_{a,x}");
  c.air_velocity_world = vec3(v_ax, v_ay, v_az);
  // Rotor speeds as symbols rather than the motor map, and a level vehicle (q = 1), so that
  // an attitude bias shows as the rotation it applies.
  for (size_t i = 0; i < v.rotors.size(); ++i) {
    const std::string n = output::latex_math_text(v.rotors[i].name);
    c.rotor_speed[i] = symbol("omega_" + v.rotors[i].name, "\\omega_{\\mathrm{" + n + "}}");
    c.commanded_speed[i] = symbol("wcmd_" + v.rotors[i].name, "\\omega_{\\mathrm{cmd},\\mathrm{" + n + "}}");
  }
  c.measured_q = quaternion(1, 0, 0, 0);
  const ModelContext before = c;
  const size_t rates_before = c.extra_rates.size();
  e.apply(c);
  SymbolicModel::EffectFormula f{e.name, {}, ""};
  const auto changed = [](const matrix& a, const matrix& b) { return !(a.sub(b)).is_zero_matrix(); };
  const std::string r0 = v.rotors.empty() ? std::string() : output::latex_math_text(v.rotors[0].name);
  // "\omega" -> "\omega_{\mathrm{M1}}", with a subscript already there ("loss") joined to it.
  const auto rotor = [&](const std::string& base, const std::string& sub = "") {
    return base + "_{" + (sub.empty() ? "" : sub + ",") + "\\mathrm{" + r0 + "}}";
  };
  if (!v.rotors.empty()) {
    if (!(c.thrust_scale[0] - before.thrust_scale[0]).is_zero())
      f.lines.push_back({"\\text{thrust factor } " + rotor("s"), c.thrust_scale[0]});
    if (!(c.thrust_speed_loss[0] - before.thrust_speed_loss[0]).is_zero())
      f.lines.push_back({"\\text{thrust speed loss } " + rotor("\\omega", "\\mathrm{loss}"), c.thrust_speed_loss[0]});
    if (!(c.lag_factor[0] - before.lag_factor[0]).is_zero())
      f.lines.push_back({"\\text{time constant factor } " + rotor("f", "\\tau"), c.lag_factor[0]});
    if (!(c.rotor_speed[0] - before.rotor_speed[0]).is_zero())
      f.lines.push_back({"\\text{rotor speed } " + rotor("\\omega"), c.rotor_speed[0]});
  }
  if (c.extra_rates.size() > rates_before)
    f.lines.push_back({"\\frac{d}{dt}" + tex_of(scratch.states[scratch.states.size() - (c.extra_rates.size() - rates_before)].name),
                       c.extra_rates[rates_before]});
  if (changed(c.cog, before.cog)) f.lines.push_back({"\\Delta c", c.cog.sub(before.cog)});
  if (changed(c.air_velocity_world, before.air_velocity_world))
    f.lines.push_back({"\\Delta v_{a}\\ \\text{(world axes)}", c.air_velocity_world.sub(before.air_velocity_world)});
  if (changed(c.extra_body_force, before.extra_body_force))
    f.lines.push_back({"\\Delta F_{body}", c.extra_body_force.sub(before.extra_body_force)});
  if (changed(c.extra_body_torque, before.extra_body_torque))
    f.lines.push_back({"\\Delta \\tau", c.extra_body_torque.sub(before.extra_body_torque)});
  if (changed(c.measured_q, before.measured_q)) {
    f.lines.push_back({"q_{\\mathrm{logged}}", c.measured_q});
    f.note = "for a level vehicle, q = 1; in general q_logged = q * that quaternion";
  }
  if (scratch.input_delay_param)
    f.note = "no term of f: the runtime feeds the commands delayed, u(t - " +
             scratch.params[*scratch.input_delay_param].name + ")";
  else if (v.rotors.size() > 1 && (!(c.thrust_scale[0] - before.thrust_scale[0]).is_zero() ||
                                   !(c.rotor_speed[0] - before.rotor_speed[0]).is_zero() ||
                                   !(c.thrust_speed_loss[0] - before.thrust_speed_loss[0]).is_zero() ||
                                   !(c.lag_factor[0] - before.lag_factor[0]).is_zero()))
    f.note = "shown for rotor " + v.rotors[0].name + "; every rotor alike";
  return f;
}

SymbolicModel derive_model(const Vehicle& v, const MassProperties& mp, const DeriveOptions& opt) {
  SymbolicModel m;
  m.vehicle_name = v.name;
  m.vehicle_hash = v.content_hash;
  std::set<std::string> wanted;
  for (const auto& e : opt.effects)
    if (!wanted.insert(e).second) throw std::invalid_argument("effect '" + e + "' named twice");
  ModelContext c{v, m};
  declare_base(c, mp);
  for (const Effect& e : effect_catalogue()) {
    if (!wanted.count(e.name)) continue;
    e.apply(c);
    m.effects.push_back(e.name);
    m.effect_formulas.push_back(effect_formula(v, mp, e));
    wanted.erase(e.name);
  }
  if (!wanted.empty()) throw std::invalid_argument("unknown effect '" + *wanted.begin() + "'");
  for (const std::string& e : refinements_without_their_effect(m.effects)) {
    const std::string& refined = find_effect(e).refines;
    throw std::invalid_argument("effect '" + e + "' scales " + refined + "'s terms and changes nothing without it: add " +
                                refined + " too");
  }
  add_terms(c, opt.terms);
  assemble(c);
  differentiate(m);
  return m;
}

std::string rotor_thrust_name(const std::string& rotor) {
  return "F_{\\mathrm{" + output::latex_math_text(rotor) + "}}";  // a rotor called front_left stays one subscript
}

std::vector<std::string> base_parameter_names() {
  std::vector<std::string> names;
  for (const auto& scalar : kScalarParameters) names.push_back(scalar.second);
  for (const auto& derived : kDerivedQuantities) names.push_back(derived.name);
  return names;
}

}  // namespace quadgen
