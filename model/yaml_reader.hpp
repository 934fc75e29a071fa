// Reading the project's YAML inputs (vehicle files, fitted parameters) with "file:line: what
// was expected" errors: the generic half of the vehicle reader, shared so that every input
// refuses unknown and repeated keys the same way (yaml-cpp keeps the first of two equal keys
// silently).
#pragma once
#include <cctype>
#include <cmath>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <yaml-cpp/depthguard.h>
#include <yaml-cpp/yaml.h>

#include "output/ascii.hpp"
#include "output/joined.hpp"
#include "output/numbers.hpp"
#include "output/nearest_word.hpp"
#include "output/sinks.hpp"
#include "model/vehicle.hpp"
#include "runtime/flight_log.hpp"
#include "runtime/log_file.hpp"

namespace quadgen {

// What yaml-cpp's words mean in a hand-written file ("end of map not found" for a tab in the
// indentation, "end of map flow not found" for a missing comma): the likely slip, appended
// to its message; "" when none is recognised. `line` counts from 0, as yaml-cpp's marks do.
// Only the error's line and the one before are read for a tab (a tab inside a block scalar
// further up is valid YAML).
inline std::string yaml_slip(const std::string& text, int line, const std::string& message) {
  std::istringstream in(text);
  std::string l;
  for (int n = 0; std::getline(in, l) && n <= line; ++n) {
    if (n < line - 1) continue;
    const size_t indent = l.find_first_not_of(" \t");
    if (indent != std::string::npos && l.find('\t') < indent)
      return " (line " + std::to_string(n + 1) + " indents with a tab: YAML indents with spaces only)";
  }
  if (message.find("end of map flow not found") != std::string::npos ||
      message.find("end of sequence flow not found") != std::string::npos)
    return " (a '{...}' or '[...]' left open, or two of its entries without a comma between them)";
  return "";
}

// "malformed YAML: ..." for a parser error in `text`, with the likely slip; yaml-cpp's depth
// guard (lists or mappings nested past it) says "bad file", so it is said in words here.
inline std::string malformed_yaml(const YAML::ParserException& e, const std::string& text) {
  if (const auto* deep = dynamic_cast<const YAML::DeepRecursion*>(&e))
    return "malformed YAML: nested more deeply than the reader follows (" + std::to_string(deep->depth()) +
           " levels of lists or mappings)";
  // yaml-cpp's message may quote a byte of the file ("unknown escape character: " and a NUL,
  // which cut the whole error short where it became a C string): shown, as every name is.
  return "malformed YAML: " + output::printable(e.msg) + yaml_slip(text, e.mark.line, e.msg);
}

// Whether a line of YAML holds anything: not blank, not only a comment.
inline bool has_content(const std::string& line) {
  const size_t first = line.find_first_not_of(" \t\r");
  return first != std::string::npos && line[first] != '#';
}

// The line (from 0, as yaml-cpp's marks count) where content after the first YAML document
// starts, or -1. A line that begins with '---' or '...' and then ends or a blank is a document
// marker wherever it stands (YAML 1.2's forbidden lines: not even a block scalar or a quoted
// string holds one), so the lines alone tell: a '---' before any content opens the first
// document, a '---' after content or any '...' ends it, and whatever is not blank or a comment
// after that (on the marker's own line too) is a second document.
inline int second_document_line(const std::string& text) {
  bool opened = false, started = false, ended = false;  // a '---' seen, content seen, the document over
  std::istringstream in(text);
  std::string line;
  for (int n = 0; std::getline(in, line); ++n) {
    const bool marker = line.size() >= 3 && (line.compare(0, 3, "---") == 0 || line.compare(0, 3, "...") == 0) &&
                        (line.size() == 3 || line[3] == ' ' || line[3] == '\t' || line[3] == '\r');
    if (marker) {
      const bool content_after = has_content(line.substr(3));  // "--- {a: 1}"
      if (!ended && line[0] == '-' && !opened && !started) {  // the '---' that opens the first document
        opened = true;
        started = content_after;
        continue;
      }
      if (ended && content_after) return n;
      ended = true;  // a '...', or a '---' that starts a second document (an empty first one, too)
      if (line[0] == '-' && content_after) return n;
      continue;
    }
    if (!has_content(line) || (!started && line[0] == '%')) continue;  // blank, a comment, a directive
    if (ended) return n;
    started = true;
  }
  return -1;
}

// The one document of a YAML input. yaml-cpp's Load reads the first document and drops the
// rest without a word: a '---' line in the middle of a vehicle file silently threw away every
// key after it, its mass among them (a hostile-input review, helper-135). A later document
// holding nothing (a trailing '---', comments) is harmless; one holding anything is an error.
// Returns in `*dropped_line` the line second_document_line gives; a parser error is thrown as
// yaml-cpp throws it. (Not YAML::LoadAll: the fuzzer found an input on which it never returns,
// where Load takes 5 ms.)
inline YAML::Node load_one_document(const std::string& text, int* dropped_line) {
  *dropped_line = second_document_line(text);
  return YAML::Load(text);
}

// What that error says, after "file:line: ".
inline constexpr const char* kSecondYamlDocument =
    "a second YAML document starts here, after a '---' or '...' line: the file is read as one document, so "
    "remove that line (everything after it would be ignored)";

// A YAML scalar's text as a number, by the rule the log cells and the command line follow
// (output/numbers.hpp; yaml-cpp's own conversion read 1e-400 as 0 without a word), for every
// YAML input (the vehicle file, fitted parameters, a column mapping's scale and offset).
// A quoted or block scalar keeps its blanks: "1 " and a block's final newline were read by
// yaml-cpp, " 1" was not; none is a number here (a review, helper-89). YAML's own words
// .inf, -.Inf, .NaN are numbers, just not finite ones.
inline output::NumberText yaml_number(const std::string& text, double* value) {
  const bool blank_around = !text.empty() && (std::isspace(static_cast<unsigned char>(text.front())) ||
                                              std::isspace(static_cast<unsigned char>(text.back())));
  output::NumberText kind = blank_around ? output::NumberText::not_a_number : output::read_number(text, value);
  if (kind == output::NumberText::not_a_number) {
    const std::string lower = output::ascii_lower(text);
    if (lower == ".inf" || lower == "+.inf" || lower == "-.inf" || lower == ".nan") kind = output::NumberText::not_finite;
  }
  return kind;
}

// The line (from 0) a value without text of its own belongs to. yaml-cpp marks an empty
// value ("name:" and a line break) where the next token starts, a line or more later: the
// error named the key after it. The mark's own line is kept where something stands before
// the mark on it (an empty value inside a flow collection, "{value: , unit: m}", is marked
// at the ',' or '}' after it, on its own line), where the mark is an empty key's ':', or
// where the mark is an explicit null (~, null: a token of its own); otherwise the last line before the mark with content (not
// blank, not only a comment) is the key's.
inline int empty_value_line(const std::string& text, const YAML::Mark& mark) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);) lines.push_back(l);
  const auto at = [&](int line) { return line >= 0 && line < static_cast<int>(lines.size()) ? lines[static_cast<size_t>(line)] : std::string(); };
  const std::string here = at(mark.line);
  const size_t column = mark.column >= 0 ? static_cast<size_t>(mark.column) : 0;
  if (here.substr(0, column).find_first_not_of(" \t") != std::string::npos) return mark.line;
  // An empty key (": value") is marked at its ':' (a review, helper-145).
  if (column < here.size() && here[column] == ':' && (column + 1 == here.size() || std::isspace(static_cast<unsigned char>(here[column + 1]))))
    return mark.line;
  if (column < here.size()) {
    const std::string rest = here.substr(column);
    const size_t word = rest.find_first_of(" \t\r#,]}");
    const std::string token = rest.substr(0, word);
    if (token == "~" || token == "null" || token == "Null" || token == "NULL") return mark.line;
  }
  for (int line = std::min(mark.line, static_cast<int>(lines.size())) - 1; line >= 0; --line)
    if (has_content(at(line))) return line;
  return mark.line;
}

