// quadgen diagnose: its flags, the arguments they land in and the command's run (the pipeline
// itself is a library call: app/diagnose_job.cpp).
#pragma once
#include <set>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "app/diagnose_job.hpp"

namespace quadgen::cli {

struct DiagnoseArgs {
  app::DiagnoseJob job;  // the flags land here; defaults are the library's
  std::string out;
};
void add_diagnose(CLI::App& app, DiagnoseArgs& args);
int run_diagnose(const DiagnoseArgs& args);

}  // namespace quadgen::cli
