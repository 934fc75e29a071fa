// quadgen simulate VEHICLE.yaml (--scenario NAME | --inputs LOG.csv) --duration S --out TRAJ.csv
#include <cctype>
#include <cmath>
#include <filesystem>
#include <iostream>

#include "app/simulate_job.hpp"
#include "cli/simulate_command.hpp"
#include "cli/options.hpp"
#include "output/ascii.hpp"
#include "derive/effects/effect_catalogue.hpp"
#include "output/output_set.hpp"
#include "output/progress.hpp"
#include "output/sinks.hpp"

namespace quadgen::cli {

namespace {

// The closed-loop test flight's trajectory, noise and disturbances: each refused without
// --closed-loop (`cl`), never silently ignored.
void add_closed_loop_options(CLI::App* c, SimulateArgs& a, CLI::Option* cl) {
  for (const app::FlightNumber& n : app::kFlightNumbers)
    c->add_option(n.option, a.job.flight.*n.field, n.help)->check(finite_range(n.range))->needs(cl);
}

}  // namespace

void add_simulate(CLI::App& app, SimulateArgs& a) {
  CLI::App* c = app.add_subcommand("simulate", "simulate a vehicle for a scenario or a logged input sequence");
  c->add_option("vehicle", a.job.vehicle, "vehicle description (YAML)")->required();
  auto* sc = c->add_option("--scenario", a.job.scenario, "a thesis manoeuvre about each rotor's hover thrust, on any layout: hover, climb, new_height "
                                 "(every rotor alike); right, forward, yaw (the rotors on the -x side, on +y, or spinning "
                                 "ccw, as A, D / C, D / A, C on the thesis' FINken 3)");
  auto* in = c->add_option("--inputs", a.job.inputs, "replay the motor commands of a flight log (canonical CSV, or any layout with --mapping)");
  c->add_option("--mapping", a.job.mapping, "column mapping (YAML) for an --inputs log not in the canonical layout (a CSV, a PX4 ULog, a Crazyflie uSD log)")
      ->needs(in);
  auto* cl = c->add_flag("--closed-loop", a.job.closed_loop,
                         "fly a smooth random trajectory under a cascaded controller (test flights); the controller runs and the "
                         "log is written at 100 Hz (--rate and --integrator are for scenarios and replays)");
  sc->excludes(in);
  cl->excludes(sc)->excludes(in);
  // Options of one mode are refused in the others (needs/excludes), never silently ignored.
  c->add_option("--seed", a.job.flight.seed, "closed loop: random trajectory and noise seed")
      ->check(whole_number_in(0, std::numeric_limits<unsigned>::max()))
      ->needs(cl);
  c->add_option("--set", a.set,
                std::string("NAME=VALUE for a parameter of the simulated model (repeatable): in a closed loop any "
                            "of the true model, which the controller does not know; in a scenario or a replay an "
                            "effect's only; an effect's values are as docs/effects.md gives them (motor_gain.<rotor> "
                            "is a relative change: thrust x (1 + value), 0 for none); names: ") +
                    parameter_names_help());
  add_closed_loop_options(c, a, cl);
  c->add_option("--duration", a.job.duration, "simulated time [s]")
      ->required()->check(finite_range(app::kDurationRange))->default_str("");  // required: no default to show
  c->add_option("--out", a.out, "trajectory in the canonical flight-log layout (CSV); a plot goes beside it (.svg)")
      ->required();
  const std::string effect_names = catalogue_names();  // --help lists what --effects accepts
  c->add_option("--effects", a.job.effects,
                "comma-separated effects to add, or 'all' (each at its neutral value, no change, until --set gives "
                "its parameters values): " + effect_names);
  c->add_option("--integrator", a.job.integrator, "rk4 (fixed step) or dopri5 (adaptive)")
      ->check(CLI::IsMember({"rk4", "dopri5"}))->excludes(cl);
  c->add_option("--step", a.job.step, "RK4 step [s]")->check(finite_range(app::kStepRange))->excludes(cl);
  c->add_option("--rate", a.job.rate, "output rate [Hz]")->check(finite_range(app::kRateRange))->excludes(cl);
  c->add_option("--interpolation", a.job.interpolation, "inputs between samples: hold or linear")
      ->check(CLI::IsMember({"hold", "linear"}))->needs(in);
  c->add_option("--ground", a.ground,
                "a ground the vehicle stands on and cannot fall through: 'start' (at the start's height: the log's "
                "first z, 0 without one) or H, the world z [m] of the body origin when it stands on the ground; none by default")
      ->check(CLI::Validator(
          [](std::string& s) -> std::string {
            double v = 0;
            if (s == "start" || (parse_finite(s, &v) && std::fabs(v) <= app::kMaxGroundHeight)) return {};
            return "'" + s + "': expected 'start' or a height in " + range_text(-app::kMaxGroundHeight, app::kMaxGroundHeight) + " m";
          },
          "start|HEIGHT"))
      ->excludes(cl);
  c->add_flag("--no-size-limit", a.job.no_size_limit,
              "run even when the estimated work exceeds the limits (" + output::six_digits(app::kMaxSteps) +
                  " integration steps, " + output::six_digits(app::kMaxRows) + " output rows)");
}

namespace {

// The trajectory and its plot beside it (TRAJ.csv, TRAJ.svg): neither may be an input, they
// may not be one file, and a file already there is replaced only if an earlier simulate wrote
// it (output::OutputFiles keeps the record), never a log or plot of the user's with that name.
std::string plot_path(const std::string& out) { return std::filesystem::path(out).replace_extension(".svg").string(); }

output::OutputFiles output_for(const SimulateArgs& a) {
  const std::string extension = output::ascii_lower(std::filesystem::path(a.out).extension().string());
  if (extension != ".csv")
    throw std::invalid_argument("--out " + output::printable(a.out) +
                                ": expected a .csv file name (the trajectory; its plot goes to the .svg beside it)");
  return output::OutputFiles({a.out, plot_path(a.out)}, "simulate", {a.job.vehicle, a.job.inputs, a.job.mapping});
}

// NAME=VALUE of --set; the value a finite number.
std::pair<std::string, double> parse_setting(const std::string& kv) {
  const auto eq = kv.find('=');
  if (eq == std::string::npos) throw std::invalid_argument("--set expects NAME=VALUE, got '" + output::printable(kv) + "'");
  double value = 0;
  if (!parse_finite(kv.substr(eq + 1), &value))
    throw std::invalid_argument("--set " + output::printable(kv) + ": '" + output::printable(kv.substr(eq + 1)) + "' " + why_not_finite(kv.substr(eq + 1)));
  return {kv.substr(0, eq), value};
}

}  // namespace

int run_simulate(const SimulateArgs& a) {
  app::SimulateJob job = a.job;
  for (const std::string& kv : a.set) job.set.push_back(parse_setting(kv));
  double height = 0;
  job.ground_at_start = a.ground == "start";
  if (!job.ground_at_start && parse_finite(a.ground, &height)) job.ground_height = height;
  job.progress = output::terminal_progress();
  output::OutputFiles out = output_for(a);  // refused before the work, not after
  const app::SimulateJobResult r = app::run_simulate_job(job);
  out.set(0, r.csv);
  if (!r.svg.empty()) out.set(1, r.svg);
  else std::cerr << "no plot: " << output::printable_lines(r.plot_error) << "\n";
  commit_and_say(out, "simulate");
  for (const auto& note : r.notes) std::cerr << output::printable(note) << "\n";
  std::cout << output::printable_lines(r.summary) << "; wrote " << output::printable(a.out) << "\n";
  return 0;
}

}  // namespace quadgen::cli