// The line (from 0) an error about `at` names: its mark's, or for an empty value the line
// of its key (empty_value_line); -1 where the node has no mark.
inline int node_line(const std::string& text, const YAML::Node& at) {
  if (!at.IsDefined() || at.Mark().line < 0) return -1;
  return at.IsNull() ? empty_value_line(text, at.Mark()) : at.Mark().line;
}

struct YamlReader {
  std::string path;
  std::string content;  // what parse() read: for the line of an empty value

  [[noreturn]] void fail(const YAML::Node& at, const std::string& what) const {
    std::ostringstream os;
    os << path;
    if (const int line = node_line(content, at); line >= 0) os << ':' << line + 1;
    os << ": " << what;
    throw VehicleError(os.str());
  }
  [[noreturn]] void fail_at(const YAML::Mark& m, const std::string& what) const {
    std::ostringstream os;
    os << path << ':' << m.line + 1 << ": " << what;
    throw VehicleError(os.str());
  }

  // The file's text; `what` names it in the error ("vehicle file"). Opened as every log is
  // (runtime::LogFile): a FIFO or a directory refused at once, checked on what was opened,
  // at most max_input_bytes(), and a read cut short is an error, never taken as the file.
  std::string read_file(const std::string& what) const {
    try {
      return runtime::LogFile(path, "a " + what, runtime::kMaxYamlBytes).read_all();
    } catch (const runtime::LogError& e) {
      throw VehicleError(e.what());
    }
  }

