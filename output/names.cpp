#include "output/names.hpp"

#include <algorithm>
#include <set>
#include <stdexcept>

#include "output/sinks.hpp"

namespace quadgen::output {
namespace {

bool ascii_letter(char c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z'); }
bool ascii_digit(char c) { return c >= '0' && c <= '9'; }

// Names the generated header (templates/model.hpp.mustache) declares next to or inside the
// vehicle's namespace, and the namespaces it opens: a vehicle called "Model" or "std" would
// shadow them and the header would not compile, or compile to something else. The test
// NameRule.RefusesEveryNameTheHeaderTemplateDeclares reads the template for the list.
const std::set<std::string>& generated_header_names() {
  static const std::set<std::string> names = {
      "std", "quadgen_generated", "Model", "Scalar", "State", "Input", "Param", "Output", "Precomputed",
      "abs_value", "sign_of", "precompute", "rhs", "rotor_speed_rates", "measurement", "kNumStates",
      "kNumInputs", "kNumParams", "kNumOutputs", "kNumPrecomputed", "kNumRotorSpeedStates", "kRotorSpeedStates",
      "kVehicleHash", "kEffects", "kStateNames", "kInputNames", "kParamNames", "kOutputNames", "kNominalParams",
      "kInputDelayParam", "kParamUnits", "kParamLower", "kParamUpper", "kParamFit", "kNumConstants", "kConstantNames",
      "kConstantValues", "kNumRotors", "kRotorSpin", "kHasHoverTrim", "kHoverCommand", "kHoverThrust",
      "kHoverRotorSpeed"};
  return names;
}

// Macros that the generated header's one include (<cmath>, which pulls in parts of <stdlib.h>
// with glibc) or the compiler's default GNU mode define without a reserved spelling: as a
// namespace they would be replaced by a number or an expression. The list is what g++ 14 and
// glibc define (`echo '#include <cmath>' | g++ -dM -E -x c++ -`); the header also refuses to
// compile with any other macro of the vehicle's name (its #error guard), this only says so
// earlier, with the vehicle file's line.
bool is_library_macro(const std::string& w) {
  static const std::set<std::string> names = {
      "BIG_ENDIAN", "BYTE_ORDER", "EXIT_FAILURE", "EXIT_SUCCESS", "FD_CLR", "FD_ISSET", "FD_SET", "FD_SETSIZE",
      "FD_ZERO", "INFINITY", "LITTLE_ENDIAN", "MATH_ERREXCEPT", "MATH_ERRNO", "MAXFLOAT", "MB_CUR_MAX", "NAN",
      "NFDBITS", "PDP_ENDIAN", "RAND_MAX", "WCONTINUED", "WEXITED", "WEXITSTATUS", "WIFCONTINUED", "WIFEXITED",
      "WIFSIGNALED", "WIFSTOPPED", "WNOHANG", "WNOWAIT", "WSTOPPED", "WSTOPSIG", "WTERMSIG", "WUNTRACED", "alloca",
      "math_errhandling", "issubnormal", "linux", "unix", "i386", "sun", "sparc", "mips", "vax"};
  static const char* const prefixes[] = {"FP_", "M_", "HUGE_VAL", "SNAN", "htobe", "htole", "be16", "be32",
                                         "be64", "le16", "le32", "le64"};
  if (names.count(w)) return true;
  for (const char* p : prefixes)
    if (w.rfind(p, 0) == 0) return true;
  return false;
}

// Standard macros a header must not redefine, refused with the keywords (a name the generated
// code declares must be neither) and named as macros.
bool is_standard_macro(const std::string& w) { return w == "assert" || w == "errno" || w == "NULL" || w == "EOF"; }

}  // namespace

bool is_cpp_keyword(const std::string& w) {
  static const std::set<std::string> keywords = {
      "alignas", "alignof", "and", "and_eq", "asm", "auto", "bitand", "bitor", "bool", "break", "case",
      "catch", "char", "char8_t", "char16_t", "char32_t", "class", "compl", "concept", "const",
      "consteval", "constexpr", "constinit", "const_cast", "continue", "co_await", "co_return",
      "co_yield", "decltype", "default", "delete", "do", "double", "dynamic_cast", "else", "enum",
      "explicit", "export", "extern", "false", "float", "for", "friend", "goto", "if", "inline", "int",
      "long", "mutable", "namespace", "new", "noexcept", "not", "not_eq", "nullptr", "operator", "or",
      "or_eq", "private", "protected", "public", "register", "reinterpret_cast", "requires", "return",
      "short", "signed", "sizeof", "static", "static_assert", "static_cast", "struct", "switch",
      "template", "this", "thread_local", "throw", "true", "try", "typedef", "typeid", "typename",
      "union", "unsigned", "using", "virtual", "void", "volatile", "wchar_t", "while", "xor", "xor_eq",
      // Identifiers with special meaning that a header must not redefine.
      "final", "override", "import", "module"};
  return keywords.count(w) > 0 || is_standard_macro(w);
}

const char* name_rule() {
  return "a letter (A-Z, a-z), then letters, digits and single underscores, at most 64 characters, "
         "not a C++ keyword or a C library macro";
}

std::optional<std::string> name_problem(const std::string& name) {
  if (name.empty()) return "the name is empty";
  if (name.size() > kMaxNameLength) return "the name is longer than 64 characters";
  if (!ascii_letter(name[0])) return "the name must start with a letter";
  for (char c : name)
    if (!ascii_letter(c) && !ascii_digit(c) && c != '_')
      return "the name may hold only letters, digits and '_' (found a character outside them)";
  if (name.find("__") != std::string::npos || name.back() == '_')
    return "the name may not hold '__' or end in '_' (reserved in C++)";
  if (is_standard_macro(name)) return "'" + name + "' is a standard macro";
  if (is_cpp_keyword(name)) return "'" + name + "' is a C++ keyword";
  if (is_library_macro(name)) return "'" + name + "' is a macro of the C library or the compiler";
  if (generated_header_names().count(name)) return "'" + name + "' is a name the generated header uses";
  return std::nullopt;
}

std::optional<std::string> vehicle_name_problem(const std::string& name) {
  if (auto problem = name_problem(name)) return problem;
  const std::string infix = kEffectsInfix, with = infix + "_", all = kAllEffectsSuffix;
  const auto ends_with = [](const std::string& s, const std::string& end) {
    return s.size() >= end.size() && s.compare(s.size() - end.size(), end.size(), end) == 0;
  };
  if (name.find(with) == std::string::npos && !ends_with(name, infix) && !ends_with(name, all)) return std::nullopt;
  // A name to use instead: "_with_" as "_w_", a trailing "_with" as "_w", "_all_effects" as "_all".
  std::string instead = name;
  for (size_t at; (at = instead.find(with)) != std::string::npos;) instead.replace(at, with.size(), "_w_");
  if (ends_with(instead, all)) instead.replace(instead.size() - all.size(), all.size(), "_all");
  else if (ends_with(instead, infix)) instead.replace(instead.size() - infix.size(), infix.size(), "_w");
  return "the name contains '" + with + "' or ends in '" + infix + "' or '" + all +
         "', which the code generator appends for a model with effects: two vehicles' models would share one C++ "
         "namespace (rename it, e.g. '" + instead + "')";
}

}  // namespace quadgen::output

namespace quadgen::output {

std::vector<std::string> split_name_list(const std::string& text, const std::string& what,
                                         const std::function<void(const std::string&)>& check_name) {
  std::vector<std::string> names;
  if (text.empty()) return names;
  if (text.front() == ',' || text.back() == ',' || text.find(",,") != std::string::npos)
    throw std::invalid_argument(what + " '" + printable(text) + "' has an empty name (a ',' at an end or two in a row)");
  size_t begin = 0;
  while (begin <= text.size()) {
    const size_t end = std::min(text.find(',', begin), text.size());
    const std::string name = text.substr(begin, end - begin);
    if (check_name) check_name(name);
    if (std::find(names.begin(), names.end(), name) != names.end())
      throw std::invalid_argument(what + ": '" + printable(name) + "' is given twice");
    names.push_back(name);
    begin = end + 1;
  }
  return names;
}

}  // namespace quadgen::output
