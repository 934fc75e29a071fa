// Fuzz target: text that reaches the header template (names, units, descriptions) is
// rendered verbatim as data, never interpreted as template syntax.
#include <cstddef>
#include <cstdint>
#include <string>

#include <kainjow/mustache.hpp>

extern const char* const kModelHeaderTemplate;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string s(reinterpret_cast<const char*>(data), size);
  static kainjow::mustache::mustache tmpl{std::string(kModelHeaderTemplate)};
  kainjow::mustache::data d;
  for (const char* key : {"namespace", "vehicle", "effects", "vehicle_file", "rhs_body"}) d.set(key, s);
  kainjow::mustache::data var;
  var.set("ident", s);
  var.set("name", s);
  var.set("unit", s);
  var.set("doc", s);
  var.set("index", "0");
  d.set("states", kainjow::mustache::data{kainjow::mustache::list{var}});
  const std::string out = tmpl.render(d);
  if (!s.empty() && out.find("{{") != std::string::npos && s.find("{{") == std::string::npos) __builtin_trap();
  return 0;
}
