// `quadgen diagnose` as a library call: the logs of one vehicle in; out, in memory, every
// file the command writes (diagnosis.json, report.html, the extended model and its
// derivation, fitted_parameters.yaml, the plots and their data). The caller decides where
// they go: the command line writes them as one output set, all or nothing.
#pragma once
#include <string>
#include <utility>
#include <vector>

#include "diagnose/diagnosis.hpp"

namespace quadgen::app {

struct DiagnoseJob {
  std::string vehicle;            // vehicle file (YAML)
  std::vector<std::string> logs;  // one flight, or several of the vehicle (diagnosed jointly)
  std::string mapping;            // column mapping (YAML); "": the canonical layout
  double resample = 0;            // Hz; 0: the samples as logged
  std::string environment;        // indoor, outdoor or unknown; "": the mapping's, else unknown
  std::string candidates;         // comma-separated effects; "": all that the logs support
  // diagnosis.json of an earlier (joint) diagnosis of this vehicle: one flight is also checked
  // against the airframe it found (diagnose::check_against_airframe); "": no check.
  std::string airframe;
  diagnose::DiagnoseOptions options;

  // Ceres-style: false with a reason for a value no diagnosis can use.
  bool IsValid(std::string* error) const;
};

struct DiagnoseJobResult {
  std::vector<std::pair<std::string, std::string>> files;  // name, contents
  std::string summary;                                     // what the command prints
  std::vector<std::string> notes;                          // what went wrong on the side (no plots)
};

// The logs a diagnosis read, as its outputs name them (diagnosis.json's "log", the report's
// head, the extended header's comment): one log as its path; several joined with ", ", each
// quoted as one shell word (output::shell_path), and so one log whose path holds ", ", so that
// such a path never reads as two.
std::string logs_label(const std::vector<std::string>& paths);

// The notes for plots not drawn (each error "name.svg: why"): every one said ("no plot
// name.svg: why"; a label gnuplot refused once lost three of six without a word: helper-146);
// where none was drawn for one reason (gnuplot missing), that reason once ("no plots: why").
std::vector<std::string> plot_notes(const std::vector<std::string>& errors, bool none_drawn);

// Throws std::invalid_argument for an invalid job, and the layers' own errors (a bad vehicle
// file or log, with file and line) unchanged.
DiagnoseJobResult run_diagnose_job(const DiagnoseJob& job);

}  // namespace quadgen::app
