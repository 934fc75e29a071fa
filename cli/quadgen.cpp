// quadgen: vehicle file -> symbolic model -> generated code -> runtime -> fit -> diagnosis.
#include <iostream>
#include <new>
#include <string>

#include "cli/commands.hpp"
#include "cli/options.hpp"
#include "output/sinks.hpp"

int main(int argc, char** argv) {
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
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return quadgen::cli::report_parse_error(app, e);
  }
  fit.given = quadgen::cli::given_options(app.get_subcommand("fit"));
  try {
    if (app.got_subcommand("derive")) return quadgen::cli::run_derive(derive);
    if (app.got_subcommand("simulate")) return quadgen::cli::run_simulate(simulate);
    if (app.got_subcommand("fit")) return quadgen::cli::run_fit(fit);
    if (app.got_subcommand("diagnose")) return quadgen::cli::run_diagnose(diagnose);
    if (app.got_subcommand("predict")) return quadgen::cli::run_predict(predict);
  } catch (const std::bad_alloc&) {
    std::cerr << "quadgen: error: out of memory: the input or the requested work is too large for this machine\n";
    return 2;
  } catch (const std::exception& e) {
    // One line, whatever the message quotes from a hostile input (newlines, escape sequences).
    std::cerr << "quadgen: error: " << quadgen::output::printable(e.what()) << "\n";
    return 2;
  }
  return 1;
}
