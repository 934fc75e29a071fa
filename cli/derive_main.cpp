// quadgen-derive: the `derive` subcommand alone. It does not link the compiled models of
// generated/, so it can regenerate them even when they are stale (scripts/regenerate.sh).
#include <iostream>
#include <string>

#include "cli/derive_command.hpp"
#include "cli/options.hpp"
#include "output/sinks.hpp"

int main(int argc, char** argv) {
  CLI::App app{"quadgen-derive: derive, audit and emit a flight model (bootstrap for generated/)"};
  app.set_version_flag("--version", std::string("quadgen-derive ") + QUADGEN_VERSION);
  app.option_defaults()->always_capture_default();
  quadgen::cli::DeriveArgs derive;
  quadgen::cli::add_derive(app, derive);
  app.require_subcommand(1);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return quadgen::cli::report_parse_error(app, e);
  }
  return quadgen::cli::run_reporting_errors([&] { return quadgen::cli::run_derive(derive); });
}
