#include "app/simulate_job.hpp"

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <memory>
#include <set>
#include <sstream>
#include <stdexcept>

#include "audit/audit.hpp"
#include "runtime/allocation_matrix.hpp"
#include "runtime/attitude.hpp"
#include "derive/dynamics.hpp"
#include "derive/effects/effect_catalogue.hpp"
#include "runtime/flight_log.hpp"
#include "derive/geometry.hpp"
#include "fit/log_reader.hpp"
#include "fit/read_flight.hpp"
#include "runtime/ground_contact.hpp"
#include "runtime/integrator.hpp"
#include "app/model_registry.hpp"
#include "derive/runtime_view.hpp"
#include "runtime/rigid_body_state.hpp"
#include "runtime/scenarios.hpp"
#include "output/numbers.hpp"
#include "output/sinks.hpp"

namespace quadgen::app {

using namespace quadgen::runtime;

namespace {


void check_size(const SimulateJob& a, double steps, double rows) {
  if (a.no_size_limit) return;
  std::ostringstream os;
  if (steps > kMaxSteps) os << "about " << steps << " integration steps (limit " << kMaxSteps << ")";
  else if (rows > kMaxRows) os << "about " << rows << " output rows (limit " << kMaxRows << ")";
  else return;
  throw std::invalid_argument("--duration " + output::six_digits(a.duration) + ": " + os.str() +
                              "; shorten it, raise --step or lower --rate, or pass --no-size-limit");
}


// Where the vehicle file gives the tensor a body cannot have: for a tensor not positive
// definite the line of a product of inertia it gives (the usual culprit, a J_xy too large or
// of the wrong sign), for moments that break the triangle rule the line of a moment; else the
// other kind's line.
std::string where_file_gives_inertia(const Vehicle& v, bool moments_first) {
  const auto line_of_first = [&](std::initializer_list<const char*> names) {
    for (const char* name : names) {
      const auto it = v.derived_overrides.find(name);
      if (v.derived_given.count(name) && it != v.derived_overrides.end() && it->second.line > 0) return it->second.line;
    }
    return 0;
  };
  const int products = line_of_first({"J_xy", "J_xz", "J_yz"}), moments = line_of_first({"J_xx", "J_yy", "J_zz"});
  const int line = moments_first ? (moments ? moments : products) : (products ? products : moments);
  return output::printable(v.source_path) + (line ? ":" + std::to_string(line) : "");
}

// What only the --set values together with the others tell (a review): an inertia tensor no
// body has (a J_xy too large for the moments: the closed loop flew it until it was lost; the
// vehicle file's own too), and
// a thrust decay whose factor 1 - rate t reaches 0 within the flight (the rotors would pull).
std::string settings_problem(const SimulateJob& a, const Vehicle& v, const DynamicModel& m, const std::vector<double>& p) {
  const auto value = [&](const char* name) {
    const int i = m.param_index(name);
    return i < 0 ? 0.0 : p[static_cast<size_t>(i)];
  };
  // Judged whether or not --set touched it: a tensor the vehicle file's `derived:` gives is
  // only a warning in derive, and a closed loop flew it until it was lost (a review).
  const Mat3 J{{{value("J_xx"), value("J_xy"), value("J_xz")},
                {value("J_xy"), value("J_yy"), value("J_yz")},
                {value("J_xz"), value("J_yz"), value("J_zz")}}};
  const PrincipalMoments pm = principal_moments(J);
  if (!pm.positive || !pm.triangle) {
    const bool set = std::any_of(a.set.begin(), a.set.end(), [](const auto& s) { return s.first.rfind("J_", 0) == 0; });
    std::ostringstream os;
    os << (set ? "--set: with these values the inertia tensor's" : where_file_gives_inertia(v, pm.positive) + ": the inertia tensor's")
       << " principal moments are " << pm.moments[0] << ", " << pm.moments[1] << ", " << pm.moments[2] << " kg m²: "
       << (pm.positive ? "the largest exceeds the sum of the other two, which no mass distribution gives"
                       : "not positive definite (a product of inertia too large for the moments, or its sign?)");
    return os.str();
  }
  const double rate = value("thrust_decay.rate");
  if (a.duration > 0 && rate * a.duration >= 1)
    return "--set: thrust_decay.rate = " + output::short_number(rate) + " /s: the thrust factor 1 - rate t reaches 0 at t = " +
           output::short_number(1 / rate) + " s, within the flight (--duration " + output::short_number(a.duration) + " s)";
  return "";
}

// The --set values, each checked, in the model the simulation flies. A scenario's commands,
// its start and its thrust plot come from the vehicle file's values (its hover trim, motor
// map, c_t, vbat_ref), so there only an effect's parameters may be set: a base parameter set
// there would be half applied. A closed loop's controller believes the file, and the truth
// may differ in anything. No bounds of a fit apply (a test flight's truth may lie beyond
// them), but a value the physics cannot take is refused in every mode (Effect::domain), as is
// a delay as long as the flight (no command would act) and a name given twice.
void apply_settings(const SimulateJob& a, const Vehicle& v, DynamicModel& m) {
  std::vector<double> p = m.params();
  std::set<std::string> seen;
  for (const auto& [name, value] : a.set) {
    const int i = m.param_index(name);
    if (i < 0) {
      std::vector<std::string> settable;  // what the hint may offer: no name refused below
      for (const auto& n : m.param_names())
        if (a.closed_loop || is_effect_parameter(n)) settable.push_back(n);
      throw std::invalid_argument("--set: no parameter '" + output::printable(name) + "' in the model" +
                                  output::printable(missing_parameter_hint(name, settable)));
    }
    if (!seen.insert(name).second)
      throw std::invalid_argument("--set: '" + output::printable(name) + "' is given twice");
    if (!a.closed_loop && !is_effect_parameter(name))
      throw std::invalid_argument("--set " + output::printable(name) +
                                  ": a scenario or a replay takes its commands, start and plot from the vehicle "
                                  "file's values, so only an effect's parameters may be set there (edit the file, or "
                                  "fly --closed-loop)");
    std::string problem = runtime::value_problem(m.parameters()[static_cast<size_t>(i)], value, false);
    if (const std::string outside = outside_physical_domain(name, value); problem.empty() && !outside.empty())
      problem = "= " + output::short_number(value) + " " + outside;
    if (problem.empty() && name == "input_delay.seconds" && a.duration > 0 && value >= a.duration)
      problem = "= " + output::short_number(value) + " s is as long as the flight or longer (--duration " +
                output::short_number(a.duration) + " s): no command would act";
    if (!problem.empty()) throw std::invalid_argument("--set: " + output::printable(name) + " " + problem);
    p[i] = value;
  }
  if (const std::string problem = settings_problem(a, v, m, p); !problem.empty()) throw std::invalid_argument(problem);
  m.set_params(p);
}

// Said when the controller ran out of authority: a motor command at 0 or 1 in more than 1 %
// of the samples. Such samples fit poorly (an idle rotor is not in the model; diagnose and fit
// leave samples with a command at or below FlightOptions::min_command out), so the flight
// tells less than it seems.
std::string saturation_note(const GeneratedFlight& flight, const std::vector<std::string>& rotors) {
  std::vector<int> columns;
  for (const auto& r : rotors) columns.push_back(index_in(flight.columns, "u_" + r));
  size_t at_limit = 0;
  for (const auto& row : flight.rows)
    if (std::any_of(columns.begin(), columns.end(), [&](int c) { return row[c] <= 1e-3 || row[c] >= 1 - 1e-3; }))
      ++at_limit;
  const double share = flight.rows.empty() ? 0.0 : static_cast<double>(at_limit) / static_cast<double>(flight.rows.size());
  if (share <= 0.01) return "";
  std::ostringstream os;
  os.precision(3);
  os << "note: a motor command is at its limit (0 or 1) in " << 100 * share
     << " % of the samples: the controller ran out of authority there (a smaller --excitation, --amplitude or "
        "disturbance keeps it within reach); fit and diagnose leave out samples with a command at or below "
     << fit::FlightOptions{}.min_command;
  return os.str();
}

// A closed-loop test flight: the true model (effects and --set values) flown by a
// controller that believes the nominal base model.
SimulateJobResult run_closed_loop(const SimulateJob& a, const Vehicle& vehicle, const ControllerModel& belief,
                                  DynamicModel& truth) {
  SimulateJobResult result;
  const std::vector<std::string> rotors = rotor_names(vehicle);
  ClosedLoopOptions o = a.flight;
  o.duration = a.duration;
  std::ostringstream what;
  what << "flying " << a.duration << " s closed loop (seed " << o.seed << ")";
  a.progress.say(what.str());
  const GeneratedFlight flight = fly_closed_loop(truth, belief, rotors, o);
  result.csv = flight.csv();
  // Plot: position against reference, commands.
  auto col = [&](const std::string& n) {
    std::vector<double> v;
    const int c = index_in(flight.columns, n);
    for (const auto& r : flight.rows) v.push_back(r[c]);
    return v;
  };
  const auto t = col("t");
  Panel pos{"position and its reference", "t [s]", "m", {}};
  for (const char* n : {"x", "y", "z", "x_ref", "y_ref", "z_ref"}) pos.series.push_back({n, t, col(n)});
  Panel cmd{"motor commands", "t [s]", "1", {}};
  for (const auto& r : rotors) cmd.series.push_back({"u_" + r, t, col("u_" + r)});
  result.plot_title = vehicle.name + ": closed-loop test flight";
  result.plot = {pos, cmd};
  std::ostringstream summary;
  summary << "flew " << a.duration << " s closed loop";
  result.summary = summary.str();
  if (const std::string note = saturation_note(flight, rotors); !note.empty()) result.notes.push_back(note);
  return result;
}

// The allocation matrix of the vehicle's nominal model and its least-norm inverse (zero where
// the rotors cannot set the four apart: the audit warns of that, and nothing is taken out).
std::pair<Eigen::MatrixXd, Eigen::MatrixXd> allocation_and_inverse(const ControllerModel& belief) {
  const Eigen::MatrixXd A = runtime::allocation_matrix(belief);
  const Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod(A);
  if (cod.rank() < 4) return {A, Eigen::MatrixXd::Zero(A.cols(), 4)};
  return {A, cod.pseudoInverse()};
}

// Each rotor's hover thrust [N] (runtime::hover_trim: m g / n on a symmetric vehicle, a rotor
// off the symmetric place carrying more or less). Hover must be within every motor's reach, or
// no manoeuvre can be flown: said once, naming the vehicle file, instead of failing somewhere
// inside the flight.
std::vector<double> hover_thrusts(const Vehicle& v, const ControllerModel& belief) {
  const runtime::HoverTrim trim = runtime::hover_trim(belief, rotor_names(v));
  if (!trim.found()) throw std::invalid_argument(output::printable(v.source_path) + ": the vehicle cannot hover: " + trim.why_not);
  return trim.thrusts;
}

// What every open-loop simulation shares: the model, each rotor's thrust law, and the
// values its inputs need. Input functions refer to it, so it outlives the integration.
struct OpenLoop {
  DynamicModel& m;
  std::vector<ThrustLaw> laws;
  std::vector<std::string> rotors;
  std::vector<RotorPlace> places;  // where the rotors sit, for the tilt and yaw manoeuvres
  ExtraInputs extra;  // looked up once, not at every integrator stage
  int delay;          // the input_delay parameter, or -1
  double vbat_ref;    // V, the battery voltage where the log holds none
  double hover;       // N per rotor, m g / n: the thesis' manoeuvres are fractions of it
  std::vector<double> hover_trim;  // N, each rotor's own hover thrust (hover_thrusts)
  // The map from the rotors' thrusts to (thrust, roll, pitch, yaw) about the CoG, and its
  // least-norm inverse: what takes a manoeuvre's turn about an axis it does not mean out.
  Eigen::MatrixXd allocation, allocation_inverse;

