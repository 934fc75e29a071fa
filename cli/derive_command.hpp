// quadgen derive: its flags, apart from the other subcommands' so that quadgen-derive (the
// bootstrap that regenerates generated/) builds without the layers that use generated/.
#pragma once
#include <string>

#include <CLI/CLI.hpp>

namespace quadgen::cli {

struct DeriveArgs {
  std::string vehicle;
  std::string out;
  std::string effects;
  std::string params;  // fitted_parameters.yaml from diagnose: its effects and values
};

void add_derive(CLI::App& app, DeriveArgs& args);
int run_derive(const DeriveArgs& args);

}  // namespace quadgen::cli
