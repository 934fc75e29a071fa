// quadgen derive VEHICLE.yaml --out DIR [--effects e1,e2|all] [--params fitted_parameters.yaml]
#include <iostream>

#include "cli/derive_command.hpp"
#include "cli/options.hpp"
#include "output/sinks.hpp"
#include "app/derive_job.hpp"
#include "derive/effects/effect_catalogue.hpp"
#include "output/output_set.hpp"
#include "output/progress.hpp"

namespace quadgen::cli {

void add_derive(CLI::App& app, DeriveArgs& args) {
  CLI::App* c = app.add_subcommand("derive", "derive, audit and emit the flight model of a vehicle");
  c->add_option("vehicle", args.vehicle, "vehicle description (YAML)")->required();
  c->add_option("--out", args.out, "output directory")->required();
  const std::string effect_names = catalogue_names();  // --help lists what --effects accepts
  c->add_option("--effects", args.effects, "comma-separated effects to add, or 'all': " + effect_names);
  c->add_option("--params", args.params,
                "fitted_parameters.yaml written by diagnose: the model gets its effects and its fitted values as "
                "nominal values (the fitted model, regenerated)");
}

int run_derive(const DeriveArgs& args) {
  const Vehicle vehicle = load_vehicle(args.vehicle);  // a bad file is reported before anything is created
  output::OutputDirectory out(args.out, "derive", {args.vehicle, args.params});  // refused before the work, not after
  app::DeriveJob job{args.vehicle, args.effects, args.params, {}};
  const int steps = app::kDeriveJobSteps + 1;  // and the writing
  int step = 0;
  const output::Progress terminal = output::terminal_progress();  // escapes what a line quotes
  const auto say = [&](const std::string& what) {
    terminal.say("[" + std::to_string(++step) + "/" + std::to_string(steps) + "] " + what);
  };
  job.progress = say;
  const app::DeriveJobResult r = app::run_derive_job(job, vehicle);
  say("writing " + output::printable(args.out));
  for (const auto& [name, contents] : r.files) out.add(name, contents);
  commit_and_say(out, "derive");
  if (!r.note.empty()) std::cerr << "quadgen: note: " << output::printable_lines(r.note) << "\n";
  std::cout << output::printable_lines(r.summary);
  return r.audit_passed ? 0 : 3;
}

}  // namespace quadgen::cli