  double delay_s() const { return delay >= 0 ? m.params()[delay] : 0.0; }
};

// The open-loop context of this vehicle, from the model flown and the controller's belief.
OpenLoop open_loop_context(DynamicModel& m, const Vehicle& vehicle, const ControllerModel& belief) {
  const double even_share =
      m.params()[m.param_index("mass")] * m.params()[m.param_index("g")] / static_cast<double>(vehicle.rotors.size());
  const auto [allocation, allocation_inverse] = allocation_and_inverse(belief);
  return OpenLoop{m,
                  belief.thrust_laws,
                  rotor_names(vehicle),
                  rotor_places(belief),
                  ExtraInputs(m),
                  m.input_delay_param(),
                  param(vehicle, "vbat_ref").nominal,
                  even_share,
                  hover_thrusts(vehicle, belief),
                  allocation,
                  allocation_inverse};
}

// `thrusts` less their change's part about the axes the manoeuvre does not mean (from the hover
// trim), with the least change of every rotor's thrust. Left as they are where that would ask
// a rotor for less than its command 0 gives or more than its command 1 (a rotor the trim holds
// at idle).
void take_out_unmeant_turn(const OpenLoop& k, const Scenario& s, Eigen::VectorXd& thrusts) {
  const Eigen::VectorXd trim = Eigen::Map<const Eigen::VectorXd>(k.hover_trim.data(), thrusts.size());
  Eigen::Vector4d unmeant = k.allocation * (thrusts - trim);
  for (int axis = 0; axis < 4; ++axis)
    if (s.changes[static_cast<size_t>(axis)]) unmeant(axis) = 0;
  const Eigen::VectorXd balanced = thrusts - k.allocation_inverse * unmeant;
  for (Eigen::Index i = 0; i < balanced.size(); ++i) {
    const ThrustLaw& law = k.laws[static_cast<size_t>(i)];
    if (!(balanced(i) >= law.thrust_at_command(0.0) && balanced(i) <= law.thrust_at_command(1.0))) return;
  }
  thrusts = balanced;
}

// A thesis manoeuvre: the thrusts it asks for at each (delayed) time, scaled by each rotor's
// own trim (1 on a symmetric vehicle), turned into commands by each rotor's law. The rotors a
// manoeuvre raises may also turn the vehicle about axes it does not mean: with uneven trims
// (a user trial: `yaw` rolled an H quad with its CoG off centre), or where the rule raises
// rotors of both spins (hexa_plus's `right` raises two ccw and one cw rotor, and yawed). That
// part is taken out. Where the raised rotors balance about the other axes (the FINken 3, the
// Crazyflie) it is zero, and the thrusts keep their bits.
InputFunction scenario_inputs(const OpenLoop& k, const Scenario& s) {
  return [&k, s](double t, double* u) {
    // About the even share m g / n; on a trimmed vehicle each rotor's thrust scaled by its trim,
    // so that a change of every rotor alike (climb) keeps the moments balanced.
    const auto F = s.thrust(t - k.delay_s(), k.hover, k.places);
    Eigen::VectorXd thrusts(static_cast<Eigen::Index>(F.size()));
    for (size_t i = 0; i < F.size(); ++i)
      thrusts(static_cast<Eigen::Index>(i)) = k.hover_trim[i] == k.hover ? F[i] : F[i] * (k.hover_trim[i] / k.hover);
    take_out_unmeant_turn(k, s, thrusts);
    for (size_t i = 0; i < F.size(); ++i) u[i] = k.laws[i].command_for(thrusts(static_cast<Eigen::Index>(i)));
    k.extra.fill(t, k.vbat_ref, u);
  };
}

// A manoeuvre whose rule picks no rotor of this vehicle (none on the side it raises: rotors in
// a line along x and `forward`) would fly as a hover and be written as the manoeuvre: refused
// (a review). Its schedule is looked at over 10 s, longer than any manoeuvre's. So is a flight
// that ends before the manoeuvre's first change (its input delay included).
void check_scenario_changes_a_rotor(const OpenLoop& k, const Scenario& s, const SimulateJob& a,
                                    const std::string& vehicle_path) {
  if (std::none_of(s.changes.begin(), s.changes.end(), [](bool c) { return c; })) return;  // hover
  const std::string what = "scenario '" + s.name + "' (" + s.description + ")";
  for (int i = 0; i <= 2000; ++i) {
    const double t = i / 200.0;  // s, in exact steps of 5 ms
    const auto F = s.thrust(t, k.hover, k.places);
    if (std::all_of(F.begin(), F.end(), [&](double f) { return f == k.hover; })) continue;
    const double first = t + k.delay_s();
    if (first < a.duration) return;
    throw std::invalid_argument("--duration " + output::short_number(a.duration) + " s ends before " + what +
                                " first changes a rotor, at " + output::short_number(first) + " s" +
                                (k.delay_s() > 0 ? " (its input delay included)" : "") +
                                ": it would fly as a hover; give a longer --duration");
  }
  throw std::invalid_argument(output::printable(vehicle_path) + ": " + what +
                              " changes no rotor of this vehicle: it would fly as a hover");
}

// The linearly interpolated battery voltage of a log, or nothing where it holds none.
std::shared_ptr<InputSignal> battery_signal(const CsvTable& log, const std::vector<double>& t) {
  if (log.column("vbat") < 0) return nullptr;
  std::vector<std::vector<double>> rows;
  for (double x : log.values("vbat")) rows.push_back({x});
  return std::make_shared<InputSignal>(t, rows, Interpolation::linear);
}

// A replay of a log's commands (and battery voltage), read through the job's mapping when it
// has one, as fit, diagnose and predict read logs; x0 takes the log's first pose where it has one.
InputFunction replay_inputs(const OpenLoop& k, const SimulateJob& a, const Vehicle& vehicle, std::vector<double>& x0) {
  const fit::ColumnMapping mapping = a.mapping.empty() ? fit::ColumnMapping{} : fit::load_mapping(a.mapping);
  const CsvTable log = fit::read_log(a.inputs, a.mapping.empty() ? nullptr : &mapping, 0);
  for (const auto& note : log.notes) a.progress.say(note);  // a topic slower than the grid, dropouts
  // The log's own motor places against the vehicle file's (fit/read_flight.hpp): a replay of
  // commands onto the wrong rotors flies another vehicle.
  for (const auto& note : fit::logged_rotor_notes(a.inputs, log.parameters, mapping, vehicle)) a.progress.say(note);
  // What a user may not guess when a column is missing: a log of another layout needs a mapping.
  validate_canonical(log, k.rotors,
                     a.mapping.empty() ? "; simulate --inputs reads a log in the canonical layout (t, u_<rotor>; "
                                         "docs/formats.md), or another through --mapping"
                                       : "");
  fit::check_euler_range(log);  // the start attitude; a command schedule may be sparse, so its time is not judged
  const std::vector<double> t = log.values("t");
  if (a.duration > t.back() - t.front() + 1e-9)
    throw std::invalid_argument("--duration " + output::six_digits(a.duration) + " s: " + output::printable(a.inputs) + " holds " +
                                output::six_digits(t.back() - t.front()) +
                                " s of commands; a longer replay would hold the last command for the rest");
  const size_t nr = k.rotors.size();
  std::vector<std::vector<double>> u(t.size(), std::vector<double>(nr));
  for (size_t r = 0; r < nr; ++r) {
    const auto col = log.values("u_" + k.rotors[r]);
    for (size_t i = 0; i < t.size(); ++i) u[i][r] = col[i];
  }
  const auto commands = std::make_shared<InputSignal>(t, u, a.interpolation == "linear" ? Interpolation::linear : Interpolation::hold);
  const auto vbat = battery_signal(log, t);
  if (k.m.input_index("vbat") >= 0 && !vbat) throw std::invalid_argument(a.inputs + ": battery_sag needs a 'vbat' column");
  for (int i = 0; i < rigid_body::kNumStates; ++i)  // start from the logged state where the log has it
    if ((i < rigid_body::kAttitude || i >= rigid_body::kAttitude + 4) && log.column(rigid_body::kStateNames[i]) >= 0)
      x0[i] = log.rows.front()[log.column(rigid_body::kStateNames[i])];
  // The attitude as a whole, as a quaternion or as Euler angles; part of one is a mistake
  // (a lone qw copied in would start from a rotation that is none), not a level start.
  if (const std::string partial = fit::incomplete_attitude(log); !partial.empty())
    throw LogError(log.where_named() + ": the start attitude needs " + fit::kAttitudeColumnSets + "; " + partial +
                   (a.mapping.empty() ? " (a log in another layout is read with --mapping)" : ""));
  if (const auto form = fit::attitude_columns(log); form != fit::AttitudeColumns::kNone) {
    const auto q = fit::logged_attitude(log, form, 0);
    std::copy(q.begin(), q.end(), x0.begin() + rigid_body::kAttitude);
    normalize_quaternion(&x0[rigid_body::kAttitude]);
  }
  const double t0 = t.front();
  return [&k, commands, vbat, t0](double tt, double* uu) {
    commands->at(t0 + tt, uu, k.delay_s());
    double vb_now = k.vbat_ref;
    if (vbat) vbat->at(t0 + tt, &vb_now);
    k.extra.fill(tt, vb_now, uu);
  };
}

// Rotor-speed states (motor_lag) start at their commanded steady state.
void start_rotor_speeds(const OpenLoop& k, const InputFunction& inputs, std::vector<double>& x0) {
  std::vector<double> u0(k.m.num_inputs());
  inputs(0.0, u0.data());
  for (size_t i = 0; i < k.rotors.size(); ++i) {
    const int w = runtime::rotor_speed_state(k.m, i);
    if (w >= 0) x0[w] = k.laws[i].speed_at(u0[i]);
  }
}

// The ground's height when the job asks for one: the start's, or the one given, which the
// start may not be below.
std::optional<double> ground_height(const SimulateJob& a, const std::vector<double>& x0) {
  const double z0 = x0[rigid_body::kPosition + 2];
  if (a.ground_at_start) return z0;
  if (a.ground_height && z0 < *a.ground_height - 1e-9) {
    std::ostringstream os;
    os << "--ground " << *a.ground_height << " m: the " << (a.scenario.empty() ? "replay" : "scenario")
       << " starts below it (z = " << z0 << " m"
       << (a.scenario.empty() ? "" : ": scenarios start at 0") << "); give the ground's height in the frame of "
       << (a.scenario.empty() ? "the log's positions (without one the start is z = 0)" : "the world") << ", or --ground start";
    throw std::invalid_argument(os.str());
  }
  return a.ground_height;
}

// RK4 at the fixed step; where it diverges and the rotors lag faster than the step can follow
// (a first-order lag leaves RK4's region of stability beyond step / tau = 2.78; a review: a
// --set motor_lag.tau of 1e-4 s at 1 ms ended in "w_A = 5.8e6"), the message says so.
Trajectory rk4_or_why_not(const SimulateJob& a, DynamicModel& m, const std::vector<double>& x0,
                          const InputFunction& inputs, const IntegratorOptions& io, Stats& stats) {
  try {
    return integrate_rk4(m, x0, inputs, 0.0, a.duration, io, &stats);
  } catch (const DivergenceError& e) {
    // The fastest rotor's time constant: the shared one scaled by 1 + its spread (a review: a
    // spread of -0.9999 diverged without this note).
    const int tau_index = m.param_index("motor_lag.tau");
    if (tau_index < 0) throw;
    double fastest = m.params()[static_cast<size_t>(tau_index)];
    const double shared = fastest;
    for (size_t i = 0; i < m.param_names().size(); ++i)
      if (m.param_names()[i].rfind("motor_lag_spread.", 0) == 0) fastest = std::min(fastest, shared * (1 + m.params()[i]));
    if (!(io.step > 2.5 * fastest)) throw;
    const std::string what =
        fastest < shared ? "the fastest rotor's time constant (motor_lag.tau times 1 + its spread) = " : "motor_lag.tau = ";
    throw DivergenceError(std::string(e.what()) + "; " + what + output::short_number(fastest) +
                          " s is too fast for RK4 at --step " + output::short_number(io.step) +
                          " s (stable to a step of about 2.5 tau): " +
                          (2.5 * fastest >= kMinStep ? "lower --step, or --integrator dopri5"
                                                     : "no step simulate takes follows it (a lag that short is none: leave motor_lag out)"));
  }
}

// The trajectory at the output rate: dopri5 stops at the output times, rk4 keeps every
// step that falls on one.
Trajectory integrate(const SimulateJob& a, DynamicModel& m, const std::vector<double>& x0, const InputFunction& inputs,
                     Stats& stats) {
  IntegratorOptions io;
  io.step = a.step;
  if (const auto ground = ground_height(a, x0)) io.constrain = GroundContact{*ground};
  std::vector<double> out_times;
  const long n_out = std::lround(a.duration * a.rate);
  for (long k = 0; k <= n_out; ++k) out_times.push_back(a.duration * static_cast<double>(k) / static_cast<double>(n_out));
  if (a.integrator == "dopri5") return integrate_dopri5(m, x0, inputs, out_times, io, &stats);
  const Trajectory full = rk4_or_why_not(a, m, x0, inputs, io, stats);
  Trajectory tr;
  const long every = std::max(1L, std::lround(1.0 / (a.rate * io.step)));
  for (size_t k = 0; k < full.t.size(); k += every) {
    tr.t.push_back(full.t[k]);
    tr.x.push_back(full.x[k]);
  }
  return tr;
}

// Plot like the thesis' figures: translation, rotation, thrust per rotor.
std::vector<Panel> simulation_plot(const OpenLoop& k, const SimulateJob& a, const Trajectory& tr,
                                   const InputFunction& inputs) {
  using namespace rigid_body;
  // The thrust law on the rotor speed; with effects (a gain, inflow, ground effect) the model's
  // thrust differs from it, and the title says so rather than showing the law as the model's.
  const std::string thrust_title =
      a.effects.empty() ? "thrust per rotor" : "thrust per rotor by the nominal law c_t rho A r^2 w^2 (effects not included)";
  Panel trans{"translation", "t [s]", "m", {}}, rot{"rotation", "t [s]", "deg", {}}, thrust{thrust_title, "t [s]", "N", {}};
  for (int i = 0; i < 3; ++i) {
    Series s{kStateNames[kPosition + i], tr.t, {}};
    for (const auto& x : tr.x) s.y.push_back(x[kPosition + i]);
    trans.series.push_back(s);
  }
  Series phi{"phi (roll)", tr.t, {}}, theta{"theta (pitch)", tr.t, {}}, psi{"psi (yaw)", tr.t, {}};
  for (const auto& x : tr.x) {
    const auto e = euler_angles(x.data());
    phi.y.push_back(e[0] * runtime::kDegreesPerRadian);
    theta.y.push_back(e[1] * runtime::kDegreesPerRadian);
    psi.y.push_back(e[2] * runtime::kDegreesPerRadian);
  }
  rot.series = {phi, theta, psi};
  std::vector<double> ub(k.m.num_inputs());
  for (size_t r = 0; r < k.rotors.size(); ++r) {
    Series s{"F_" + k.rotors[r], tr.t, {}};
    const int w = runtime::rotor_speed_state(k.m, r);
    for (size_t i = 0; i < tr.t.size(); ++i) {
      inputs(tr.t[i], ub.data());
      const double speed = w >= 0 ? tr.x[i][w] : k.laws[r].speed_at(ub[r]);
      s.y.push_back(k.laws[r].thrust_at_speed(speed));
    }
    thrust.series.push_back(s);
  }
  return {trans, rot, thrust};
}

// A scenario's or a replay's flight, open loop.
SimulateJobResult run_open_loop(const SimulateJob& a, const Vehicle& vehicle, const OpenLoop& k) {
  DynamicModel& m = k.m;
  if (!a.scenario.empty()) check_scenario_changes_a_rotor(k, find_scenario(a.scenario), a, vehicle.source_path);
  std::vector<double> x0(m.num_states(), 0.0);
  x0[rigid_body::kAttitude] = 1.0;
  const InputFunction inputs =
      a.scenario.empty() ? replay_inputs(k, a, vehicle, x0) : scenario_inputs(k, find_scenario(a.scenario));
  start_rotor_speeds(k, inputs, x0);
  Stats stats;
  std::ostringstream starting;
  starting << "simulating " << a.duration << " s of " << vehicle.name << " with " << a.integrator;
  if (const auto ground = ground_height(a, x0)) starting << " on a ground at z = " << *ground << " m";
  a.progress.say(starting.str());
  const Trajectory tr = integrate(a, m, x0, inputs, stats);

  SimulateJobResult result;
  result.csv = trajectory_csv(m, tr, inputs, k.rotors);
  const std::string what = a.scenario.empty() ? "replay of " + a.inputs : "scenario " + a.scenario;
  result.plot_title = vehicle.name + ": " + what;
  result.plot = simulation_plot(k, a, tr, inputs);
  const auto& xe = tr.x.back();
  std::ostringstream summary;
  summary << "simulated " << a.duration << " s (" << stats.rhs_evaluations << " rhs evaluations): final position ("
          << xe[rigid_body::kPosition] << ", " << xe[rigid_body::kPosition + 1] << ", " << xe[rigid_body::kPosition + 2]
          << ") m";
  result.summary = summary.str();
  return result;
}

// What a divergence may come from that the state it ends in cannot name: a --set value far
// beyond what its effect's physics produces (a review: wind.x = 1e300 ended in "state x = -nan").
std::string implausible_settings(const SimulateJob& a, const Vehicle& vehicle) {
  std::string out;
  for (const auto& [name, value] : a.set) {
    double lower = 0, upper = 0;
    std::string why;
    if (!outside_plausible_range(name, value, Environment::kUnknown, vehicle_scales(vehicle), &lower, &upper, &why))
      continue;
    out += (out.empty() ? "; outside its plausible range, --set " : ", ") + output::printable(name) + " = " +
           output::short_number(value) + " (plausible " + output::short_number(lower) + " to " +
           output::short_number(upper) + ": " + why + ")";
  }
  return out;
}

}  // namespace

bool SimulateJob::IsValid(std::string* error) const {
  const auto fail = [&](const std::string& why) {
    if (error) *error = why;
    return false;
  };
  if (!kDurationRange.contains(duration)) return fail("--duration: " + kDurationRange.text("s"));
  if (!kStepRange.contains(step)) return fail("--step: " + kStepRange.text("s"));
  if (!kRateRange.contains(rate)) return fail("--rate: " + kRateRange.text("Hz"));
  for (const auto& n : kFlightNumbers)
    if (!n.range.contains(flight.*n.field)) return fail(std::string(n.option) + ": " + n.range.text());
  if (ground_height && !(std::fabs(*ground_height) <= kMaxGroundHeight))
    return fail("--ground " + output::six_digits(*ground_height) + ": expected a height within +-" +
                output::six_digits(kMaxGroundHeight) + " m");
  return true;
}

SimulateJobResult run_simulate_job(const SimulateJob& a) {
  if (std::string error; !a.IsValid(&error)) throw std::invalid_argument(error);
  if (!a.closed_loop && a.scenario.empty() == a.inputs.empty())
    throw std::invalid_argument("give one of --scenario, --inputs or --closed-loop");
  if (!a.mapping.empty() && a.inputs.empty()) throw std::invalid_argument("--mapping reads an --inputs log: give one");
  const Vehicle vehicle = load_vehicle(a.vehicle);
  if (const std::string note = fitted_section_note(vehicle, "simulate"); !note.empty()) a.progress.say(note);
  if (a.closed_loop) check_size(a, 0, a.duration * a.flight.log_rate);
  else check_size(a, a.integrator == "rk4" ? a.duration / a.step : 0, a.duration * a.rate);
  DeriveOptions opt;
  opt.effects = parse_effect_list(a.effects);
  const SymbolicModel model = derive_model(vehicle, derive_mass_properties(vehicle), opt);
  const auto model_ptr = make_model(model);
  DynamicModel& m = *model_ptr;
  apply_settings(a, vehicle, m);  // before anything reads the parameters (the scenario's delay)
  // Flown as set (a test flight may mean it), but said before the flight rather than only after
  // a divergence: motor_gain.M3=0.93 meant as "93 %" flew a rotor at 193 % (a user trial).
  if (const std::string outside = implausible_settings(a, vehicle); !outside.empty())
    a.progress.say("note: flown as set, though" + outside.substr(1));
  // The nominal base model as a controller believes it: the scenarios' thrust laws, rotor
  // places, trim and allocation, and the closed loop's controller, all from this one.
  const ControllerModel belief = nominal_controller_belief(vehicle, model);
  const OpenLoop k = open_loop_context(m, vehicle, belief);  // also where a vehicle that cannot hover is said
  if (a.closed_loop && (a.ground_at_start || a.ground_height))
    throw std::invalid_argument("a ground is for a scenario or a replay; the closed-loop flight stays in the air");
  SimulateJobResult result;
  try {
    result = a.closed_loop ? run_closed_loop(a, vehicle, belief, m) : run_open_loop(a, vehicle, k);
  } catch (const DivergenceError& e) {
    const std::string cause = implausible_settings(a, vehicle);
    if (cause.empty()) throw;
    throw DivergenceError(e.what() + cause);
  }
  render_svg(result.plot_title, result.plot, &result.svg, &result.plot_error);
  return result;
}

}  // namespace quadgen::app
