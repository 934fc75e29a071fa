// quadgen: vehicle file -> symbolic model -> generated code -> runtime -> fit -> diagnosis.
#include <iostream>

#include "commands.hpp"

int main(int argc, char** argv) {
  CLI::App app{"quadgen: derived, generated and audited multirotor flight models"};
  app.require_subcommand(1);
  quadgen::cli::DeriveArgs derive;
  quadgen::cli::add_derive(app, derive);
  quadgen::cli::SimulateArgs simulate;
  quadgen::cli::add_simulate(app, simulate);
  quadgen::cli::FitArgs fit;
  quadgen::cli::add_fit(app, fit);
  quadgen::cli::DiagnoseArgs diagnose;
  quadgen::cli::add_diagnose(app, diagnose);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  try {
    if (app.got_subcommand("derive")) return quadgen::cli::run_derive(derive);
    if (app.got_subcommand("simulate")) return quadgen::cli::run_simulate(simulate);
    if (app.got_subcommand("fit")) return quadgen::cli::run_fit(fit);
    if (app.got_subcommand("diagnose")) return quadgen::cli::run_diagnose(diagnose);
  } catch (const std::exception& e) {
    std::cerr << "quadgen: error: " << e.what() << "\n";
    return 2;
  }
  return 1;
}
