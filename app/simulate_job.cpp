#include "app/simulate_job.hpp"

#include <cmath>
#include <iostream>
#include <memory>
#include <sstream>
#include <stdexcept>

#include "runtime/attitude.hpp"
#include "derive/dynamics.hpp"
#include "derive/effects/effect_catalogue.hpp"
#include "runtime/flight_log.hpp"
#include "derive/geometry.hpp"
#include "runtime/integrator.hpp"
#include "app/model_registry.hpp"
#include "codegen/runtime_bridge.hpp"
#include "runtime/scenarios.hpp"
#include "output/sinks.hpp"

namespace quadgen::app {

using namespace quadgen::runtime;

namespace {

// Work beyond these sizes is refused before it starts unless --no-size-limit is given: each
// stored sample costs ~0.2 kB, so 1e7 of them is about 2 GB.
constexpr double kMaxSteps = 1e7, kMaxRows = 1e7;

void check_size(const SimulateJob& a, double steps, double rows) {
  if (a.no_size_limit) return;
  std::ostringstream os;
  if (steps > kMaxSteps) os << "about " << steps << " integration steps (limit " << kMaxSteps << ")";
  else if (rows > kMaxRows) os << "about " << rows << " output rows (limit " << kMaxRows << ")";
  else return;
  throw std::invalid_argument("--duration " + std::to_string(a.duration) + ": " + os.str() +
                              "; shorten it, raise --step or lower --rate, or pass --no-size-limit");
}


// A closed-loop test flight: the true model (effects and --set values) flown by a
// controller that believes the nominal base model.
SimulateJobResult run_closed_loop(const SimulateJob& a, const Vehicle& vehicle, const SymbolicModel& model,
                                  DynamicModel& truth) {
  SimulateJobResult result;
  std::vector<double> p = truth.params();
  for (const auto& [name, value] : a.set) {
    const int i = truth.param_index(name);
    if (i < 0) throw std::invalid_argument("--set: no parameter '" + output::printable(name) + "' in the model (add its effect with --effects)");
    p[i] = value;
  }
  truth.set_params(p);
  const ControllerModel belief = nominal_controller_belief(vehicle, model);
  const std::vector<std::string> rotors = rotor_names(vehicle);
  ClosedLoopOptions o = a.flight;
  o.duration = a.duration;
  std::cerr << "flying " << a.duration << " s closed loop (seed " << o.seed << ")\n";
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
  return result;
}

// Hover must be within reach of every rotor's motor map, or no manoeuvre can be flown; said
// once, naming the vehicle file, instead of failing somewhere inside the flight.
void check_hover_reachable(const Vehicle& v, const std::vector<ThrustLaw>& laws, double hover_thrust) {
  for (size_t i = 0; i < laws.size(); ++i) try {
      laws[i].command_for(hover_thrust);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(v.source_path + ": rotor " + v.rotors[i].name + " cannot hover: " + e.what() +
                                  "; check c_t (rotor_model) and a0, a1, a2 (motor_map)");
    }
}

}  // namespace

SimulateJobResult run_simulate_job(const SimulateJob& a) {
  if (!a.closed_loop && a.scenario.empty() == a.inputs.empty())
    throw std::invalid_argument("give one of --scenario, --inputs or --closed-loop");
  const Vehicle vehicle = load_vehicle(a.vehicle);
  if (a.closed_loop) check_size(a, 0, a.duration * a.flight.log_rate);
  else check_size(a, a.integrator == "rk4" ? a.duration / a.step : 0, a.duration * a.rate);
  DeriveOptions opt;
  opt.effects = parse_effect_list(a.effects);
  const SymbolicModel model = derive_model(vehicle, derive_mass_properties(vehicle), opt);
  const auto model_ptr = make_model(model);
  DynamicModel& m = *model_ptr;
  const size_t nr = vehicle.rotors.size();
  const auto laws = nominal_thrust_laws(vehicle, model);
  const double vbat_ref = param(vehicle, "vbat_ref").nominal;
  const double hover = m.params()[m.param_index("mass")] * m.params()[m.param_index("g")] / static_cast<double>(nr);
  check_hover_reachable(vehicle, laws, hover);
  if (a.closed_loop) return run_closed_loop(a, vehicle, model, m);
  SimulateJobResult result;
  const int delay = m.input_delay_param();
  const std::vector<std::string> rotors = rotor_names(vehicle);

  std::vector<double> x0(m.num_states(), 0.0);
  x0[6] = 1.0;
  InputFunction inputs;
  std::unique_ptr<InputSignal> signal;
  const ExtraInputs extra(m);  // looked up once, not at every integrator stage
  if (!a.scenario.empty()) {
    const Scenario& s = find_scenario(a.scenario);
    inputs = [&, s, hover](double t, double* u) {
      const double td = delay >= 0 ? t - m.params()[delay] : t;
      const auto F = s.thrust(td, hover, rotors);
      for (size_t i = 0; i < nr; ++i) u[i] = laws[i].command_for(F[i]);
      extra.fill(t, vbat_ref, u);
    };
  } else {
    const CsvTable log = read_csv(a.inputs);
    try {
      validate_canonical(log, rotors);
    } catch (const LogError& e) {  // the one thing a user cannot guess: replay reads no mapping
      throw LogError(std::string(e.what()) +
                     "; simulate --inputs replays a log in the canonical layout (t, u_<rotor>; docs/formats.md)");
    }
    std::vector<double> t = log.values("t");
    if (a.duration > t.back() - t.front() + 1e-9)
      throw std::invalid_argument("--duration " + std::to_string(a.duration) + " s: " + output::printable(a.inputs) + " holds " +
                                  std::to_string(t.back() - t.front()) +
                                  " s of commands; a longer replay would hold the last command for the rest");
    std::vector<std::vector<double>> u(t.size(), std::vector<double>(nr));
    for (size_t r = 0; r < nr; ++r) {
      const auto col = log.values("u_" + rotors[r]);
      for (size_t k = 0; k < t.size(); ++k) u[k][r] = col[k];
    }
    signal = std::make_unique<InputSignal>(t, u, a.interpolation == "linear" ? Interpolation::linear : Interpolation::hold);
    const double t0 = t.front();
    const bool has_vbat = log.column("vbat") >= 0;
    if (m.input_index("vbat") >= 0 && !has_vbat)
      throw std::invalid_argument(a.inputs + ": battery_sag needs a 'vbat' column");
    std::shared_ptr<InputSignal> vbat_signal;
    if (has_vbat) {
      const auto v = log.values("vbat");
      std::vector<std::vector<double>> rows;
      for (double x : v) rows.push_back({x});
      vbat_signal = std::make_shared<InputSignal>(t, rows, Interpolation::linear);
    }
    // Start from the logged pose where the log has one.
    const char* pose[] = {"x", "y", "z", "vx", "vy", "vz", "qw", "qx", "qy", "qz", "p", "q", "r"};
    for (int i = 0; i < 13; ++i)
      if (log.column(pose[i]) >= 0) x0[i] = log.rows.front()[log.column(pose[i])];
    const InputSignal* sig = signal.get();
    inputs = [&, sig, t0, vbat_signal](double tt, double* uu) {
      sig->at(t0 + tt, uu, delay >= 0 ? m.params()[delay] : 0.0);
      double vb_now = vbat_ref;
      if (vbat_signal) vbat_signal->at(t0 + tt, &vb_now);
      extra.fill(tt, vb_now, uu);
    };
  }
  // Rotor-speed states (motor_lag) start at their commanded steady state.
  {
    std::vector<double> u0(m.num_inputs());
    inputs(0.0, u0.data());
    for (size_t i = 0; i < nr; ++i) {
      const int w = m.state_index("w_" + rotors[i]);
      if (w >= 0) x0[w] = laws[i].speed_at(u0[i]);
    }
  }

  IntegratorOptions io;
  io.step = a.step;
  std::vector<double> out_times;
  const long n_out = std::lround(a.duration * a.rate);
  for (long k = 0; k <= n_out; ++k) out_times.push_back(a.duration * static_cast<double>(k) / static_cast<double>(n_out));
  Stats stats;
  std::cerr << "simulating " << a.duration << " s of " << vehicle.name << " with " << a.integrator << "\n";
  Trajectory tr;
  if (a.integrator == "dopri5") {
    tr = integrate_dopri5(m, x0, inputs, out_times, io, &stats);
  } else {
    const Trajectory full = integrate_rk4(m, x0, inputs, 0.0, a.duration, io, &stats);
    const long every = std::max(1L, std::lround(1.0 / (a.rate * io.step)));
    for (size_t k = 0; k < full.t.size(); k += every) {
      tr.t.push_back(full.t[k]);
      tr.x.push_back(full.x[k]);
    }
  }

  result.csv = trajectory_csv(m, tr, inputs, rotors);
  // Plot like the thesis' figures: translation, rotation, thrust per rotor.
  // The thrust law on the rotor speed; with effects (a gain, inflow, ground effect) the model's
  // thrust differs from it, and the title says so rather than showing the law as the model's.
  const std::string thrust_title =
      a.effects.empty() ? "thrust per rotor" : "thrust per rotor by the nominal law c_t rho A r^2 w^2 (effects not included)";
  Panel trans{"translation", "t [s]", "m", {}}, rot{"rotation", "t [s]", "deg", {}}, thrust{thrust_title, "t [s]", "N", {}};
  const char* pos[] = {"x", "y", "z"};
  for (int i = 0; i < 3; ++i) {
    Series s{pos[i], tr.t, {}};
    for (const auto& x : tr.x) s.y.push_back(x[i]);
    trans.series.push_back(s);
  }
  Series phi{"phi (roll)", tr.t, {}}, theta{"theta (pitch)", tr.t, {}}, psi{"psi (yaw)", tr.t, {}};
  for (const auto& x : tr.x) {
    const auto e = euler_zyx(x[6], x[7], x[8], x[9]);
    phi.y.push_back(e[0] * 180 / M_PI);
    theta.y.push_back(e[1] * 180 / M_PI);
    psi.y.push_back(e[2] * 180 / M_PI);
  }
  rot.series = {phi, theta, psi};
  std::vector<double> ub(m.num_inputs());
  for (size_t r = 0; r < nr; ++r) {
    Series s{"F_" + rotors[r], tr.t, {}};
    const int w = m.state_index("w_" + rotors[r]);
    for (size_t k = 0; k < tr.t.size(); ++k) {
      inputs(tr.t[k], ub.data());
      const double speed = w >= 0 ? tr.x[k][w] : laws[r].speed_at(ub[r]);
      s.y.push_back(laws[r].thrust_at_speed(speed));
    }
    thrust.series.push_back(s);
  }
  const std::string what = a.scenario.empty() ? "replay of " + a.inputs : "scenario " + a.scenario;
  result.plot_title = vehicle.name + ": " + what;
  result.plot = {trans, rot, thrust};
  const auto& xe = tr.x.back();
  std::ostringstream summary;
  summary << "simulated " << a.duration << " s (" << stats.rhs_evaluations << " rhs evaluations): final position ("
          << xe[0] << ", " << xe[1] << ", " << xe[2] << ") m";
  result.summary = summary.str();
  return result;
}

}  // namespace quadgen::app
