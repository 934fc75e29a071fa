// Fuzz target: text from a vehicle file or a command line that reaches a sink stays text.
//  - The generated header: provenance fields (vehicle name, file path, effects flag) go
//    through header_writer's escaping into the real template; the header must keep its line
//    structure (no new line, no line splice, nothing that would become a directive).
//  - The gnuplot script: labels must not add lines to the script (a new line is a command).
//  - Every escaper keeps its own promise (output/sinks.hpp).
#include <cstddef>
#include <cstdint>
#include <string>

#include <kainjow/mustache.hpp>

#include "codegen/header_writer.hpp"
#include "output/names.hpp"
#include "runtime/plot.hpp"
#include "output/sinks.hpp"

extern const char* const kModelHeaderTemplate;

namespace {

size_t count(const std::string& s, char c) {
  size_t n = 0;
  for (char x : s) n += x == c;
  return n;
}

std::string header_with(const std::string& s) {
  static const kainjow::mustache::mustache tmpl{std::string(kModelHeaderTemplate)};
  kainjow::mustache::data d;
  quadgen::codegen::set_provenance_fields(d, {s, s, s, s, s, s});
  d.set("namespace", "fuzz_model");
  kainjow::mustache::data var;
  var.set("ident", "v");
  var.set("index", "0");
  var.set("name", quadgen::output::cpp_comment(s));
  var.set("unit", quadgen::output::cpp_comment(s));
  var.set("doc", quadgen::output::cpp_comment(s));
  d.set("states", kainjow::mustache::data{kainjow::mustache::list{var}});
  return kainjow::mustache::mustache(tmpl).render(d);
}

void check_header(const std::string& s) {
  static const std::string reference = header_with("x");
  const std::string h = header_with(s);
  if (count(h, '\n') != count(reference, '\n')) __builtin_trap();           // a line was added
  for (size_t i = h.find('\n'); i != std::string::npos; i = h.find('\n', i + 1))
    if (i > 0 && h[i - 1] == '\\') __builtin_trap();                          // a line splice
  // With the lines unchanged in number and unspliced, a directive could only be a line that
  // starts with '#' where the template has none.
  for (size_t a = 0, b = 0; a < h.size() && b < reference.size();) {
    const size_t ae = h.find('\n', a), be = reference.find('\n', b);
    if ((h[a] == '#') != (reference[b] == '#')) __builtin_trap();
    if (ae == std::string::npos || be == std::string::npos) break;
    a = ae + 1, b = be + 1;
  }
}

void check_gnuplot(const std::string& s) {
  using quadgen::runtime::Panel;
  const auto script = [](const std::string& label) {
    return quadgen::runtime::gnuplot_script(label, {Panel{label, label, label, {{label, {0, 1}, {0, 1}}}}});
  };
  static const size_t reference_lines = count(script("x"), '\n');
  if (count(script(s), '\n') != reference_lines) __builtin_trap();
  const std::string q = quadgen::output::gnuplot_string(s);
  for (unsigned char c : q)
    if (c < 0x20 || c == 0x7f) __builtin_trap();
  // Single-quoted pieces without a quote inside, joined by ."'". (gnuplot_string's form):
  // nothing between them that gnuplot would read as a command.
  static const std::string joint = "'.\"'\".'";
  if (q.size() < 2 || q.front() != '\'' || q.back() != '\'') __builtin_trap();
  const std::string inner = q.substr(1, q.size() - 2);
  for (size_t at = 0; at < inner.size(); ++at)
    if (inner[at] == '\'') {
      if (inner.compare(at, joint.size(), joint) != 0) __builtin_trap();
      at += joint.size() - 1;
    }
}

void check_escapers(const std::string& s) {
  namespace out = quadgen::output;
  for (unsigned char c : out::cpp_comment(s))
    if (c < 0x20 || c >= 0x7f || c == '\\') __builtin_trap();
  const std::string lit = out::cpp_string_literal(s);
  if (lit.size() < 2 || lit.substr(1, lit.size() - 2).find('"') != std::string::npos) __builtin_trap();
  const std::string html = out::html_text(s);
  if (html.find('<') != std::string::npos || html.find('"') != std::string::npos) __builtin_trap();
  if (out::markdown_text(s).find('\n') != std::string::npos) __builtin_trap();
  if (out::printable(s).find('\n') != std::string::npos) __builtin_trap();
  // The name rule admits only what the generator's identifier check admits.
  if (!out::name_problem(s)) out::checked_cpp_identifier(s, "fuzz");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string s(reinterpret_cast<const char*>(data), size);
  check_header(s);
  check_gnuplot(s);
  check_escapers(s);
  return 0;
}
