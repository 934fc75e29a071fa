// quadgen: vehicle file -> symbolic model -> generated code -> runtime -> fit -> diagnosis.
#include <algorithm>
#include <iostream>
#include <new>
#include <string>
#include <vector>

#include "cli/commands.hpp"
#include "cli/options.hpp"
#include "output/joined.hpp"
#include "output/output_set.hpp"
#include "output/sinks.hpp"

namespace {

// CLI11 says only "A subcommand is required" for `quadgen diagnos ...`; this names the word,
// the commands there are, and the nearest one.
bool unknown_command(const CLI::App& app, const std::string& word) {
  if (word.empty() || word[0] == '-') return false;
  std::vector<std::string> commands;
  for (const CLI::App* command : app.get_subcommands([](const CLI::App*) { return true; })) {
    if (command->get_name() == word) return false;
    commands.push_back(command->get_name());
  }
  std::cerr << quadgen::output::printable_error("quadgen: error: unknown command '" + word + "' (commands: " +
                                                quadgen::output::joined(commands) + ")" +
                                                quadgen::output::did_you_mean(word, commands));
  if (word == "generate") std::cerr << "; 'derive' writes the generated C++ (model.hpp) with the derivation";
  std::cerr << "\nRun with --help for more information.\n";
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  quadgen::output::remove_empty_outputs_on_interrupt();
  CLI::App app{"quadgen: derived, generated and audited multirotor flight models"};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("quadgen ") + QUADGEN_VERSION);
  app.option_defaults()->always_capture_default();  // --help shows each option's default
  quadgen::cli::DeriveArgs derive;
  quadgen::cli::add_derive(app, derive);
  quadgen::cli::SimulateArgs simulate;
  quadgen::cli::add_simulate(app, simulate);
  quadgen::cli::FitArgs fit;
  quadgen::cli::add_fit(app, fit);
  quadgen::cli::DiagnoseArgs diagnose;
  quadgen::cli::add_diagnose(app, diagnose);
  quadgen::cli::PredictArgs predict;
  quadgen::cli::add_predict(app, predict);
  quadgen::cli::CompareArgs compare;
  quadgen::cli::add_compare(app, compare);
  std::vector<char*> args(argv, argv + argc);
  std::string help = "--help";
  if (argc > 1 && std::string(argv[1]) == "help") args[1] = help.data();  // `quadgen help` as git has it
  if (argc > 1 && unknown_command(app, args[1])) return 106;  // CLI11's code for a missing subcommand
  try {
    app.parse(argc, args.data());
  } catch (const CLI::ParseError& e) {
    return quadgen::cli::report_parse_error(app, e);
  }
  fit.given = quadgen::cli::given_options(app.get_subcommand("fit"));
  return quadgen::cli::run_reporting_errors([&] {
    if (app.got_subcommand("derive")) return quadgen::cli::run_derive(derive);
    if (app.got_subcommand("simulate")) return quadgen::cli::run_simulate(simulate);
    if (app.got_subcommand("fit")) return quadgen::cli::run_fit(fit);
    if (app.got_subcommand("diagnose")) return quadgen::cli::run_diagnose(diagnose);
    if (app.got_subcommand("predict")) return quadgen::cli::run_predict(predict);
    if (app.got_subcommand("compare")) return quadgen::cli::run_compare(compare);
    return 1;
  });
}
