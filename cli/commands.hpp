// Subcommands of the quadgen executable (contracts.md §4).
#pragma once
#include <string>

#include <CLI/CLI.hpp>

namespace quadgen::cli {

struct DeriveArgs {
  std::string vehicle;
  std::string out;
  std::string effects;
};

void add_derive(CLI::App& app, DeriveArgs& args);
int run_derive(const DeriveArgs& args);

}  // namespace quadgen::cli
