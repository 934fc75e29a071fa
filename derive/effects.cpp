#include "effects.hpp"

#include <cmath>
#include <iomanip>
#include <set>
#include <sstream>
#include <stdexcept>

#include "kinematics.hpp"

namespace quadgen {
using namespace GiNaC;

namespace {

// Thrust of rotor i scaled by (1 + gain_i).
void motor_gain(ModelContext& c) {
  for (size_t i = 0; i < c.vehicle.rotors.size(); ++i) {
    const std::string n = c.vehicle.rotors[i].name;
    const ex g = c.add_param("motor_gain." + n, "1", 0.0, -0.5, 0.5, true,
                             "relative thrust error of rotor " + n);
    c.thrust_scale[i] = c.thrust_scale[i] * (1 + g);
  }
}

// First-order lag from commanded to actual rotor speed: tau dw/dt = w_cmd − w.
// The rotor speeds become states; started at w_cmd they reproduce the base model for
// any tau, and as tau -> 0 the trajectories converge to it (a singular perturbation),
// so the nominal tau is small rather than zero.
void motor_lag(ModelContext& c) {
  const ex tau = c.add_param("motor_lag.tau", "s", 1e-3, 1e-6, 1.0, true,
                             "time constant of the rotor speed response");
  for (size_t i = 0; i < c.vehicle.rotors.size(); ++i) {
    const std::string n = c.vehicle.rotors[i].name;
    const ex w = c.add_state("w_" + n, "rad/s", "rotor speed of rotor " + n);
    c.extra_rates.push_back((c.commanded_speed[i] - w) / tau);
    c.rotor_speed[i] = w;
  }
}

// A pure delay of the inputs. Not an ODE term: the runtime evaluates u(t − d) and
// the model only carries the parameter (see SymbolicModel::input_delay_param).
void input_delay(ModelContext& c) {
  c.add_param("input_delay.seconds", "s", 0.0, 0.0, 0.2, true,
              "time shift between logged commands and their effect");
  c.model.input_delay_param = c.model.params.size() - 1;
}

void cog_offset(ModelContext& c) {
  const ex dx = c.add_param("cog_offset.x", "m", 0.0, -0.05, 0.05, true, "CoG displacement x");
  const ex dy = c.add_param("cog_offset.y", "m", 0.0, -0.05, 0.05, true, "CoG displacement y");
  c.cog = c.cog.add(vec3(dx, dy, 0));
}

// Horizontal body force −k (Σ w_i) v_air,body,xy (rotor drag / induced drag, linear in
// airspeed and rotor speed), acting at the CoG: a pure force. The moment a multirotor feels
// in forward flight is blade_flapping's, with its own coefficient. Putting each rotor's share
// at its hub would tie the moment to the hub's height above the CoG, which the blocks give
// only roughly (8 mm on the Crazyflie file): fitted to real flights, the force then stood in
// for the flapping moment through that lever, or was rejected because the moment it forced
// conflicted with the gyro. With force and moment apart, their ratio is the effective point
// of action, estimated rather than assumed.
void rotor_drag(ModelContext& c) {
  const ex k = c.add_param("rotor_drag.k", "N s^2/m", 0.0, 0.0, 1e-3, true,
                           "rotor drag per rotor speed sum");
  const matrix vb = c.R.transpose().mul(c.air_velocity_world);
  ex speed_sum = 0;
  for (const ex& w : c.rotor_speed) speed_sum += w;
  c.extra_body_force = c.extra_body_force.add(vec3(-k * speed_sum * vb(0, 0), -k * speed_sum * vb(1, 0), 0));
}

// Moment from blade flapping: flying through the air tilts each rotor disc away from the
// relative wind, and the stiff hub of a small propeller passes the tilt to the body as a
// moment proportional to rotor speed and airspeed (blade flapping, as in Mahony, Kumar and
// Corke, "Multirotor Aerial Vehicles", IEEE Robotics & Automation Magazine 19(3), 2012).
// With its own coefficient rather than through an assumed hub height (see rotor_drag):
//   tau_body = k (sum of rotor speeds) (v_y, -v_x, 0), body-frame air velocity;
// k > 0 pitches the nose up when flying forward. Typical size: the NanoBench Crazyflie's
// residuals give 2-2.7e-4 N m per m/s at a rotor speed sum near 9,000 rad/s, k ~ 3e-8 N s^2
// (docs/crazyflie_evidence.md); no published Crazyflie value was found.
void blade_flapping(ModelContext& c) {
  const ex k = c.add_param("blade_flapping.k", "N s^2", 0.0, -1e-4, 1e-4, true,
                           "flapping moment per rotor speed sum and airspeed");
  const matrix vb = c.R.transpose().mul(c.air_velocity_world);
  ex speed_sum = 0;
  for (const ex& w : c.rotor_speed) speed_sum += w;
  c.extra_body_torque = c.extra_body_torque.add(vec3(k * speed_sum * vb(1, 0), -k * speed_sum * vb(0, 0), 0));
}

void wind(ModelContext& c) {
  const ex wx = c.add_param("wind.x", "m/s", 0.0, -10.0, 10.0, true, "steady wind x, world");
  const ex wy = c.add_param("wind.y", "m/s", 0.0, -10.0, 10.0, true, "steady wind y, world");
  c.air_velocity_world = c.air_velocity_world.sub(vec3(wx, wy, 0));
}

// Logged attitude = true attitude rotated by a fixed roll and pitch: q_log = q ⊗ q_bias.
void attitude_bias(ModelContext& c) {
  const ex roll = c.add_param("attitude_bias.roll", "rad", 0.0, -0.2, 0.2, true, "logged roll offset");
  const ex pitch = c.add_param("attitude_bias.pitch", "rad", 0.0, -0.2, 0.2, true, "logged pitch offset");
  const matrix q_bias = quaternion_product(axis_quaternion(1, pitch), axis_quaternion(0, roll));
  c.measured_q = quaternion_product(c.measured_q, q_bias);
}

void thrust_decay(ModelContext& c) {
  const ex rate = c.add_param("thrust_decay.rate", "1/s", 0.0, -0.05, 0.05, true,
                              "relative thrust loss per second");
  const ex t = c.add_input("t", "s", "time since the start of the log");
  for (ex& s : c.thrust_scale) s = s * (1 - rate * t);
}

void battery_sag(ModelContext& c) {
  const ex e = c.add_param("battery_sag.exponent", "1", 0.0, -1.0, 4.0, true,
                           "thrust ~ (vbat/vbat_ref)^exponent");
  const Parameter& ref = param(c.vehicle, "vbat_ref");
  const ex vref = c.add_param("vbat_ref", "V", ref.value, ref.value, ref.value, false, ref.doc);
  const ex vbat = c.add_input("vbat", "V", "battery voltage");
  for (ex& s : c.thrust_scale) s = s * pow(vbat / vref, e);
}

// Thrust near the ground scaled by 1/(1 − (R/4z)^2) (Cheeseman & Bennett 1955).
void ground_effect(ModelContext& c) {
  const ex radius = c.add_param("ground_effect.radius", "m", 0.0, 0.0, 0.5, true,
                                "rotor radius in the ground-effect law");
  const ex z = c.position(2, 0);
  for (ex& s : c.thrust_scale) s = s / (1 - pow(radius / (4 * z), 2));
}

// Thrust loss with inflow: air flowing through a rotor disc from above (the rotor climbing,
// or rising as the body rolls or pitches) lowers the blades' angle of attack, and the thrust
// at a given rotor speed falls; a descending rotor gains thrust. For an axial speed v_i
// small against the tip speed w_i r_p, blade-element theory with momentum inflow (Leishman,
// Principles of Helicopter Aerodynamics, 2nd ed., 2006, ch. 3) gives a thrust linear in
// the climb inflow ratio v_i / (w_i r_p):
//   F_i = c_t rho A_p r_p^2 w_i^2 (1 - k v_i / (w_i r_p)) = ... w_i (w_i - k v_i / r_p),
// with v_i the body-z speed of rotor i's hub through the air, (R^T v_air)_z + (omega x arm_i)_z.
// Its rotational part damps roll and pitch. Typical size: uniform-inflow BEMT at hover gives
// dC_T/C_T per unit climb ratio = 1 / (lambda_h + 16 lambda_h^2 / (sigma a)), lambda_h =
// sqrt(C_T / 2); for the Crazyflie (C_T ~ 0.02, solidity sigma ~ 0.1-0.15, lift slope
// a ~ 5.7 /rad, both assumed) k ~ 2.5-3.5: a 1 m/s climb at a 40 m/s tip speed costs ~7 %.
void inflow(ModelContext& c) {
  const ex k = c.add_param("inflow.k", "1", 0.0, -5.0, 20.0, true, "thrust loss per climb inflow ratio v / (w r_p)");
  const matrix vb = c.R.transpose().mul(c.air_velocity_world);
  for (size_t i = 0; i < c.rotor_speed.size(); ++i) {
    const matrix arm = c.rotor_position[i].sub(c.cog);
    const ex climb = vb(2, 0) + c.omega(0, 0) * arm(1, 0) - c.omega(1, 0) * arm(0, 0);  // (v + omega x arm)_z
    c.thrust_speed_loss[i] += k * climb / c.rotor_radius[i];
  }
}

}  // namespace

namespace {

// A number for a sentence: two significant digits (three at 100 and above), no exponent
// between 0.01 and 10,000.
std::string words(double v) {
  std::ostringstream os;
  const double a = std::fabs(v);
  if (a != 0 && (a < 0.01 || a >= 1e4)) os << std::setprecision(2) << v;
  else os << std::fixed << std::setprecision(a >= 100 ? 0 : a >= 10 ? 1 : a >= 1 ? 1 : 2) << v;
  return os.str();
}

double value_of(const std::map<std::string, double>& v, const std::string& name) {
  const auto it = v.find(name);
  return it == v.end() ? 0.0 : it->second;
}

std::string after_dot(const std::string& name) { return name.substr(name.find('.') + 1); }

// "Motor C gives 8.0 % less thrust than motor A; motor D 3.1 % more."
std::string motor_gain_headline(const std::map<std::string, double>& v, const std::string& reference) {
  std::ostringstream os;
  bool first = true;
  for (const auto& [name, g] : v) {
    os << (first ? "Motor " : "; motor ") << after_dot(name) << (first ? " gives " : " ") << words(100 * std::fabs(g))
       << " % " << (g < 0 ? "less" : "more") << (first ? " thrust" : "");
    if (first && !reference.empty()) os << " than motor " << after_dot(reference);
    first = false;
  }
  return os.str() + ".";
}

// Each effect's sentence in words, with the units a reader expects (ms, degrees, mm, %).
void set_headlines(std::vector<Effect>& list) {
  using Values = std::map<std::string, double>;
  const double deg = 180.0 / 3.14159265358979323846;
  const std::map<std::string, std::function<std::string(const Values&, const std::string&)>> sentences = {
      {"motor_gain", motor_gain_headline},
      {"motor_lag",
       [](const Values& v, const std::string&) {
         return "The rotors follow a new command with a time constant of " + words(1e3 * value_of(v, "motor_lag.tau")) +
                " ms.";
       }},
      {"input_delay",
       [](const Values& v, const std::string&) {
         return "Commands act " + words(1e3 * value_of(v, "input_delay.seconds")) + " ms after they are logged.";
       }},
      {"cog_offset",
       [](const Values& v, const std::string&) {
         const double x = 1e3 * value_of(v, "cog_offset.x"), y = 1e3 * value_of(v, "cog_offset.y");
         return "The centre of gravity sits " + words(std::fabs(x)) + " mm " + (x < 0 ? "behind" : "ahead of") +
                " and " + words(std::fabs(y)) + " mm " + (y < 0 ? "right" : "left") + " of where the blocks put it.";
       }},
      {"wind",
       [](const Values& v, const std::string&) {
         const double x = value_of(v, "wind.x"), y = value_of(v, "wind.y");
         return "A steady wind of " + words(std::hypot(x, y)) + " m/s (x " + words(x) + ", y " + words(y) +
                " m/s, world frame).";
       }},
      {"rotor_drag",
       [](const Values& v, const std::string&) {
         return "The rotors drag the vehicle back against its airspeed (k = " + words(value_of(v, "rotor_drag.k")) +
                " N s²/m per rad/s of summed rotor speed).";
       }},
      {"blade_flapping",
       [](const Values& v, const std::string&) {
         const double k = value_of(v, "blade_flapping.k");
         return std::string("Flying through the air ") + (k > 0 ? "pitches the nose up" : "pitches the nose down") +
                " (flapping moment k = " + words(k) + " N s² per rad/s of summed rotor speed and m/s of airspeed).";
       }},
      {"attitude_bias",
       [deg](const Values& v, const std::string&) {
         return "The logged attitude is off by " + words(deg * value_of(v, "attitude_bias.roll")) + "° in roll and " +
                words(deg * value_of(v, "attitude_bias.pitch")) + "° in pitch.";
       }},
      {"thrust_decay",
       [](const Values& v, const std::string&) {
         const double r = value_of(v, "thrust_decay.rate");
         return "Thrust " + std::string(r >= 0 ? "falls" : "rises") + " by " + words(100 * std::fabs(r)) +
                " % per second of flight (" + words(6000 * std::fabs(r)) + " % per minute).";
       }},
      {"battery_sag",
       [](const Values& v, const std::string&) {
         return "Thrust follows the battery voltage to the power " + words(value_of(v, "battery_sag.exponent")) + ".";
       }},
      {"ground_effect",
       [](const Values& v, const std::string&) {
         return "Near the ground thrust rises as for a rotor of radius " +
                words(1e3 * value_of(v, "ground_effect.radius")) + " mm.";
       }},
      {"inflow",
       [](const Values& v, const std::string&) {
         const double k = value_of(v, "inflow.k");
         return "Climbing costs thrust: each rotor loses " + words(k) +
                " times its climb-to-tip-speed ratio (a 1 m/s climb at a 40 m/s tip speed: " + words(100 * k / 40) +
                " %), which also damps roll and pitch.";
       }},
  };
  for (Effect& e : list) {
    const auto it = sentences.find(e.name);
    if (it == sentences.end()) throw std::logic_error("effect '" + e.name + "' has no headline");
    e.headline = it->second;
  }
}

// The catalogue, built one entry at a time so that each effect's facts sit together.
std::vector<Effect> build_catalogue() {
  std::vector<Effect> list;
  auto add = [&](std::string name, std::string meaning, std::function<void(ModelContext&)> apply) -> Effect& {
    list.push_back({std::move(name), std::move(meaning), std::move(apply)});
    return list.back();
  };
  using Scale = PlausibleRange::Scale;
  {
    Effect& e = add("motor_gain", "thrust of each rotor scaled by (1 + value)", motor_gain);
    e.first_parameter_is_reference = true;
    // The NanoBench flights of one Crazyflie trim their motors differently on every flight
    // (M4/M1 mean duty 1.03-1.20; docs/crazyflie_evidence.md).
    e.per_flight = true;
    e.plausible = {{"", -0.35, 0.35, Scale::kSI, Environment::kUnknown,
                    "motors of one type differ by up to ~20 % in thrust at one command, worn brushed motors by ~30 % "
                    "(the NanoBench trims reach a duty ratio of 1.2); beyond, a motor is broken or something else acts"}};
    e.look_alikes = {{"cog_offset",
                      "climb and descend at several thrust levels while hovering level: a CoG offset's torque grows "
                      "with total thrust on one axis, a weak motor's torque also shows in yaw (its reaction torque)"}};
  }
  {
    Effect& e = add("motor_lag", "first-order lag from commanded to actual rotor speed", motor_lag);
    e.typical_start = {{"motor_lag.tau", 0.03}};
    e.off_at_lower_bound = true;
    e.plausible = {{"motor_lag.tau", 0.0, 0.25, Scale::kSI, Environment::kUnknown,
                    "small electric motors respond in 20-100 ms (Crazyflie: 0.072 s, ARPL log authors)"}};
    e.look_alikes = {{"input_delay", "fast throttle steps or chirps (1-10 Hz): a lag rounds and attenuates the response, a "
                                     "delay shifts it without changing its shape"}};
  }
  {
    Effect& e = add("input_delay", "pure time shift between logged commands and their effect", input_delay);
    e.typical_start = {{"input_delay.seconds", 0.015}};
    e.plausible = {{"input_delay.seconds", 0.0, 0.1, Scale::kSI, Environment::kUnknown,
                    "logging and radio latencies are one to a few control periods (10-50 ms)"}};
  }
  add("cog_offset", "centre of gravity displaced from the body origin in x, y", cog_offset).plausible = {
      {"", -0.2, 0.2, Scale::kRotorArm, Environment::kUnknown,
       "a centre of gravity a fifth of the rotor arm off centre needs one motor at ~1.5x its opposite's thrust to "
       "hover level: visible at a glance"}};
  // wind first among the airspeed effects: rotor_drag and blade_flapping act on the
  // air-relative velocity it changes.
  {
    Effect& e = add("wind", "steady air velocity in the world frame, through the drag terms", wind);
    e.per_flight = true;
    e.plausible = {{"", -0.5, 0.5, Scale::kSI, Environment::kIndoor,
                    "indoors the air is still but for ventilation drafts of a few dm/s"},
                   {"", -15.0, 15.0, Scale::kSI, Environment::kUnknown,
                    "small multirotors are not flown beyond about Beaufort 6-7 (11-15 m/s)"}};
  }
  add("rotor_drag", "horizontal body force -k (sum of rotor speeds) v_body,xy", rotor_drag).look_alikes = {
      {"blade_flapping", "straight legs at several constant speeds: rotor drag slows the vehicle (a horizontal force), "
                         "flapping only tilts it (a moment the attitude loop must hold)"}};
  add("blade_flapping", "body moment k (sum of rotor speeds) (v_y, -v_x, 0) on the body-frame airspeed", blade_flapping);
  {
    Effect& e = add("attitude_bias", "logged attitude = true attitude rotated by roll and pitch", attitude_bias);
    // Vicon attitude and IMU differ by 0.5-2.3 degrees in roll and pitch, by flight (the
    // marker frame is fitted per session; docs/crazyflie_evidence.md).
    e.per_flight = true;
    e.plausible = {{"", -0.052, 0.052, Scale::kSI, Environment::kUnknown,
                    "an IMU or marker frame misaligned by more than ~3 degrees is visible by eye and corrected"}};
    e.look_alikes = {{"wind", "hover while turning through a full yaw circle: an attitude bias turns with the body, a "
                              "steady wind stays fixed in the world"}};
  }
  {
    Effect& e = add("thrust_decay", "all thrust scaled by (1 - rate (t - t_start))", thrust_decay);
    e.plausible = {{"thrust_decay.rate", -1e-4, 5e-3, Scale::kSI, Environment::kUnknown,
                    "a LiPo from full to the end of a flight loses 15-30 % of thrust over minutes; half the thrust "
                    "in 100 s (0.5 %/s) is beyond any battery that still flies"}};
    e.look_alikes = {{"battery_sag", "a flight whose battery voltage does not fall linearly in time (e.g. throttle bursts)"}};
  }
  {
    Effect& e = add("battery_sag", "thrust scaled by (vbat / vbat_ref)^exponent", battery_sag);
    e.needs = EffectNeeds::kBatteryVoltage;
    e.plausible = {{"battery_sag.exponent", 0.0, 3.0, Scale::kSI, Environment::kUnknown,
                    "at a fixed duty cycle rotor speed grows about with voltage and thrust with its square: ~2"}};
  }
  {
    Effect& e = add("ground_effect", "thrust scaled by 1 / (1 - (R / 4 z)^2) near the ground", ground_effect);
    e.needs = EffectNeeds::kPose;
    e.typical_start = {{"ground_effect.radius", 0.05}};
    e.plausible = {{"ground_effect.radius", 0.0, 3.0, Scale::kRotorRadius, Environment::kUnknown,
                    "the Cheeseman-Bennett law's R is the rotor radius; several rotors side by side act like a "
                    "somewhat larger one"}};
  }
  {
    Effect& e = add("inflow", "thrust lowered by k (climb speed of each rotor through the air) / (tip speed)", inflow);
    e.plausible = {{"inflow.k", 0.0, 8.0, Scale::kSI, Environment::kUnknown,
                    "blade-element theory with momentum inflow gives 1 / (lambda_h + 16 lambda_h^2 / (sigma a)): "
                    "about 1-6 for small rotors; negative would mean thrust grows with climb"}};
    e.look_alikes = {{"thrust_decay", "climbs and descents at several speeds at one battery state: inflow follows the "
                                      "climb rate, a decay follows the clock"}};
  }
  set_headlines(list);
  return list;
}

}  // namespace

const std::vector<Effect>& effect_catalogue() {
  static const std::vector<Effect> list = build_catalogue();
  return list;
}

const Effect& find_effect(const std::string& name) {
  for (const auto& e : effect_catalogue())
    if (e.name == name) return e;
  throw std::invalid_argument("unknown effect '" + name + "'");
}

std::string effect_of_parameter(const std::string& parameter) {
  const auto dot = parameter.find('.');
  return dot == std::string::npos ? std::string() : parameter.substr(0, dot);
}

std::vector<std::string> reference_parameters(const std::vector<std::string>& names) {
  std::vector<std::string> out;
  std::set<std::string> seen;
  for (const auto& n : names) {
    const std::string e = effect_of_parameter(n);
    if (e.empty() || !seen.insert(e).second) continue;
    if (find_effect(e).first_parameter_is_reference) out.push_back(n);
  }
  return out;
}

double off_value(const Variable& p) {
  const std::string e = effect_of_parameter(p.name);
  return !e.empty() && find_effect(e).off_at_lower_bound ? p.lower : p.nominal;
}

Environment parse_environment(const std::string& text) {
  if (text == "indoor") return Environment::kIndoor;
  if (text == "outdoor") return Environment::kOutdoor;
  if (text == "unknown" || text.empty()) return Environment::kUnknown;
  throw std::invalid_argument("unknown environment '" + text + "' (expected indoor, outdoor or unknown)");
}

std::string environment_name(Environment e) {
  return e == Environment::kIndoor ? "indoor" : e == Environment::kOutdoor ? "outdoor" : "unknown";
}

bool plausible_range(const std::string& parameter, Environment where, const VehicleScales& scales, double* lower,
                     double* upper, std::string* why) {
  const std::string effect = effect_of_parameter(parameter);
  if (effect.empty()) return false;
  // The best match: a range for this environment over one for any, then one for this
  // parameter over one for all of the effect's.
  const PlausibleRange* found = nullptr;
  int best = -1;
  for (const auto& r : find_effect(effect).plausible) {
    if (!r.parameter.empty() && r.parameter != parameter) continue;
    if (r.only_in != Environment::kUnknown && r.only_in != where) continue;
    const int rank = (r.only_in == where && where != Environment::kUnknown ? 2 : 0) + (r.parameter.empty() ? 0 : 1);
    if (rank > best) best = rank, found = &r;
  }
  if (!found) return false;
  const double unit = found->scale == PlausibleRange::Scale::kRotorArm      ? scales.rotor_arm
                      : found->scale == PlausibleRange::Scale::kRotorRadius ? scales.rotor_radius
                                                                            : 1.0;
  *lower = found->lower * unit;
  *upper = found->upper * unit;
  *why = found->why;
  return true;
}

std::vector<std::string> parse_effect_list(const std::string& text) {
  std::vector<std::string> out;
  if (text.empty()) return out;
  if (text == "all") {
    for (const auto& e : effect_catalogue()) out.push_back(e.name);
    return out;
  }
  std::set<std::string> known, seen;
  for (const auto& e : effect_catalogue()) known.insert(e.name);
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    if (!known.count(item)) {
      std::string list;
      for (const auto& e : effect_catalogue()) list += (list.empty() ? "" : ", ") + e.name;
      throw std::invalid_argument("unknown effect '" + item + "' (known: " + list + ", or all)");
    }
    if (!seen.insert(item).second) throw std::invalid_argument("effect '" + item + "' named twice");
    out.push_back(item);
  }
  return out;
}

std::string canonical_effect_list(const std::vector<std::string>& effects) {
  std::string out;
  for (const auto& e : effect_catalogue())
    if (std::find(effects.begin(), effects.end(), e.name) != effects.end()) out += (out.empty() ? "" : ",") + e.name;
  return out;
}

}  // namespace quadgen
