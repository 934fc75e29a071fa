// diagnosis.json (the fields of docs/formats.md "diagnosis.json", with the evidence behind
// every finding) and the report a person reads: one self-contained HTML page with its plots
// inlined as SVG, so it renders in a browser without network access. One file each
// (diagnosis_json.cpp, diagnosis_plots.cpp, diagnosis_html.cpp, diagnosis_text.cpp for the
// terminal summary); the sentences they share are in report_words.hpp.
#pragma once
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "diagnose/diagnosis.hpp"

namespace quadgen::diagnose {

nlohmann::ordered_json diagnosis_json(const Diagnosis& d, const std::string& log_path);

// Plots as (file name, SVG text); one not drawn is said in `errors` ("name.svg: why"), every
// one when gnuplot is unavailable. `data`, when given, receives each plot's series as
// (name.csv, CSV text), gnuplot or not.
std::vector<std::pair<std::string, std::string>> diagnosis_plots(
    const Diagnosis& d, const fit::Flight& validation, std::vector<std::string>* errors,
    std::vector<std::pair<std::string, std::string>>* data = nullptr);

// What a reader should look for in one of diagnosis_plots' plots, by its file name ("" for
// one it does not make): the report's caption under the plot.
std::string what_to_look_for(const std::string& plot_name);

std::string diagnosis_html(const Diagnosis& d, const std::string& log_path,
                           const std::vector<std::pair<std::string, std::string>>& plots);

// One line per finding / ambiguity / unexplained discrepancy, for the terminal.
std::string diagnosis_summary(const Diagnosis& d);

}  // namespace quadgen::diagnose
