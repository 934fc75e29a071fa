// The one rule for names that leave the program: vehicle, block and rotor names end up as C++
// namespaces and identifiers, CSV columns, gnuplot labels, HTML, Markdown and LaTeX. A name that
// passes this rule is inert in every one of those sinks; each sink escapes anyway
// (output/sinks.hpp), so that one missed check cannot become an injection.
#pragma once
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace quadgen::output {

inline constexpr std::size_t kMaxNameLength = 64;

// What is wrong with `name` as a vehicle, block or rotor name, or nothing when it is allowed:
// an ASCII letter, then letters, digits and single '_' (no "__", no trailing '_'), at most
// kMaxNameLength characters, and neither a C++ keyword nor a name the generated header uses.
std::optional<std::string> name_problem(const std::string& name);

// The rule in words, for error messages and docs.
const char* name_rule();

// What the code generator appends to a vehicle's name for a model's namespace and folder:
// "<vehicle>_with_<effect>_<effect>..." or "<vehicle>_all_effects".
inline constexpr const char* kEffectsInfix = "_with";
inline constexpr const char* kAllEffectsSuffix = "_all_effects";

// name_problem, and for a vehicle's name also what would make two models' namespaces one: a
// vehicle named "cf_with_wind" (or "cf_all_effects") would generate the namespace of "cf"
// with the wind effect (or with all), and the linker would keep one model's code for both.
std::optional<std::string> vehicle_name_problem(const std::string& name);

// True for a C++ keyword or alternative token (class, int, and, ...).
bool is_cpp_keyword(const std::string& word);

// Whether `word` is one of `words` (an option's choices, declared once beside its options
// struct and read by IsValid and the command line's check alike).
inline bool is_one_of(const std::string& word, const std::vector<std::string>& words) {
  for (const auto& w : words)
    if (w == word) return true;
  return false;
}

// A comma-separated list of names as an option gives it ("ax,qdot"), by one rule for every
// option that takes one (--effects, --candidates, --channels, --free, --profiles): an empty
// name (a ',' at an end or two in a row) and a name given twice are refused with
// std::invalid_argument, which begins with `what` (a channel listed twice was weighted twice
// in a fit, and fit's lists had skipped empty names where the effect lists refused them).
// The names are not checked otherwise: their owner knows which it accepts, and may pass
// `check_name`, called on each name before the repeat check (so a misspelt name given twice is
// named as unknown, with its nearest known name, not as a repeat).
std::vector<std::string> split_name_list(const std::string& text, const std::string& what,
                                         const std::function<void(const std::string&)>& check_name = {});

}  // namespace quadgen::output