  YAML::Node parse(const std::string& text) {
    content = text;
    int dropped = -1;
    YAML::Node root;
    try {
      root = load_one_document(text, &dropped);
    } catch (const YAML::ParserException& e) {
      fail_at(e.mark, malformed_yaml(e, text));
    }
    if (dropped >= 0) {
      YAML::Mark m;
      m.line = dropped;
      fail_at(m, kSecondYamlDocument);
    }
    return root;
  }

  // An empty value ("kappa:" and nothing) said as such: "expected a name for vehicle name"
  // and "expected parameter kappa (a mapping of keys)" read as if something else had been
  // written (a newcomer's trial, helper-143).
  void require_value(const YAML::Node& n, const std::string& what, const std::string& expected) const {
    if (n.IsNull()) fail(n, what + " has no value (expected " + expected + ")");
  }

  void require_map(const YAML::Node& n, const std::string& what) const {
    if (!n.IsMap()) fail(n, "expected " + what + " (a mapping of keys)");
  }

  // Plain keys, each once.
  void unique_keys(const YAML::Node& n, const std::string& where) const {
    std::set<std::string> seen;
    for (const auto& kv : n) {
      if (!kv.first.IsScalar()) fail(kv.first, "expected a plain key in " + where + " (found a list or mapping as a key)");
      if (!seen.insert(kv.first.Scalar()).second)
        fail(kv.first, "key '" + output::printable(kv.first.Scalar()) + "' given twice in " + where);
    }
  }

  // Rejects keys not in `allowed`, so that a typo never silently drops a number, and keys
  // given twice.
  void only_keys(const YAML::Node& n, const std::set<std::string>& allowed, const std::string& where) const {
    unique_keys(n, where);
    for (const auto& kv : n) {
      const std::string key = kv.first.Scalar();
      if (allowed.count(key)) continue;
      fail(kv.first, "unknown key '" + output::printable(key) + "' in " + where + " (expected one of: " +
                         output::joined(allowed) + ")" +
                         output::did_you_mean(key, std::vector<std::string>(allowed.begin(), allowed.end())));
    }
  }

  const YAML::Node need(const YAML::Node& parent, const std::string& key, const std::string& where) const {
    const YAML::Node n = parent[key];
    if (!n) fail(parent, "missing key '" + key + "' in " + where);
    return n;
  }

  // By the rule the log cells and the command line follow (output/numbers.hpp): yaml-cpp's
  // own conversion read 1e-400 as 0 without a word.
  double number(const YAML::Node& n, const std::string& what) const {
    require_value(n, what, "a number");
    if (!n.IsScalar()) fail(n, "expected a number for " + what);
    const std::string& text = n.Scalar();
    const std::string shown = output::printable(text);
    double v = 0;
    switch (yaml_number(text, &v)) {
      case output::NumberText::finite: return v;
      case output::NumberText::not_a_number:
        fail(n, "expected a number for " + what + ", got '" + shown + "'" + output::hexadecimal_hint(text));
      case output::NumberText::not_finite: fail(n, "expected a finite number for " + what + ", got '" + shown + "'");
      case output::NumberText::underflow:
        fail(n, "'" + shown + "' for " + what + " " + output::number_text_problem(output::NumberText::underflow));
    }
    return v;
  }

  // Free text (a description, a unit): any printable characters and line breaks, no other
  // control characters (escape sequences would reach terminals and reports).
  std::string text(const YAML::Node& n, const std::string& what) const {
    require_value(n, what, "text");
    if (!n.IsScalar()) fail(n, "expected text for " + what);
    for (unsigned char c : n.Scalar())
      if ((c < 0x20 && c != '\n' && c != '\t') || c == 0x7f) fail(n, "control character in " + what);
    return n.Scalar();
  }
};

}  // namespace quadgen
