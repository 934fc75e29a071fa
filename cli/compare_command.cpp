// quadgen compare A.yaml B.yaml [--effects e1,e2|all]
#include <iostream>
#include <stdexcept>

#include "app/compare_job.hpp"
#include "cli/compare_command.hpp"
#include "cli/options.hpp"
#include "derive/effects/effect_catalogue.hpp"
#include "output/progress.hpp"
#include "output/sinks.hpp"

namespace quadgen::cli {

void add_compare(CLI::App& app, CompareArgs& args) {
  CLI::App* c = app.add_subcommand(
      "compare", "what differs between the derivations of two vehicle files: blocks, rotors, values, equations");
  c->add_option("vehicle_a", args.vehicle_a, "vehicle description A (YAML)")->required();
  c->add_option("vehicle_b", args.vehicle_b, "vehicle description B (YAML)")->required();
  c->add_option("--effects", args.effects,
                "comma-separated effects to derive both with, or 'all' (default: each file's fitted ones, or none): " +
                    catalogue_names());
  c->add_flag("--exit-code", args.exit_code, "exit with 1 where the derivations differ (for scripts), 0 where they are the same");
}

int run_compare(const CompareArgs& args) {
  const output::Progress terminal = output::terminal_progress();
  int step = 0;
  app::CompareJob job{args.vehicle_a, args.vehicle_b, args.effects,
                      [&](const std::string& what) { terminal.say("[" + std::to_string(++step) + "/3] " + what); }};
  const app::CompareJobResult r = app::run_compare_job(job);
  for (const std::string& note : r.notes) std::cerr << "quadgen: note: " << output::printable_error(note) << "\n";
  std::cout << output::printable_lines(r.text) << std::flush;
  // A comparison nobody received is no success: a full disk or a closed pipe (helper-161).
  if (!std::cout) throw std::runtime_error("cannot write the comparison to standard output");
  return r.same || !args.exit_code ? 0 : 1;
}

}  // namespace quadgen::cli
