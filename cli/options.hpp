// Checks shared by the subcommands' flags: numbers that are finite and in range (CLI11's Range
// lets NaN through) and which options a command line actually gave. (The NAME=VALUE pairs of
// simulate's --set are parsed in simulate_command.cpp.)
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <limits>
#include <new>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "output/accepted_range.hpp"
#include "output/numbers.hpp"
#include "output/nearest_word.hpp"
#include "output/output_set.hpp"
#include "output/sinks.hpp"

namespace quadgen::cli {

// Every error the programs report after their flags are read: "quadgen: error: " and one line
// of a readable length, whatever the message quotes from a hostile input (newlines, escape
// sequences, a name of 200 kB).
inline void print_error(const std::string& what) {
  std::cerr << "quadgen: error: " << output::printable_error(what) << "\n";
}

// Runs a subcommand; what it throws is reported by print_error, with exit code 2.
template <class Run>
int run_reporting_errors(const Run& run) {
  try {
    return run();
  } catch (const std::bad_alloc&) {
    print_error("out of memory: the input or the requested work is too large for this machine");
  } catch (const std::exception& e) {
    print_error(e.what());
  }
  return 2;
}

// Whether `option` is `word` with at most three letters left out, its first letter kept
// ("--out" in "--ouput" or "--output", not in "--count" or "--about"): a slip of a letter or
// a word's ending too many, which an edit count within a third of a short word's length does
// not reach.
inline bool within_three_extra_letters(const std::string& word, const std::string& option) {
  if (word.size() <= option.size() || word.size() > option.size() + 3) return false;
  const size_t first = option.find_first_not_of('-');
  if (first == std::string::npos || word.find_first_not_of('-') != first || word[first] != option[first]) return false;
  size_t i = 0;
  for (char c : word)
    if (i < option.size() && c == option[i]) ++i;
  return i == option.size();
}

// The option of `command` nearest to `word` ("--maping" -> "--mapping"), as nearest_word
// judges nearness, else one the word holds with three letters or fewer added ("--ouput" ->
// "--out": a newcomer's trial, helper-143); "" when none is near.
inline std::string nearest_option(const CLI::App& command, const std::string& word) {
  std::vector<std::string> options;
  for (const CLI::Option* o : command.get_options())
    for (const std::string& name : o->get_lnames()) options.push_back("--" + name);
  const std::string typed = word.substr(0, word.find('='));
  if (std::string near = output::nearest_word(typed, options); !near.empty()) return near;
  std::string best;  // the fewest letters added; of equals, the first
  for (const std::string& o : options)
    if (o.size() > 3 && within_three_extra_letters(typed, o) && o.size() > best.size()) best = o;  // not "--x" in anything
  return best;
}

// A command line CLI11 refused, reported as every other error is: one line, whatever the
// argument it quotes holds (escape sequences, a newline that would fake a second message).
// --help and --version leave through CLI11 itself (exit code 0).
// CLI11 reports a missing required option before an unknown one, so `--ouut DIR` reads as
// "--out is required"; the words it did not understand are named beside it, and a misspelt
// option gets the nearest one back.
inline int report_parse_error(const CLI::App& app, const CLI::ParseError& e) {
  if (e.get_exit_code() == 0) return app.exit(e);
  std::string not_understood, suggestions, dash_file;
  for (const CLI::App* command : app.get_subcommands())
    for (const std::string& word : command->remaining()) {
      // A log named "-x.csv" reads as an option, and CLI11 then says "logs is required" (a
      // review, helper-135): the file is named, with the spelling that reads as a path.
      std::error_code ec;
      if (dash_file.empty() && word.size() > 1 && word[0] == '-' && std::filesystem::is_regular_file(word, ec))
        dash_file = word;
      if (word.rfind("--", 0) != 0) continue;
      not_understood += (not_understood.empty() ? "" : " ") + word;
      if (const std::string near = nearest_option(*command, word); !near.empty() && near != word)
        suggestions += std::string(suggestions.empty() ? "" : ", ") + "'" + near + "' for '" + word + "'" +
                       output::lookalike_note(word.substr(0, word.find('=')), near);
    }
  std::cerr << "quadgen: error: " << output::printable_error(e.what());
  if (!not_understood.empty() && dynamic_cast<const CLI::RequiredError*>(&e))
    std::cerr << " (not understood: " << output::printable_error(not_understood) << ")";
  if (!suggestions.empty()) std::cerr << "; did you mean " << output::printable_error(suggestions) << "?";
  if (!dash_file.empty())
    std::cerr << "; '" << output::printable_error(dash_file) << "' is a file whose name reads as an option: write ./"
              << output::printable_error(dash_file);
  std::cerr << "\nRun with --help for more information.\n";
  return e.get_exit_code();
}

// What --help says a log may be, and which parameter names the options that take names
// accept (the effects' names depend on the vehicle's rotors, so they are given as patterns).
inline const char* const kLogFormats =
    "CSV in the canonical layout, or any CSV, PX4 ULog or Crazyflie uSD log through --mapping";
// The base parameters' names come from the derivation, the effects' from their descriptors
// (options.cpp: the derivation's headers stay out of the commands that do not need them).
std::string parameter_names_help();

// A finite number of the whole text, or nothing (output/numbers.hpp: the rule of the vehicle
// file and the log cells).
inline bool parse_finite(const std::string& text, double* value) {
  return output::read_number(text, value) == output::NumberText::finite;
}

// Why `text` is no finite number, for a message after it: "is not a finite number" (with a
// word on hexadecimal where it is that), or that it is below a double's smallest and would read
// as 0 (1e-400).
inline std::string why_not_finite(const std::string& text) {
  double v = 0;
  const output::NumberText kind = output::read_number(text, &v);
  return kind == output::NumberText::underflow ? output::number_text_problem(kind)
                                               : "is not a finite number" + output::hexadecimal_hint(text);
}

inline std::string range_text(double lo, double hi) {
  std::ostringstream os;
  os << "[" << lo << ", " << hi << "]";
  return os.str();
}

// A finite number within [lo, hi]; the message names the accepted range.
inline CLI::Validator finite_range(double lo, double hi) {
  return CLI::Validator(
      [lo, hi](std::string& s) -> std::string {
        double v = 0;
        if (!parse_finite(s, &v)) return "'" + s + "' " + why_not_finite(s) + " (accepted: " + range_text(lo, hi) + ")";
        if (v < lo || v > hi) return s + " is outside the accepted range " + range_text(lo, hi);
        return {};
      },
      "in " + range_text(lo, hi));
}

// A whole number within [lo, hi], in decimal: CLI11 reads "010" as octal 8 and "0x2" as 2
// (a hostile-input audit, helper-161: --max-effects 010 ran with 8), so only digits pass, and
// leading zeros are taken off before CLI11 converts. Text that is no number is told so, not
// "not in range".
inline CLI::Validator whole_number_in(long long lo, long long hi) {
  return CLI::Validator(
      [lo, hi](std::string& s) -> std::string {
        const bool minus = !s.empty() && s[0] == '-';
        std::string digits = s.substr(minus || (!s.empty() && s[0] == '+') ? 1 : 0);
        if (digits.empty() || digits.find_first_not_of("0123456789") != std::string::npos)
          return "'" + s + "' is not a whole number in decimal digits (accepted: " + range_text(lo, hi) + ")";
        digits.erase(0, std::min(digits.find_first_not_of('0'), digits.size() - 1));
        const long long v = digits.size() > 15 ? (minus ? lo - 1 : hi + 1) : (minus ? -1 : 1) * std::stoll(digits);
        if (v < lo || v > hi) return s + " is outside the accepted range " + range_text(lo, hi);
        s = std::to_string(v);
        return {};
      },
      "in " + range_text(lo, hi));
}

// ... the range its options struct declares (output/accepted_range.hpp), which IsValid checks too.
inline CLI::Validator finite_range(const output::AcceptedRange& r) { return finite_range(r.lo, r.hi); }

// Switches a command's output in and says when it replaced an earlier run of the same
// command in that folder (two runs given one --out keep only the second).
inline void commit_and_say(output::OutputDirectory& out, const std::string& command) {
  out.commit();
  if (out.replaced_earlier_run())
    std::cerr << "quadgen: note: replaced the earlier " << command << " output in " << output::printable(out.dir()) << "\n";
}

// ... and of a command that writes files, not a folder (simulate).
inline void commit_and_say(output::OutputFiles& out, const std::string& command) {
  out.commit();
  if (!out.replaced_earlier_run()) return;
  std::cerr << "quadgen: note: replaced the earlier " << command << " output";
  for (size_t i = 0; i < out.replaced_files().size(); ++i)
    std::cerr << (i == 0 ? " " : " and ") << output::printable(out.replaced_files()[i]);
  std::cerr << "\n";
}

// The long names of the options of `sub` that the command line gave.
inline std::set<std::string> given_options(const CLI::App* sub) {
  std::set<std::string> given;
  for (const CLI::Option* o : sub->get_options())
    if (o->count() > 0 && !o->get_lnames().empty()) given.insert("--" + o->get_lnames().front());
  return given;
}

}  // namespace quadgen::cli
