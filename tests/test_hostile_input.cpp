// Hostile input at every sink: names and paths from a vehicle file or the command line must
// never run a command, change generated code, or destroy a file. Each case checks the exit
// code, a one-line reason naming the file or option, that no output was created or changed,
// and that no input was changed.
#include <gtest/gtest.h>

#include <regex>
#include <sstream>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <random>
#include <set>
#include <string>
#include <thread>

#include "app/diagnose_job.hpp"
#include "app/simulate_job.hpp"
#include "app/derive_job.hpp"
#include "app/fit_job.hpp"
#include "output/names.hpp"
#include "diagnose/diagnosis_report.hpp"
#include "derive/dynamics.hpp"
#include "derive/geometry.hpp"
#include "output/json_document.hpp"
#include "codegen/expression_graph.hpp"
#include "codegen/header_writer.hpp"
#include "output/fnv1a.hpp"
#include "model/sha256.hpp"
#include "output/names.hpp"
#include "output/nearest_word.hpp"
#include "output/output_set.hpp"
#include "runtime/plot.hpp"
#include "runtime/flight_log.hpp"
#include "app/model_registry.hpp"
#include "cli/options.hpp"
#include "audit/report.hpp"
#include "output/sinks.hpp"
#include "tests/test_helpers.hpp"
#include "model/vehicle.hpp"
#include "runtime/portable_random.hpp"

namespace fs = std::filesystem;
using quadgen::test::source_path;
namespace out = quadgen::output;

namespace {

// Strings that break out of a naive sink: quotes, newlines, backslash splices, gnuplot's
// system(), a preprocessor directive, comment ends, HTML script, LaTeX and Markdown controls.
const std::vector<std::string>& hostile_strings() {
  static const std::vector<std::string> s = {
      "a'b\"c",
      "'leading quote, doubled '' and closing'",
      "x\nsystem \"touch PWNED\"\n#",
      "x'\nsystem \"touch PWNED\"\nset title 'y",
      "`touch PWNED`",
      "@PWNED",
      "finken3\n#define Scalar(v) (2*(v))\n//",
      "trailing backslash \\",
      "trigraph ?\?/",  // the characters ? ? /, written so that no compiler reads a trigraph
      "end */ of comment /*",
      "</script><script>alert(1)</script>",
      "</svg><img src=x onerror=alert(1)>",
      "$\\input{/etc/passwd}$ & % # _ ^ ~ { }",
      "| table | break |\n# heading",
      std::string("nul\0byte", 8),
      "\x1b[31mred\x1b[0m",
      "\xff\xfe invalid utf-8",
      "c1 \xc2\x9b" "31m csi in utf-8",               // U+009B, CSI where C1 controls are honoured
      "bidi \xe2\x80\xae" "desrever \xe2\x81\xa6x",  // U+202E right-to-left override, U+2066 isolate
      "mark \xe2\x80\x8f" "rtl \xd8\x9c" "alm",       // U+200F right-to-left mark, U+061C Arabic letter mark
      "sep \xe2\x80\xa8" "line \xe2\x80\xa9" "para",     // U+2028 line and U+2029 paragraph separators
      "cdata ]]]> end \xef\xbf\xbf" "nonchar \xef\xbf\xbe",  // none allowed in XML text (an SVG)
      "javascript:alert(1)",
  };
  return s;
}

// A scratch directory per test (ctest runs tests as parallel processes), removed afterwards.
struct Scratch {
  fs::path dir;
  Scratch() {
    dir = fs::temp_directory_path() /
          ("quadgen_hostile_" + std::string(testing::UnitTest::GetInstance()->current_test_info()->name()) + "_" +
           std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
  }
  ~Scratch() { fs::remove_all(dir); }
  std::string operator/(const std::string& name) const { return (dir / name).string(); }
};

std::string read(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), {});
}

void write(const fs::path& p, const std::string& s) { std::ofstream(p, std::ios::binary) << s; }

struct CliResult {
  int rc;
  std::string err;
};

// How a test interrupts a run: `signal` after `after_s` seconds, or once `exists` exists.
struct Interrupt {
  double after_s = -1;  // < 0: not by time
  fs::path exists;      // empty: not by a path
  int signal = SIGKILL;
  bool reader_gone = false;  // stderr a pipe whose reader has closed it: SIGPIPE at the first line
};

// Runs quadgen with `args` (each one argv element: no shell parses them) in `cwd`, with
// `env` ("NAME=value") added to its environment.
CliResult run_quadgen(const std::vector<std::string>& args, const fs::path& cwd, Interrupt interrupt = {},
                      std::vector<std::string> env = {}) {
  const fs::path err = cwd / ".stderr";
  const pid_t pid = ::fork();
  if (pid == 0) {
    if (::chdir(cwd.c_str()) != 0) _exit(99);
    for (auto& v : env) ::putenv(v.data());  // the child's own copy, alive until execv
    // quadgen keeps a signal its caller ignores ignored; the tests' signals must act.
    for (int sig : {SIGINT, SIGTERM, SIGHUP, SIGPIPE}) ::signal(sig, SIG_DFL);
    FILE* e = std::freopen(err.c_str(), "w", stderr);
    int gone[2];
    if (interrupt.reader_gone && (::pipe(gone) != 0 || ::close(gone[0]) != 0 || ::dup2(gone[1], 2) < 0)) _exit(97);
    FILE* o = std::freopen("/dev/null", "w", stdout);
    (void)e;
    (void)o;
    std::vector<char*> argv;
    std::string bin = QUADGEN_BINARY;
    argv.push_back(bin.data());
    std::vector<std::string> copy = args;
    for (auto& a : copy) argv.push_back(a.data());
    argv.push_back(nullptr);
    ::execv(bin.c_str(), argv.data());
    _exit(98);
  }
  if (interrupt.after_s >= 0) {
    std::this_thread::sleep_for(std::chrono::duration<double>(interrupt.after_s));
    ::kill(pid, interrupt.signal);
  } else if (!interrupt.exists.empty()) {
    std::error_code ec;
    siginfo_t info{};
    for (int k = 0; k < 6000 && !fs::exists(interrupt.exists, ec); ++k) {
      info.si_pid = 0;  // still running? (WNOWAIT: its status stays for the waitpid below)
      if (::waitid(P_PID, static_cast<id_t>(pid), &info, WEXITED | WNOHANG | WNOWAIT) == 0 && info.si_pid == pid) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    const bool seen = fs::exists(interrupt.exists, ec);
    if (seen) ::kill(pid, interrupt.signal);
    EXPECT_TRUE(seen) << interrupt.exists << " never appeared: nothing was interrupted";
  }
  int status = 0;
  ::waitpid(pid, &status, 0);
  CliResult r{WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status), read(err)};
  fs::remove(err);
  return r;
}

// `quadgen --version` prints the project's version on stdout and exits 0.
TEST(Cli, VersionPrintsTheProjectVersion) {
  FILE* p = ::popen((std::string(QUADGEN_BINARY) + " --version 2>&1").c_str(), "r");
  ASSERT_NE(p, nullptr);
  std::string out;
  char buf[256];
  while (std::fgets(buf, sizeof buf, p)) out += buf;
  EXPECT_EQ(::pclose(p), 0);
  EXPECT_EQ(out, std::string("quadgen ") + QUADGEN_VERSION + "\n");
}

// Every number a subcommand takes shows its default in --help ("--window FLOAT:...=0.5"),
// and the effect names are listed where --effects is offered.
TEST(Cli, HelpShowsTheDefaultOfEveryNumberAndTheEffectNames) {
  for (const char* command : {"derive", "simulate", "fit", "diagnose", "predict", "compare"}) {
    FILE* p = ::popen((std::string(QUADGEN_BINARY) + " " + command + " --help 2>&1").c_str(), "r");
    ASSERT_NE(p, nullptr);
    std::string out;
    char buf[1024];
    while (std::fgets(buf, sizeof buf, p)) out += buf;
    EXPECT_EQ(::pclose(p), 0) << command;
    std::istringstream lines(out);
    int numbers = 0;
    for (std::string line; std::getline(lines, line);) {
      static const std::regex number_option(R"(^\s+(--[a-z-]+) (FLOAT|INT|UINT)\b)");
      std::smatch m;
      if (!std::regex_search(line, m, number_option) || line.find("REQUIRED") != std::string::npos) continue;
      ++numbers;
      EXPECT_NE(line.find('='), std::string::npos) << command << " " << m[1] << ": no default in '" << line << "'";
    }
    const bool takes_numbers = std::string(command) != "derive" && std::string(command) != "compare";
    if (takes_numbers) EXPECT_GT(numbers, 0) << command;
    if (out.find("--effects") != std::string::npos) EXPECT_NE(out.find("blade_flapping"), std::string::npos) << command;
  }
}

// The error line: "quadgen: error: ..." as the last line, alone.
void expect_one_line_error(const CliResult& r, const std::string& must_contain, const std::string& what) {
  EXPECT_NE(r.rc, 0) << what;
  const auto pos = r.err.find("quadgen: error: ");
  ASSERT_NE(pos, std::string::npos) << what << ": " << r.err;
  const std::string line = r.err.substr(pos);
  EXPECT_EQ(std::count(line.begin(), line.end(), '\n'), 1) << what << ": " << r.err;
  EXPECT_NE(line.find(must_contain), std::string::npos) << what << ": expected '" << must_contain << "' in " << line;
}

// The bundled FINken 3 file with one line replaced.
std::string finken3_with(const std::string& from, const std::string& to) {
  std::string s = read(source_path("vehicles/finken3.yaml"));
  const auto at = s.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return s.replace(at, from.size(), to);
}

// A YAML double-quoted scalar holding any bytes.
std::string yaml_quoted(const std::string& s) {
  std::string q = "\"";
  for (unsigned char c : s) {
    char buf[8];
    if (c == '"' || c == '\\') q += std::string("\\") + static_cast<char>(c);
    else if (c < 0x20 || c >= 0x7f) std::snprintf(buf, sizeof buf, "\\x%02X", c), q += buf;
    else q += static_cast<char>(c);
  }
  return q + "\"";
}

}  // namespace

// ---- the name rule -------------------------------------------------------------------------

TEST(NameRule, AcceptsIdentifiersAndRefusesEverythingElse) {
  for (const char* ok : {"finken3", "crazyflie21", "A", "M1", "upper_body", "arm_A"})
    EXPECT_FALSE(out::name_problem(ok)) << ok;
  // The macros of <cmath> (with glibc) and of g++'s default GNU mode would replace the
  // namespace: HUGE_VAL made the header fail to compile, linux under -std=gnu++17.
  for (const char* bad : {"", "3d", "class", "int", "std", "Model", "Scalar", "a__b", "a_", "_a", "a-b", "a b", "a.b",
                          "ä", "a\nb", "HUGE_VAL", "NAN", "M_PI", "FP_ZERO", "linux", "unix", "EXIT_SUCCESS"})
    EXPECT_TRUE(out::name_problem(bad)) << bad;
  EXPECT_TRUE(out::name_problem(std::string(65, 'a')));
  for (const auto& s : hostile_strings()) EXPECT_TRUE(out::name_problem(s)) << out::printable(s);
  // Named for what they are (a user trial: errno was called a keyword).
  for (const char* macro : {"errno", "assert", "NULL", "EOF"}) EXPECT_EQ(*out::name_problem(macro), "'" + std::string(macro) + "' is a standard macro");
  EXPECT_EQ(*out::name_problem("class"), "'class' is a C++ keyword");
}

// Terminal output (every error message goes through output::printable): nothing a terminal
// acts on survives - C0 controls, DEL, the C1 controls in their UTF-8 form, bidirectional
// overrides and isolates - and ordinary UTF-8 text is kept as it is.
TEST(Sinks, TerminalTextShowsControlsAsEscapes) {
  auto acts_on = [](const std::string& t) {
    for (size_t i = 0; i < t.size(); ++i) {
      const auto c = static_cast<unsigned char>(t[i]);
      if (c < 0x20 || c == 0x7f) return true;
      if (c == 0xC2 && i + 1 < t.size() && static_cast<unsigned char>(t[i + 1]) >= 0x80 &&
          static_cast<unsigned char>(t[i + 1]) <= 0x9F)
        return true;
      if (c == 0xE2 && i + 2 < t.size()) {
        const auto b1 = static_cast<unsigned char>(t[i + 1]), b2 = static_cast<unsigned char>(t[i + 2]);
        if ((b1 == 0x80 && b2 >= 0xA8 && b2 <= 0xAE) || (b1 == 0x81 && b2 >= 0xA6 && b2 <= 0xA9)) return true;
        if (b1 == 0x80 && (b2 == 0x8E || b2 == 0x8F)) return true;  // LRM, RLM
      }
      if (c == 0xD8 && i + 1 < t.size() && static_cast<unsigned char>(t[i + 1]) == 0x9C) return true;  // ALM
    }
    return false;
  };
  for (const auto& s : hostile_strings()) EXPECT_FALSE(acts_on(out::printable(s))) << out::printable(s);
  EXPECT_EQ(out::printable("F\xc3\xb6rster \xe2\x80\x94 \xce\xbc"), "F\xc3\xb6rster \xe2\x80\x94 \xce\xbc");
  EXPECT_EQ(out::printable("a\xc2\x9b" "b"), "a\\xC2\\x9Bb");
}

// A vehicle named after a type the generated header declares broke it: "Output" was added to
// the template and not to the reserved names, and derive wrote a header that did not compile.
// The names are read from the template itself, so the next one added cannot be missed.
TEST(NameRule, RefusesEveryNameTheHeaderTemplateDeclares) {
  std::ifstream in(source_path("templates/model.hpp.mustache"));
  ASSERT_TRUE(in);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  // struct X, namespace X, inline ... X( or X = / X[ at the start of a declaration, template <typename X>.
  const std::regex declared(
      R"((?:struct|namespace|typename)\s+([A-Za-z_]\w*)|inline\s+(?:constexpr\s+)?[\w:<>*\s]*?\b([A-Za-z_]\w*)\s*(?:\(|=|\[))");
  std::set<std::string> names;
  for (auto it = std::sregex_iterator(text.begin(), text.end(), declared); it != std::sregex_iterator(); ++it)
    names.insert((*it)[1].matched ? (*it)[1].str() : (*it)[2].str());
  for (const char* expected : {"Output", "State", "Precomputed", "quadgen_generated", "kNumStates", "rhs", "Scalar"})
    EXPECT_TRUE(names.count(expected)) << expected << " not read from the template: the pattern is out of date";
  for (const auto& n : names) EXPECT_TRUE(out::name_problem(n)) << n << " is declared by the header but accepted as a name";
}

TEST(NameRule, VehicleParserRefusesHostileNamesWithFileAndLine) {
  for (const auto& s : hostile_strings()) {
    for (const auto& [from, what] : std::vector<std::pair<std::string, std::string>>{
             {"name: finken3", "vehicle name"}, {"{name: upper_body,", "block name"}, {"{name: A,", "rotor name"}}) {
      const std::string to = from.back() == ',' ? "{name: " + yaml_quoted(s) + "," : "name: " + yaml_quoted(s);
      try {
        quadgen::parse_vehicle(finken3_with(from, to), "hostile.yaml");
        ADD_FAILURE() << what << " accepted: " << out::printable(s);
      } catch (const quadgen::VehicleError& e) {
        const std::string msg = e.what();
        EXPECT_EQ(msg.rfind("hostile.yaml:", 0), 0u) << msg;
        EXPECT_NE(msg.find(what), std::string::npos) << msg;
        EXPECT_EQ(msg.find('\n'), std::string::npos) << "message quotes the raw name: " << out::printable(msg);
      }
    }
  }
}

// Two vehicles whose models would share one namespace: "cf_with_wind" bare and "cf" with the
// wind effect both made quadgen_generated::cf_with_wind, and two translation units linked one
// rhs for both (an address sanitizer saw the other's parameter array overrun). The vehicle
// name may not contain what the generator appends.
TEST(NameRule, AVehicleNameCannotBeAnotherModelsNamespace) {
  for (const char* ok : {"finken3", "cf_within", "with_cf", "cf_all", "crazyflie21_nanobench"})
    EXPECT_FALSE(out::vehicle_name_problem(ok)) << ok;
  for (const char* bad : {"cf_with_wind", "cf_with", "cf_all_effects", "a_with_b_c"})
    EXPECT_TRUE(out::vehicle_name_problem(bad)) << bad;
  try {
    quadgen::parse_vehicle(finken3_with("name: finken3", "name: finken3_with_motor_lag"), "twin.yaml");
    ADD_FAILURE() << "a vehicle named as finken3's model with motor_lag was accepted";
  } catch (const quadgen::VehicleError& e) {
    const std::string msg = e.what();
    EXPECT_EQ(msg.rfind("twin.yaml:", 0), 0u) << msg;
    EXPECT_NE(msg.find("share one C++ namespace (rename it, e.g. 'finken3_w_motor_lag')"), std::string::npos) << msg;
  }
}

// A generated header runs only for the vehicle file it was generated from and only with the
// derivation's shape. It was chosen by the file's FNV-1a hash, which sixteen bytes appended
// in a comment can forge (helper-54, 2026-12-01): a six-rotor file with crazyflie21's hash
// ran on that header, and simulate wrote six commands into its four inputs (heap corruption);
// a heavier Crazyflie flew with the stock one's physics. Now the hash is SHA-256 (checked
// against FIPS 180-2's vectors), and a header whose hash and effects match is still refused
// unless its states, inputs, parameters and nominal values are the derivation's: here the
// hash is set by hand, as a forgery would make it.
TEST(HostileVehicle, AGeneratedHeaderRunsOnlyForTheFileAndShapeItWasGeneratedFrom) {
  EXPECT_EQ(quadgen::sha256_hex(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(quadgen::sha256_hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(quadgen::sha256_hex(std::string(1000000, 'a')),
            "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
  const auto compiled = [](const quadgen::Vehicle& v, int* inputs = nullptr) {
    bool is_compiled = false;
    const auto model = quadgen::app::make_model(quadgen::derive_model(v, quadgen::derive_mass_properties(v), {}),
                                                &is_compiled);
    if (inputs) *inputs = model->num_inputs();
    return is_compiled;
  };
  const quadgen::Vehicle cf = quadgen::load_vehicle(source_path("vehicles/crazyflie21.yaml"));
  EXPECT_EQ(cf.content_hash.size(), 64u);
  EXPECT_TRUE(compiled(cf));  // the bundled header of generated/crazyflie21
  quadgen::Vehicle hexa = quadgen::load_vehicle(source_path("vehicles/hexa_plus.yaml"));
  hexa.content_hash = cf.content_hash;
  int inputs = 0;
  EXPECT_FALSE(compiled(hexa, &inputs));
  EXPECT_EQ(inputs, 6);  // its own tape
  quadgen::Vehicle heavier = cf;  // same rotors, a heavier battery
  for (auto& b : heavier.blocks)
    if (b.name == "battery") b.mass += 0.005;
  EXPECT_FALSE(compiled(heavier));
  quadgen::Vehicle renamed = cf;
  renamed.rotors[0].name = "M0";
  EXPECT_FALSE(compiled(renamed));
  quadgen::Vehicle longer_arms = cf;  // the same blocks and parameters: only the header's constants differ
  for (auto& r : longer_arms.rotors) r.position[0] *= 1.1, r.position[1] *= 1.1;
  EXPECT_FALSE(compiled(longer_arms));
}

TEST(NameRule, DuplicateKeysInVehicleFilesAreRefused) {
  try {
    quadgen::parse_vehicle(finken3_with("name: finken3", "name: finken3\nname: other"), "dup.yaml");
    ADD_FAILURE() << "duplicate key accepted";
  } catch (const quadgen::VehicleError& e) {
    EXPECT_NE(std::string(e.what()).find("dup.yaml:13: key 'name' given twice"), std::string::npos) << e.what();
  }
}

// ---- one test per sink ---------------------------------------------------------------------

TEST(Sinks, CppCommentAndLiteralCannotEndEarly) {
  for (const auto& s : hostile_strings()) {
    const std::string c = out::cpp_comment(s);
    for (unsigned char ch : c) EXPECT_TRUE(ch >= 0x20 && ch < 0x7f && ch != '\\') << out::printable(c);
    EXPECT_EQ(c.find("??"), std::string::npos);
    const std::string l = out::cpp_string_literal(s);
    EXPECT_EQ(l.front(), '"');
    EXPECT_EQ(l.back(), '"');
    EXPECT_EQ(l.substr(1, l.size() - 2).find('"'), std::string::npos) << l;
    EXPECT_THROW(out::checked_cpp_identifier(s, "test"), std::invalid_argument) << out::printable(s);
  }
}

TEST(Sinks, GeneratedHeaderChangesOnlyInItsCommentWhatEverThePath) {
  const quadgen::Vehicle v = quadgen::test::finken3();
  const auto model = quadgen::derive_model(v, quadgen::derive_mass_properties(v), {});
  quadgen::codegen::EmitOptions plain;
  plain.vehicle_file = "vehicles/finken3.yaml";
  const std::string reference = quadgen::codegen::generate_header(model, plain).content;
  for (const auto& s : hostile_strings()) {
    quadgen::codegen::EmitOptions o = plain;
    o.vehicle_file = s;
    o.regenerate_flags = s;
    const std::string h = quadgen::codegen::generate_header(model, o).content;
    // Line 2 (the regenerate command) is the only one that may differ, and stays one line.
    const auto line2 = [](const std::string& x) {
      const size_t a = x.find('\n') + 1;
      return std::make_pair(a, x.find('\n', a));
    };
    const auto [ra, rb] = line2(reference);
    const auto [ha, hb] = line2(h);
    EXPECT_EQ(h.substr(0, ha), reference.substr(0, ra));
    EXPECT_EQ(h.substr(hb), reference.substr(rb)) << out::printable(s);
    EXPECT_EQ(h.substr(ha, hb - ha).find('\\'), std::string::npos);
  }
  // A name that got past the parser is refused by the generator, never emitted.
  auto bad = model;
  bad.vehicle_name = "finken3\n#define Scalar(v) (2*(v))\n//";
  EXPECT_THROW(quadgen::codegen::generate_header(bad, plain), std::invalid_argument);
  bad.vehicle_name = "class";
  EXPECT_THROW(quadgen::codegen::generate_header(bad, plain), std::invalid_argument);
}

TEST(Sinks, GnuplotRunsNoCommandAndDrawsTheLabelsAsText) {
  Scratch tmp;
  struct RestoreDirectory {  // however the test ends
    fs::path path;
    ~RestoreDirectory() { fs::current_path(path); }
  } restore{fs::current_path()};
  fs::current_path(tmp.dir);  // a `system "touch PWNED"` would create the file here
  for (const auto& s : hostile_strings()) {
    quadgen::runtime::Panel p{s, s, s, {{s, {0, 1, 2}, {1, 0, 1}}, {s, {0, 1}, {0, 1}, true}}, {1}, {{1.0, s}}};
    std::string svg, err;
    const bool drawn = quadgen::runtime::render_svg(s, {p}, &svg, &err);
    // setup.sh installs gnuplot: without it this test would prove nothing, so it fails.
    ASSERT_NE(err, "gnuplot is not installed");
    EXPECT_TRUE(drawn) << out::printable(s) << ": " << err;
    EXPECT_FALSE(fs::exists(tmp.dir / "PWNED")) << out::printable(s);
    std::string lower = svg;
    std::transform(lower.begin(), lower.end(), lower.begin(), ::tolower);
    EXPECT_EQ(lower.find("<script"), std::string::npos);
    EXPECT_EQ(lower.find("<img"), std::string::npos);
    // What XML does not allow in text, which would leave an SVG a browser refuses to show.
    EXPECT_EQ(svg.find("]]>"), std::string::npos) << out::printable(s);
    EXPECT_EQ(svg.find("\xef\xbf\xbf"), std::string::npos) << out::printable(s);
    EXPECT_EQ(svg.find("\xef\xbf\xbe"), std::string::npos) << out::printable(s);
  }
  EXPECT_TRUE(fs::is_empty(tmp.dir));  // nothing left behind: no data or script files
}

// Every quote of a label reaches the plot as text: gnuplot's '' escape lost a plot whose label
// began with a quote or held two together (a hostile-input review, helper-146).
TEST(Sinks, GnuplotDrawsEveryQuoteOfALabel) {
  for (const std::string label : {"'b.csv", "it''s", "end'", "''", "'"}) {
    quadgen::runtime::Panel p;
    p.title = "panel " + label;
    p.series.push_back({"series " + label, {0, 1, 2}, {1, 0, 1}});
    std::string svg, err;
    ASSERT_TRUE(quadgen::runtime::render_svg("plot " + label, {p}, &svg, &err)) << label << ": " << err;
    for (const std::string shown : {"plot " + label, "panel " + label, "series " + label})
      EXPECT_NE(svg.find(">" + shown + "<"), std::string::npos) << shown;
  }
}

// The second line of defence behind gnuplot's escaping: an SVG whose tags hold script is
// refused, whatever hides it in an attribute; the same words as text are drawn.
TEST(Sinks, AnSvgWithScriptInATagIsRefusedAndTextIsNot) {
  const auto doc = [](const std::string& body) { return "<?xml version=\"1.0\"?>\n<svg width=\"10\">" + body + "</svg>\n"; };
  EXPECT_TRUE(quadgen::runtime::whole_inert_svg(doc("<text>javascript:alert(1) onload=x &lt;script</text>")));
  EXPECT_TRUE(quadgen::runtime::whole_inert_svg(doc("<path d=\"M 1 2 L 3 4\" stroke=\"rgb(0, 0, 0)\"/>")));
  EXPECT_TRUE(quadgen::runtime::whole_inert_svg(doc("<g id=\"a&amp;b &#38; c & d\">javascript&colon;</g>")));
  // references that are none stay literal: no read past the tag, nothing decoded
  EXPECT_TRUE(quadgen::runtime::whole_inert_svg(doc("<g id=\"&#; &#x; &# &#xg &#99999999999999999999999;\" class=\"font-family_on\">y</g>")));
  for (const std::string bad : {"<script>alert(1)</script>", "<svg:script>x</svg:script>",
                                "<a xlink:href=\"x>javascript:alert(1)\">y</a>", "<a href='JavaScript:x'>y</a>",
                                "<g onload=\"x\">y</g>", "<g\tONCLICK = 'x'>y</g>", "<g id=\"a\" onmouseover=x>y</g>",
                                // character references and the controls a URL parser drops
                                "<a href=\"&#106;avascript:x\">y</a>", "<a href=\"&#x4A;ava&#X53;cript:x\">y</a>",
                                "<a href=\"java&#9;script:x\">y</a>", "<a href=\"java\nscript&#58;x\">y</a>",
                                "<a href=\"&#106avascript:x\">y</a>", "<a href=\"javascript&colon;x\">y</a>",
                                "<a href=\"vbscript:x\">y</a>", "<g id=\"a&amp b\">y</g>",
                                // a document of its own, and handlers after '/' or a quote (helper-66)
                                "<foreignObject><iframe srcdoc=\"&lt;script&gt;alert(1)&lt;/script&gt;\"></iframe></foreignObject>",
                                "<image href=\"x\"/onerror=\"alert(1)\"/>", "<image href=\"x\"onerror=\"alert(1)\"/>",
                                "<g/onclick=\"alert(1)\">y</g>", "<embed src=\"x.svg\"/>", "<object data=\"x\"></object>"})
    EXPECT_FALSE(quadgen::runtime::whole_inert_svg(doc(bad))) << bad;
  EXPECT_FALSE(quadgen::runtime::whole_inert_svg("<svg><text>cut short"));
  EXPECT_FALSE(quadgen::runtime::whole_inert_svg(doc("<g id=\"unclosed>") ));
}

// Several logs named in one line (diagnosis.json's "log", the report, the extended header):
// a path holding ", " or a quote stays one item, and one log is its path as given.
TEST(Sinks, SeveralLogPathsReadAsSeveral) {
  EXPECT_EQ(quadgen::app::logs_label({"a b.csv"}), "a b.csv");
  EXPECT_EQ(quadgen::app::logs_label({"x/a.csv, y.csv"}), "'x/a.csv, y.csv'");  // one log, not two
  EXPECT_EQ(quadgen::app::logs_label({"x/a.csv", "y.csv"}), "x/a.csv, y.csv");
  EXPECT_EQ(quadgen::app::logs_label({"x/a.csv", "a b, c.csv", "it's.csv"}), "x/a.csv, 'a b, c.csv', 'it'\\''s.csv'");
}

// A plot's series as CSV: read back with an RFC 4180 reader written here, every hostile label
// is one field of one record (no extra row or column), unchanged but for control characters
// and a formula guard, and the numbers come back exactly.
namespace {
std::vector<std::vector<std::string>> read_rfc4180(const std::string& text) {
  std::vector<std::vector<std::string>> rows(1, std::vector<std::string>(1));
  bool quoted = false;
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (quoted) {
      if (c == '"' && i + 1 < text.size() && text[i + 1] == '"') rows.back().back() += '"', ++i;
      else if (c == '"') quoted = false;
      else rows.back().back() += c;
    } else if (c == '"') quoted = true;
    else if (c == ',') rows.back().emplace_back();
    else if (c == '\n') rows.emplace_back(1);
    else rows.back().back() += c;
  }
  if (rows.back().size() == 1 && rows.back()[0].empty()) rows.pop_back();
  return rows;
}
}  // namespace

TEST(Sinks, PlotDataCsvKeepsEveryLabelInItsField) {
  for (const auto& s : hostile_strings()) {
    quadgen::runtime::Panel p{s, s, s, {{s, {0, 1, 2}, {1.25, -0.5, 1e-300}}}};
    const auto rows = read_rfc4180(quadgen::runtime::panels_csv(s, {p}));
    ASSERT_EQ(rows.size(), 4u) << out::printable(s);
    for (const auto& r : rows) ASSERT_EQ(r.size(), 7u) << out::printable(s);
    const bool formula = !s.empty() && std::string("=+-@").find(s[0]) != std::string::npos;
    for (int f = 0; f < 5; ++f) {
      const std::string& label = rows[1][f];
      if (formula) EXPECT_EQ(label.substr(0, 1), "'") << out::printable(s);
      // Text that needs no repair (no control character, valid UTF-8) comes back as it was.
      if (out::printable(s) == s) EXPECT_EQ(formula ? label.substr(1) : label, s);
    }
    EXPECT_EQ(std::stod(rows[2][5]), 1.0);
    EXPECT_EQ(std::stod(rows[2][6]), -0.5);
    EXPECT_EQ(std::stod(rows[3][6]), 1e-300);
  }
  const auto rows = read_rfc4180(quadgen::runtime::panels_csv("t", {{"a,b", "t [s]", "m", {{"say \"hi\"", {1}, {2}}}}}));
  EXPECT_EQ(rows[1][1], "a,b");
  EXPECT_EQ(rows[1][4], "say \"hi\"");
  EXPECT_EQ(read_rfc4180(out::csv_field("=HYPERLINK(1)"))[0][0], "'=HYPERLINK(1)");
  EXPECT_EQ(read_rfc4180(out::csv_field("a\nb"))[0][0], "a b");
  EXPECT_EQ(read_rfc4180(out::csv_field(" \t=1+1"))[0][0], "'  =1+1");  // blanks do not hide a formula
  EXPECT_EQ(read_rfc4180(out::csv_field("a=1"))[0][0], "a=1");
}

// JSON: valid whatever the bytes, and the line separators, valid in a JSON string but a line
// break to older JavaScript and to some editors, escaped; the string reads back unchanged.
TEST(Sinks, JsonEscapesTheLineSeparators) {
  for (const auto& s : hostile_strings()) {
    const std::string doc = out::json_document(nlohmann::json{{"path", s}});
    EXPECT_EQ(doc.find("\xe2\x80\xa8"), std::string::npos) << out::printable(s);
    EXPECT_EQ(doc.find("\xe2\x80\xa9"), std::string::npos) << out::printable(s);
    const auto back = nlohmann::json::parse(doc)["path"].get<std::string>();
    if (s.find('\xff') == std::string::npos) EXPECT_EQ(back, s) << out::printable(s);  // invalid UTF-8 is replaced
  }
  EXPECT_EQ(out::json_document(nlohmann::json{{"a", "x\xe2\x80\xa8y\xe2\x80\xa9z\xe2\x80\xa6"}}),
            "{\n  \"a\": \"x\\u2028y\\u2029z\xe2\x80\xa6\"\n}\n");  // U+2026, an ellipsis, kept
}

TEST(Sinks, HtmlReportQuotesNoMarkup) {
  quadgen::diagnose::Diagnosis d;
  for (const auto& s : hostile_strings()) {
    d.vehicle = s;
    const std::string html = quadgen::diagnose::diagnosis_html(d, s, {{s, "<svg></svg>"}});
    EXPECT_EQ(html.find("<script>alert"), std::string::npos) << out::printable(s);
    EXPECT_EQ(html.find("<img"), std::string::npos) << out::printable(s);
    // The JSON beside it stays valid JSON whatever the bytes of the path.
    EXPECT_NO_THROW(nlohmann::json::parse(out::json_document(quadgen::diagnose::diagnosis_json(d, s))));
  }
  // Filled where paths reach a diagnosis (the flights, the airframe file, the screening's
  // reasons), in the report and its JSON: the empty diagnosis above has none of these sections.
  for (const auto& s : hostile_strings()) {
    quadgen::diagnose::Diagnosis f;
    f.vehicle = "finken3";
    f.flights = {s, s + "2"};
    f.airframe_source = s;
    f.screening = {{s, 0.4, false, "commands saturated in " + s, true}, {s + "2", 0, true, "", false}};
    const std::string html = quadgen::diagnose::diagnosis_html(f, s, {{s, "<svg></svg>"}});
    EXPECT_EQ(html.find("<script>alert"), std::string::npos) << out::printable(s);
    EXPECT_EQ(html.find("<img"), std::string::npos) << out::printable(s);
    EXPECT_NO_THROW(nlohmann::json::parse(out::json_document(quadgen::diagnose::diagnosis_json(f, s))));
    // The terminal summary quotes the paths: as the commands print it (printable_lines), no
    // escape sequence or other control reaches the terminal and the lines stay lines.
    const std::string text = out::printable_lines(quadgen::diagnose::diagnosis_summary(f));
    for (char c : text) EXPECT_TRUE(c == '\n' || static_cast<unsigned char>(c) >= 0x20) << out::printable(text);
  }
  EXPECT_EQ(out::printable_lines("a\x1b[31m\nb\n"), "a\\x1B[31m\nb\n");
}

TEST(Sinks, MarkdownAndLatexTextStayText) {
  for (const auto& s : hostile_strings()) {
    const std::string md = out::markdown_text(s);
    EXPECT_EQ(md.find('\n'), std::string::npos);
    for (size_t i = 0; i < md.size(); ++i)
      if (md[i] == '|' || md[i] == '`' || md[i] == '$' || md[i] == '<' || md[i] == '>' || md[i] == '&')
        EXPECT_TRUE(i > 0 && md[i - 1] == '\\') << md;
    // In math mode every backslash starts an escape or a command math mode has (a text-mode
    // command such as \textbackslash is an error there), and every special is escaped.
    const std::string tex = out::latex_math_text(s);
    for (size_t i = 0; i < tex.size(); ++i) {
      if (tex[i] == '\\') {
        const std::string rest = tex.substr(i + 1);
        const bool command = rest.rfind("backslash{}", 0) == 0 || rest.rfind("sim{}", 0) == 0 || rest.rfind("wedge{}", 0) == 0;
        EXPECT_TRUE(command || (!rest.empty() && std::string("$&%#_{} ").find(rest[0]) != std::string::npos)) << tex;
        i += command ? rest.find('}') + 1 : 1;
      } else {
        EXPECT_EQ(std::string("$&%#_{}~^\n").find(tex[i]), std::string::npos) << tex;
      }
    }
  }
  // The derivation report of a vehicle with a hostile description.
  quadgen::Vehicle v = quadgen::test::finken3();
  v.description = "</p><script>alert(1)</script> | $x$ `code`";
  const auto mp = quadgen::derive_mass_properties(v);
  const auto model = quadgen::derive_model(v, mp, {});
  const quadgen::AuditResult no_audit;
  const std::vector<quadgen::ThesisItem> no_thesis;
  const quadgen::runtime::HoverTrim no_trim;
  const quadgen::Derivation d{v, mp, model, no_audit, no_thesis, no_trim};
  const std::string md = quadgen::derivation_markdown(d);
  EXPECT_EQ(md.find("<script>"), std::string::npos);
  EXPECT_NE(md.find("\\<script\\>"), std::string::npos);
}

// GitHub's autolinks (extended: bare https://, www., e-mail addresses) turn a description
// into a clickable link; escaped, they stay text. The escapes are what CommonMark defines for
// ASCII punctuation, so the text reads the same.
TEST(Sinks, MarkdownLeavesNoBareLink) {
  EXPECT_EQ(out::markdown_text("see https://evil.example/x"), "see https\\://evil.example/x");
  EXPECT_EQ(out::markdown_text("WWW.evil.example"), "WWW\\.evil.example");
  EXPECT_EQ(out::markdown_text("me@evil.example"), "me\\@\xE2\x81\xA0" "evil.example");
  EXPECT_EQ(out::markdown_text("a.b www, ratio 1:2"), "a.b www, ratio 1:2");  // a '.' or ':' elsewhere stays
}

// The escaped text rendered as GitHub renders Markdown (cmark-gfm with GitHub's extensions;
// one of the project's test dependencies): no link, image, heading, list, code, rule, table,
// strike-through or raw HTML comes of it. The escapes alone once left name@host a link.
TEST(Sinks, MarkdownRendersAsOneParagraphOfText) {
  Scratch tmp;
  std::vector<std::string> texts = hostile_strings();
  for (const char* s : {"a@b.co mailto:a@b.co xmpp:a@b.co/c", "    four blanks", "see https://x.example/y www.x.example",
                        "[l](http://x.example) ![i](x.png) <http://x.example>", "`c` ~~s~~ *e* _e_", "| a | b |\n|---|---|",
                        "# h", "- li", "1. li", "***", "<b>raw</b> &amp; &#64;", "x\n===", "$x$ \\(y\\)"})
    texts.push_back(s);
  for (const auto& s : texts) {
    const fs::path file = tmp.dir / "d.md";
    write(file.string(), "before\n\n" + out::markdown_text(s) + "\n\nafter\n");
    FILE* p = ::popen(("cmark-gfm -e autolink -e table -e strikethrough -e tagfilter " + file.string()).c_str(), "r");
    ASSERT_NE(p, nullptr);
    std::string html;
    char buf[4096];
    for (size_t n; (n = std::fread(buf, 1, sizeof buf, p)) > 0;) html.append(buf, n);
    ASSERT_EQ(::pclose(p), 0) << "cmark-gfm is a test dependency (scripts/install-deps.sh)";
    for (const char* tag : {"<a ", "<img", "<h1", "<h2", "<ul", "<ol", "<pre", "<code", "<hr", "<table", "<del", "<em",
                            "<strong", "<b>", "<!--", "<script"})
      EXPECT_EQ(html.find(tag), std::string::npos) << tag << " from " << out::printable(s) << ":\n" << out::printable(html);
    EXPECT_EQ(html.rfind("<p>before</p>\n<p>", 0), 0u) << out::printable(html);
  }
  // And it reads as written, rendered and raw: a reviewer reads derivation.md in an editor
  // too, where "&#39;" and "&lt;" stood for ' and < (the escapes now CommonMark's backslashes).
  const std::string plain = "the model's J, a_y < 0 & \"x\" > 1";
  EXPECT_EQ(out::markdown_text(plain), "the model's J, a\\_y \\< 0 \\& \"x\" \\> 1");
  const fs::path file = tmp.dir / "plain.md";
  write(file.string(), out::markdown_text(plain) + "\n");
  FILE* p = ::popen(("cmark-gfm " + file.string()).c_str(), "r");
  ASSERT_NE(p, nullptr);
  std::string html;
  char buf[4096];
  for (size_t n; (n = std::fread(buf, 1, sizeof buf, p)) > 0;) html.append(buf, n);
  ASSERT_EQ(::pclose(p), 0);
  EXPECT_EQ(html, "<p>the model's J, a_y &lt; 0 &amp; &quot;x&quot; &gt; 1</p>\n");
}

// What opens a block at the start of a line is escaped there (a description is a paragraph
// of its own in derivation.md): "# Owned heading" rendered as a heading.
TEST(Sinks, MarkdownLineStartsOpenNoBlock) {
  EXPECT_EQ(out::markdown_text("# Owned heading"), "\\# Owned heading");
  EXPECT_EQ(out::markdown_text("  - item"), "\\- item");
  EXPECT_EQ(out::markdown_text("    indented code"), "indented code");
  EXPECT_EQ(out::markdown_text("+ item"), "\\+ item");
  EXPECT_EQ(out::markdown_text("=== rule"), "\\=== rule");
  EXPECT_EQ(out::markdown_text("12. item"), "12\\. item");
  EXPECT_EQ(out::markdown_text("3) item"), "3\\) item");
  EXPECT_EQ(out::markdown_text("---"), "\\---");
  // Behind what the output turns into blanks (a tab, a line break, a control character).
  EXPECT_EQ(out::markdown_text("\t# Owned").find("\\#"), 0u);
  EXPECT_EQ(out::markdown_text("\n\x01# Owned").find("\\#"), 0u);
  // Inside the text, or not followed by a blank, they are text (numbers in table cells).
  EXPECT_EQ(out::markdown_text("a-b #3 v1.2"), "a-b #3 v1.2");
  EXPECT_EQ(out::markdown_text("-26 %, 0.2 N, #3"), "-26 %, 0.2 N, #3");
}

// HTML shows the bidirectional controls instead of obeying them (a log named with U+202E
// reordered the report's heading), and <pre> keeps its lines (the verdict block was one line).
// A control character shows as a blank in a CSV field, and some spreadsheets skip blanks, Unicode
// spaces and zero-width characters before a formula's '=': none of them hides a formula.
TEST(Sinks, CsvFormulaGuardSeesThroughEverythingThatLooksBlank) {
  for (const std::string& lead : {std::string("\x01"), std::string("\x1b"), std::string(" \t"), std::string("\xC2\xA0"),
                                  std::string("\xE2\x80\x8B"), std::string("\xEF\xBB\xBF"), std::string("\xE3\x80\x80")})
    for (const std::string& formula : {"=cmd|' /C calc'!A0", "+SUM(1,2)", "-1+1", "@SUM(1)"}) {
      const std::string field = read_rfc4180(out::csv_field(lead + formula))[0][0];
      EXPECT_EQ(field.substr(0, 1), "'") << out::printable(lead + formula);
    }
  EXPECT_EQ(read_rfc4180(out::csv_field("\x01=cmd"))[0][0], "' =cmd");
  EXPECT_EQ(read_rfc4180(out::csv_field("a\xC2\xA0=1"))[0][0], "a\xC2\xA0=1");
  // A bidirectional override is shown, not obeyed, and then hides nothing either.
  const std::string bidi = read_rfc4180(out::csv_field("\xE2\x80\xAE=1"))[0][0];
  EXPECT_EQ(bidi, "\\xE2\\x80\\xAE=1");
}

// The SVG gnuplot draws is pasted into report.html: a label's bidi controls must not reorder it.
TEST(Sinks, GnuplotStringShowsBidiControls) {
  for (const auto& s : hostile_strings()) {
    const std::string g = out::gnuplot_string(s);
    for (const char* bidi : {"\xE2\x80\xAE", "\xE2\x81\xA6", "\xE2\x80\x8F", "\xD8\x9C", "\xC2\x9B"})
      EXPECT_EQ(g.find(bidi), std::string::npos) << out::printable(s);
  }
  EXPECT_EQ(out::gnuplot_string("a\xE2\x80\xAE" "b"), "'a\\xE2\\x80\\xAEb'");
  // A character reference in a name reaches the SVG as text, not as the character: gnuplot's
  // SVG terminal passes "&#x" through (it decoded U+202E into report.html, and "&#x0;" broke
  // the SVG). gnuplot is one of the project's dependencies (scripts/install-deps.sh).
  EXPECT_EQ(out::gnuplot_string("x&#x202E;y & z"), "'x&#x26;#x202E;y & z'");
  std::string svg, error;
  const std::vector<double> t{0, 1, 2};
  quadgen::runtime::Panel panel;
  panel.title = "log y&#x0;.csv";
  panel.series.push_back({"x&#x202E;vsc.gol", t, t});
  ASSERT_TRUE(quadgen::runtime::render_svg("replay of x&#x202E;vsc.gol.csv", {panel}, &svg, &error)) << error;
  EXPECT_EQ(svg.find("&#x202E;"), std::string::npos);
  EXPECT_EQ(svg.find("&#x0;"), std::string::npos);
  EXPECT_NE(svg.find("x&#x26;#x202E;vsc.gol"), std::string::npos) << svg.substr(0, 2000);
  // The series' tooltip (a <title> element, where gnuplot escapes every &) shows the name too.
  EXPECT_NE(svg.find("<title>x&amp;#x202E;vsc.gol</title>"), std::string::npos) << svg;
  EXPECT_EQ(svg.find("&amp;#x26;"), std::string::npos);
  EXPECT_EQ(out::gnuplot_svg_tooltips_mended("<text>a&#x26;#x1;</text><title>a&amp;#x26;#x1; &amp;#x26;</title>&amp;#x26;<title>"),
            "<text>a&#x26;#x1;</text><title>a&amp;#x1; &amp;</title>&amp;#x26;<title>");
  // Names that hold the workaround's own text keep it, drawn and in their tooltips.
  quadgen::runtime::Panel own;
  own.series.push_back({"p&#x26;q", t, t});
  own.series.push_back({"r&amp;#x26;s", t, {2, 1, 0}});
  ASSERT_TRUE(quadgen::runtime::render_svg("own", {own}, &svg, &error)) << error;
  EXPECT_NE(svg.find("<title>p&amp;#x26;q</title>"), std::string::npos) << svg;
  EXPECT_NE(svg.find("<title>r&amp;amp;#x26;s</title>"), std::string::npos) << svg;
  EXPECT_NE(svg.find("p&#x26;#x26;q"), std::string::npos);  // drawn: p&#x26;q
}

TEST(Sinks, HtmlShowsBidiControlsAndPreformattedTextKeepsItsLines) {
  EXPECT_EQ(out::html_text("log\xe2\x80\xae" "vsc.csv"), "log\\xE2\\x80\\xAEvsc.csv");
  EXPECT_EQ(out::html_text("a\xe2\x80\x8f" "b"), "a\\xE2\\x80\\x8Fb");
  EXPECT_EQ(out::html_preformatted("named:\n  <x> & y\x1b[2J"), "named:\n  &lt;x&gt; &amp; y[2J");
  EXPECT_EQ(out::html_text("a\nb"), "a b");
  quadgen::diagnose::Diagnosis d;
  const std::string html = quadgen::diagnose::diagnosis_html(d, "log\xe2\x80\xae" "vsc.csv", {});
  EXPECT_EQ(html.find("\xe2\x80\xae"), std::string::npos);
  const size_t pre = html.find("<pre>"), end = html.find("</pre>", pre);
  ASSERT_NE(pre, std::string::npos);
  EXPECT_NE(html.substr(pre, end - pre).find('\n'), std::string::npos) << "the verdict block lost its lines";
}

// The header's regenerate command is one a reader may paste: each path one shell word. Checked
// by a shell: `printf %s WORD` must print the string itself, and run nothing.
TEST(Sinks, ShellWordsAreOneWordToAShell) {
  Scratch tmp;
  EXPECT_EQ(out::shell_path("vehicles/cf2.yaml"), "vehicles/cf2.yaml");
  EXPECT_EQ(out::shell_path("a b'c"), "'a b'\\''c'");
  EXPECT_EQ(out::shell_path(""), "''");
  EXPECT_EQ(out::shell_path("-v.yaml"), "./-v.yaml");
  EXPECT_EQ(out::shell_path("=v.yaml"), "'=v.yaml'");  // zsh would expand =word to a command's path
  EXPECT_EQ(out::shell_path("a=v.yaml"), "a=v.yaml");
  std::vector<std::string> strings = hostile_strings();
  strings.push_back("v $(touch PWNED);`touch PWNED`|x.yaml");
  for (const auto& s : strings) {
    if (s.find('\0') != std::string::npos) continue;  // no shell word holds a NUL
    const fs::path script = tmp.dir / "run.sh", got = tmp.dir / "got";
    write(script, "printf %s " + out::shell_path(s) + " > '" + got.string() + "'\n");  // (no hostile string starts with '-')
    ASSERT_EQ(std::system(("cd '" + tmp.dir.string() + "' && sh '" + script.string() + "'").c_str()), 0) << out::printable(s);
    EXPECT_EQ(read(got), s) << out::printable(s);
    EXPECT_FALSE(fs::exists(tmp.dir / "PWNED")) << out::printable(s);
  }
  // In the header: quoted where needed, a placeholder where the comment cannot hold the path.
  const quadgen::Vehicle v = quadgen::test::finken3();
  const auto model = quadgen::derive_model(v, quadgen::derive_mass_properties(v), {});
  quadgen::codegen::EmitOptions o;
  o.vehicle_file = "my vehicles/cf $(x).yaml";
  EXPECT_NE(quadgen::codegen::generate_header(model, o).content.find("quadgen derive 'my vehicles/cf $(x).yaml' --out <folder>"),
            std::string::npos);
  o.vehicle_file = "v\xe2\x80\xae.yaml";
  EXPECT_NE(quadgen::codegen::generate_header(model, o).content.find("quadgen derive VEHICLE_FILE --out <folder>"),
            std::string::npos);
}

// A command line CLI11 refuses is reported in one printable line, like every other error.
TEST(Cli, ParseErrorsQuoteNoControlCharacters) {
  Scratch tmp;
  const std::string vehicle = std::string(QUADGEN_SOURCE_DIR) + "/vehicles/finken3.yaml";
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"derive", vehicle, "--out", tmp / "o", "--bogus\x1b[2J\x1b]0;X\x07"},
        std::vector<std::string>{"diagnose", vehicle, "l.csv", "--out", tmp / "o", "--translational", "\x1b[31mx\nquadgen: fake"},
        std::vector<std::string>{"simulate", vehicle, "--duration", "1\x1b[31m", "--out", tmp / "o.csv"}}) {
    const CliResult r = run_quadgen(args, tmp.dir);
    EXPECT_NE(r.rc, 0);
    EXPECT_EQ(r.err.find('\x1b'), std::string::npos) << out::printable(r.err);
    EXPECT_EQ(r.err.rfind("quadgen: error: ", 0), 0u) << out::printable(r.err);
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 2) << out::printable(r.err);  // the error and the hint
  }
  // A hostile --out is refused (a control character in a folder's name, as in simulate's file
  // names; a review, helper-135), in a line that shows it as escapes; one with only printable
  // oddities reaches the progress lines escaped too.
  const CliResult r = run_quadgen({"derive", vehicle, "--out", tmp / "o\x1b[31mRED"}, tmp.dir);
  EXPECT_NE(r.rc, 0);
  EXPECT_NE(r.err.find("cannot be an output folder name"), std::string::npos) << out::printable(r.err);
  EXPECT_EQ(r.err.find('\x1b'), std::string::npos) << out::printable(r.err);
  EXPECT_FALSE(fs::exists(tmp / "o\x1b[31mRED"));
  for (const char* slip : {"o ", " o", "o\nx", "p \n/o"}) {  // the last: a parent the run would create
    const CliResult refused = run_quadgen({"derive", vehicle, "--out", tmp / slip}, tmp.dir);
    EXPECT_NE(refused.rc, 0) << out::printable(slip);
    EXPECT_NE(refused.err.find("cannot be an output folder name"), std::string::npos) << out::printable(refused.err);
    EXPECT_FALSE(fs::exists(tmp / std::string(slip).substr(0, std::string(slip).find('/')))) << out::printable(slip);
  }
  const CliResult odd = run_quadgen({"derive", vehicle, "--out", tmp / "o\xe2\x80\xae$(x)"}, tmp.dir);
  EXPECT_EQ(odd.rc, 0) << out::printable(odd.err);
  EXPECT_EQ(odd.err.find("\xe2\x80\xae"), std::string::npos) << out::printable(odd.err);
}

// Whole numbers on the command line are decimal: CLI11 alone read "011" as octal 9 and "0x2"
// as 2 (--max-effects 010 ran with 8; a hostile-input audit, helper-161), and told "abc" it
// was "not in range". Refused before any work, with what was expected.
TEST(Cli, WholeNumbersAreDecimalDigits) {
  Scratch tmp;
  const std::string vehicle = std::string(QUADGEN_SOURCE_DIR) + "/vehicles/finken3.yaml";
  const auto diagnose_with = [&](const std::string& n) {
    return run_quadgen({"diagnose", vehicle, tmp / "none.csv", "--out", tmp / "o", "--max-effects", n}, tmp.dir);
  };
  for (const char* not_a_number : {"0x2", "abc", "1e1", "5.0", ""}) {
    const CliResult r = diagnose_with(not_a_number);
    EXPECT_NE(r.rc, 0) << not_a_number;
    EXPECT_NE(r.err.find("is not a whole number in decimal digits (accepted: [1, 10])"), std::string::npos)
        << out::printable(r.err);
  }
  for (const char* outside : {"011", "0", "-1", "99999999999999999999"}) {
    const CliResult r = diagnose_with(outside);
    EXPECT_NE(r.rc, 0) << outside;
    EXPECT_NE(r.err.find(std::string(outside) + " is outside the accepted range [1, 10]"), std::string::npos)
        << out::printable(r.err);
  }
  // "010" is ten: accepted, and the run goes on to the missing log.
  const CliResult ten = diagnose_with("010");
  EXPECT_NE(ten.err.find("none.csv"), std::string::npos) << out::printable(ten.err);
  EXPECT_FALSE(fs::exists(tmp / "o"));
  const CliResult hex_seed = run_quadgen({"simulate", vehicle, "--seed", "0x10", "--out", tmp / "s.csv"}, tmp.dir);
  EXPECT_NE(hex_seed.err.find("'0x10' is not a whole number"), std::string::npos) << out::printable(hex_seed.err);
}

// A name of 200 kB is refused in a line a person can read: its head (where, what) and its tail
// (what was expected), the bytes between them counted, not printed (a review of the eighth
// audit: a 200 kB block name gave a 200 kB error line); a cut never splits a UTF-8 character.
TEST(Cli, AHugeNameGivesAnErrorLineOfReadableLength) {
  Scratch tmp;
  std::string text = read(source_path("vehicles/finken3.yaml"));
  const std::string block = "{name: upper_body,";
  ASSERT_NE(text.find(block), std::string::npos);
  const std::string line = std::to_string(1 + std::count(text.begin(), text.begin() + text.find(block), '\n'));
  text.replace(text.find(block), block.size(), "{name: " + std::string(200000, 'a') + ",");
  write(tmp.dir / "huge.yaml", text);
  const CliResult r = run_quadgen({"derive", tmp / "huge.yaml", "--out", tmp / "o"}, tmp.dir);
  EXPECT_NE(r.rc, 0);
  EXPECT_LT(r.err.size(), 2000u) << r.err.substr(0, 300);
  EXPECT_EQ(r.err.rfind("quadgen: error: ", 0), 0u) << r.err.substr(0, 300);
  EXPECT_NE(r.err.find("huge.yaml:" + line + ":"), std::string::npos) << r.err.substr(0, 300);
  EXPECT_NE(r.err.find(" bytes left out ...] aaa"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(std::string("(allowed: ") + out::name_rule() + ")\n"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(tmp / "o"));
  // Three- and four-byte characters after 0 to 3 ASCII bytes: some cut falls inside a
  // character, which would print as '?' had the cut not moved to a character's start.
  for (const std::string c : {"\xe2\x82\xac", "\xf0\x9f\x98\x80"})
    for (size_t ascii = 0; ascii < 4; ++ascii) {
      std::string e(ascii, 'x');
      for (int i = 0; i < 1500; ++i) e += c;
      e += std::string(ascii, 'y');  // so that the tail's cut moves too
      const std::string shown = out::printable_error(e);
      EXPECT_NE(shown.find("bytes left out"), std::string::npos);
      EXPECT_EQ(shown.find('?'), std::string::npos) << ascii << " " << c.size();
    }
  EXPECT_EQ(out::printable_error("short\n"), "short\\x0A");
  // A log's cell quoted in a message: its head cut on a whole character too.
  EXPECT_EQ(out::printable_head("ab\xe2\x82\xac", 4), "ab...");
  EXPECT_EQ(out::printable_head("ab\xe2\x82\xac", 5), "ab\xe2\x82\xac");
  EXPECT_EQ(out::printable_head("a\tb", 40), "a\\x09b");
}

// ... and their colour and marker (a review, helper-107: a thinned series was drawn in
// gnuplot's next colour, not its model's).
TEST(Sinks, LongSeriesAreThinnedKeepingTheirExtremes) {
  quadgen::runtime::Series s{"long", {}, {}, true, "#1f77b4", 9};
  for (int i = 0; i < 1000000; ++i) s.x.push_back(i), s.y.push_back(i == 123457 ? 50.0 : std::sin(i * 1e-3));
  const auto d = quadgen::runtime::decimated(s);
  EXPECT_LE(d.x.size(), quadgen::runtime::kMaxPlotPointsPerSeries);
  EXPECT_EQ(*std::max_element(d.y.begin(), d.y.end()), 50.0);
  EXPECT_TRUE(std::is_sorted(d.x.begin(), d.x.end()));
  EXPECT_EQ(d.color, "#1f77b4");
  EXPECT_EQ(d.marker, 9);
  EXPECT_TRUE(d.points);
  const std::string script = quadgen::runtime::gnuplot_script("t", {{"p", "x", "y", {s}}});
  EXPECT_LT(script.size(), 200000u);
  EXPECT_NE(script.find("points pt 9 ps 0.5 lc rgb '#1f77b4'"), std::string::npos);
}

// ---- data loss -----------------------------------------------------------------------------

TEST(DataLoss, SimulateRefusesToWriteOverItsInputs) {
  Scratch tmp;
  const std::string vehicle = tmp / "v.yaml";
  fs::copy_file(source_path("vehicles/finken3.yaml"), vehicle);
  ASSERT_EQ(run_quadgen({"simulate", vehicle, "--scenario", "hover", "--duration", "0.2", "--out", tmp / "log.csv"}, tmp.dir).rc, 0);
  const std::string log = tmp / "log.csv";
  const std::string v_before = read(vehicle), log_before = read(log);
  fs::create_hard_link(log, tmp / "hardlink.csv");
  fs::create_symlink(vehicle, tmp / "symlink.csv");
  const std::vector<std::vector<std::string>> cases = {
      {"simulate", vehicle, "--inputs", log, "--duration", "0.1", "--out", log},
      {"simulate", vehicle, "--inputs", log, "--duration", "0.1", "--out", "./log.csv"},
      {"simulate", vehicle, "--inputs", log, "--duration", "0.1", "--out", tmp / "hardlink.csv"},
      {"simulate", vehicle, "--scenario", "hover", "--duration", "0.1", "--out", vehicle},
      {"simulate", vehicle, "--scenario", "hover", "--duration", "0.1", "--out", tmp / "symlink.csv"},
      {"simulate", vehicle, "--scenario", "hover", "--duration", "0.1", "--out", tmp / "x.svg"},
  };
  for (const auto& c : cases) {
    const CliResult r = run_quadgen(c, tmp.dir);
    expect_one_line_error(r, "", c.back());
    EXPECT_EQ(read(vehicle), v_before) << c.back();
    EXPECT_EQ(read(log), log_before) << c.back();
  }
  EXPECT_FALSE(fs::exists(tmp / "x.svg"));
}

// An output folder that holds an input, by its path or as a hard link to it, is refused for
// that reason, before the folder's other files are judged (helper-126: the simulate cases
// above are each refused by another check as well, so these two branches never decided).
TEST(DataLoss, AnOutputFolderHoldingAnInputIsRefusedForThat) {
  Scratch tmp;
  fs::create_directories(tmp / "inside");
  fs::create_directories(tmp / "linked");
  const std::string inside = tmp / "inside/v.yaml", vehicle = tmp / "v.yaml";
  fs::copy_file(source_path("vehicles/finken3.yaml"), inside);
  fs::copy_file(source_path("vehicles/finken3.yaml"), vehicle);
  fs::create_hard_link(vehicle, tmp / "linked/copy.yaml");
  const std::string before = read(inside);
  expect_one_line_error(run_quadgen({"derive", inside, "--out", tmp / "inside"}, tmp.dir), "is or contains the input",
                        "an input inside the folder");
  expect_one_line_error(run_quadgen({"derive", vehicle, "--out", tmp / "linked"}, tmp.dir), "(a link to it)",
                        "a hard link to the input inside the folder");
  EXPECT_EQ(read(inside), before);
  EXPECT_EQ(read(vehicle), before);
  EXPECT_EQ(fs::directory_iterator(tmp / "inside")->path().filename(), "v.yaml");
}

// `link/../x` is x beside the link's target for the kernel; an output path resolved
// lexically first (the '..' dropping the link) wrote beside the link instead, so the files
// were not where the path the user gave (and the one quadgen printed) leads.
TEST(DataLoss, AnOutputPathIsResolvedAsTheFileSystemResolvesIt) {
  Scratch tmp;
  const std::string vehicle = tmp / "v.yaml";
  fs::copy_file(source_path("vehicles/finken3.yaml"), vehicle);
  fs::create_directories(tmp.dir / "far/dir");
  fs::create_directory_symlink(tmp.dir / "far/dir", tmp.dir / "lnk");
  const CliResult sim =
      run_quadgen({"simulate", vehicle, "--scenario", "hover", "--duration", "0.1", "--out", "lnk/../z.csv"}, tmp.dir);
  ASSERT_EQ(sim.rc, 0) << sim.err;
  EXPECT_TRUE(fs::exists(tmp.dir / "far/z.csv"));
  EXPECT_FALSE(fs::exists(tmp.dir / "z.csv"));
  const CliResult der = run_quadgen({"derive", vehicle, "--out", "lnk/../zz"}, tmp.dir);
  ASSERT_EQ(der.rc, 0) << der.err;
  EXPECT_TRUE(fs::exists(tmp.dir / "far/zz/model.hpp"));
  EXPECT_FALSE(fs::exists(tmp.dir / "zz"));
  // A name longer than the file system takes is refused before the work, not when the output
  // is moved into place at the end.
  const std::string long_name(300, 'n');
  expect_one_line_error(run_quadgen({"derive", vehicle, "--out", long_name}, tmp.dir), "has a name of 300 bytes", "--out 300");
  expect_one_line_error(run_quadgen({"simulate", vehicle, "--scenario", "hover", "--duration", "0.1", "--out", long_name + ".csv"},
                                    tmp.dir),
                        "has a name of 304 bytes", "--out 300.csv");
  // A folder named with a '.' or '..' at its end, not there yet: the folder itself (resolved
  // with a trailing '/', it was made as the staging folder's parent and the finished output
  // could not move onto it).
  const CliResult dot = run_quadgen({"derive", vehicle, "--out", "new/."}, tmp.dir);
  ASSERT_EQ(dot.rc, 0) << dot.err;
  EXPECT_TRUE(fs::exists(tmp.dir / "new/model.hpp"));
  const CliResult up = run_quadgen({"derive", vehicle, "--out", "made/sub/.."}, tmp.dir);
  ASSERT_EQ(up.rc, 0) << up.err;
  EXPECT_TRUE(fs::exists(tmp.dir / "made/model.hpp"));
  // A symbolic link that leads nowhere is refused before the work (it failed with "Not a
  // directory" when the output was moved into place), and nothing is made where it points.
  // The same for a link on the way to the output, one that loops, and the simulation's
  // folder; a relative link's target is said from the working directory.
  fs::create_directory_symlink(tmp.dir / "gone/sub", tmp.dir / "dangling");
  fs::create_symlink("loop", tmp.dir / "loop");
  fs::create_symlink("gone/rel", tmp.dir / "relative");
  const std::string nowhere = "is a symbolic link to " + (tmp.dir / "gone/sub").string() + ", which leads nowhere";
  const std::vector<std::pair<std::vector<std::string>, std::string>> cases = {
      {{"derive", vehicle, "--out", "dangling"}, nowhere},
      {{"derive", vehicle, "--out", "dangling/deeper/still"}, nowhere},
      {{"simulate", vehicle, "--scenario", "hover", "--duration", "0.1", "--out", "dangling/t.csv"}, nowhere},
      {{"derive", vehicle, "--out", "relative"}, "is a symbolic link to " + (tmp.dir / "gone/rel").string() + ", which"},
      {{"derive", vehicle, "--out", "loop"}, "is a symbolic link that loops"},
  };
  for (const auto& [args, message] : cases) {
    const CliResult r = run_quadgen(args, tmp.dir);
    expect_one_line_error(r, message, args.back());
    EXPECT_EQ(r.err.find("generating C++"), std::string::npos) << r.err;
  }
  EXPECT_FALSE(fs::exists(tmp.dir / "gone"));
}

// One flight named twice (or through a hard or symbolic link) doubled its weight in the fit
// and had a joint diagnosis compare the flight with itself.
TEST(DataLoss, ALogNamedTwiceIsRefused) {
  Scratch tmp;
  const std::string vehicle = tmp / "v.yaml";
  fs::copy_file(source_path("vehicles/finken3.yaml"), vehicle);
  ASSERT_EQ(run_quadgen({"simulate", vehicle, "--scenario", "hover", "--duration", "0.2", "--out", "a.csv"}, tmp.dir).rc, 0);
  fs::create_hard_link(tmp.dir / "a.csv", tmp.dir / "hard.csv");
  fs::create_symlink("a.csv", tmp.dir / "sym.csv");
  for (const std::string& second : {"a.csv", "hard.csv", "sym.csv"})
    for (const std::string& command : {"diagnose", "predict"}) {
      const CliResult r = run_quadgen({command, vehicle, "a.csv", second, "--out", "out"}, tmp.dir);
      expect_one_line_error(r, second + ": the same file as a.csv", command + " a.csv " + second);
      EXPECT_FALSE(fs::exists(tmp.dir / "out")) << command << " " << second;
    }
}

TEST(DataLoss, OutputDirectoriesHoldingOtherFilesOrInputsAreRefused) {
  Scratch tmp;
  const std::string vehicle = tmp / "v.yaml";
  fs::copy_file(source_path("vehicles/finken3.yaml"), vehicle);
  fs::create_directories(tmp / "mine");
  write(tmp / "mine/notes.txt", "my notes");
  const CliResult foreign = run_quadgen({"derive", vehicle, "--out", tmp / "mine"}, tmp.dir);
  expect_one_line_error(foreign, "holds files quadgen did not write (notes.txt)", "foreign files");
  EXPECT_EQ(read(tmp / "mine/notes.txt"), "my notes");
  expect_one_line_error(run_quadgen({"derive", vehicle, "--out", "."}, tmp.dir), "working directory", "--out .");
  expect_one_line_error(run_quadgen({"derive", vehicle, "--out", tmp.dir.string()}, tmp.dir), "", "--out holding the input");
  expect_one_line_error(run_quadgen({"derive", vehicle, "--out", vehicle}, tmp.dir), "is or contains the input", "--out = input");
  // The earlier run of quadgen itself is replaced.
  ASSERT_EQ(run_quadgen({"derive", vehicle, "--out", tmp / "d"}, tmp.dir).rc, 0);
  ASSERT_EQ(run_quadgen({"derive", vehicle, "--out", tmp / "d", "--effects", "motor_lag"}, tmp.dir).rc, 0);
  EXPECT_TRUE(out::complete_output_directory(tmp / "d"));
  EXPECT_NE(read(tmp / "d/model.hpp").find("motor_lag"), std::string::npos);
  // Nothing but the outputs beside them: no staging directories, no temporaries.
  for (const auto& e : fs::directory_iterator(tmp.dir))
    EXPECT_EQ(e.path().filename().string().find(".quadgen-tmp."), std::string::npos) << e.path();
}

// An edited manifest cannot turn the removal of the earlier run into the removal of files
// elsewhere: a name with a path in it marks the directory as not quadgen's.
TEST(DataLoss, ManifestNamingPathsRemovesNothingOutsideTheDirectory) {
  Scratch tmp;
  const std::string vehicle = source_path("vehicles/finken3.yaml");
  ASSERT_EQ(run_quadgen({"derive", vehicle, "--out", tmp / "d"}, tmp.dir).rc, 0);
  write(tmp / "victim.txt", "keep me");
  write(tmp / "absolute_victim.txt", "keep me too");
  const std::string manifest = read(tmp / "d/.quadgen-manifest");
  for (const std::string& line : {std::string("0 0 ../victim.txt"), "0 0 " + (tmp / "absolute_victim.txt"), std::string("0 0 ..")}) {
    write(tmp / "d/.quadgen-manifest", manifest + line + "\n");
    expect_one_line_error(run_quadgen({"derive", vehicle, "--out", tmp / "d"}, tmp.dir), "is not one quadgen writes", line);
    EXPECT_EQ(read(tmp / "victim.txt"), "keep me");
    EXPECT_EQ(read(tmp / "absolute_victim.txt"), "keep me too");
    EXPECT_TRUE(fs::exists(tmp / "d/model.hpp"));
  }
  std::string why;
  EXPECT_FALSE(out::complete_output_directory(tmp / "d", &why));
  EXPECT_NE(why.find("manifest"), std::string::npos) << why;
}

// What a manifest is and what sits beside it in the folder decide, not what the names say: a
// link in the folder is not quadgen's, a manifest that is a FIFO is refused without blocking,
// blank lines and CRLF are read, and a manifest from before the command was recorded is
// taken as the command its files show.
TEST(DataLoss, ManifestAndFolderAreReadWithCare) {
  Scratch tmp;
  const std::string vehicle = source_path("vehicles/finken3.yaml");
  ASSERT_EQ(run_quadgen({"derive", vehicle, "--out", tmp / "d"}, tmp.dir).rc, 0);
  const std::string manifest = read(tmp / "d/.quadgen-manifest");
  // A link with the listed name and content: not replaced (its target is the user's).
  write(tmp / "mine.json", read(tmp / "d/model.json"));
  fs::remove(tmp / "d/model.json");
  fs::create_symlink(tmp / "mine.json", tmp / "d/model.json");
  expect_one_line_error(run_quadgen({"derive", vehicle, "--out", tmp / "d"}, tmp.dir), "holds files quadgen did not write (model.json)",
                        "a link");
  EXPECT_TRUE(fs::is_symlink(tmp / "d/model.json"));
  fs::remove(tmp / "d/model.json");
  fs::copy_file(tmp / "mine.json", tmp / "d/model.json");
  // A FIFO manifest.
  fs::remove(tmp / "d/.quadgen-manifest");
  ASSERT_EQ(::mkfifo((tmp / "d/.quadgen-manifest").c_str(), 0600), 0);
  expect_one_line_error(run_quadgen({"derive", vehicle, "--out", tmp / "d"}, tmp.dir), "is not one quadgen writes", "a FIFO");
  fs::remove(tmp / "d/.quadgen-manifest");
  // CRLF and blank lines; then the same without the command line, as older versions wrote it.
  std::string crlf;
  for (char c : manifest) crlf += c == '\n' ? std::string("\r\n") : std::string(1, c);
  write(tmp / "d/.quadgen-manifest", crlf + "\r\n\n");
  ASSERT_EQ(run_quadgen({"derive", vehicle, "--out", tmp / "d"}, tmp.dir).rc, 0);
  const std::string current = read(tmp / "d/.quadgen-manifest");
  const size_t cmd = current.find("command derive\n");
  ASSERT_NE(cmd, std::string::npos);
  write(tmp / "d/.quadgen-manifest", current.substr(0, cmd) + current.substr(cmd + 15));
  expect_one_line_error(run_quadgen({"fit", vehicle, source_path("data/finken3_motor_steps.csv"), "--out", tmp / "d"}, tmp.dir),
                        "holds the output of 'quadgen derive'", "an older manifest");
  EXPECT_TRUE(out::complete_output_directory(tmp / "d"));
  // What the kill tests' judge must also refuse (helper-126): a listed file missing, and a
  // file the manifest does not list.
  std::string why;
  fs::rename(tmp / "d/model.json", tmp / "model.json.aside");
  EXPECT_FALSE(out::complete_output_directory(tmp / "d", &why));
  EXPECT_NE(why.find("missing"), std::string::npos) << why;
  fs::rename(tmp / "model.json.aside", tmp / "d/model.json");
  write(tmp / "d/extra.txt", "not quadgen's");
  EXPECT_FALSE(out::complete_output_directory(tmp / "d", &why));
  EXPECT_NE(why.find("extra.txt is not in the manifest"), std::string::npos) << why;
  fs::remove(tmp / "d/extra.txt");
  EXPECT_TRUE(out::complete_output_directory(tmp / "d"));
}

// A file of an earlier run that the user edited is theirs now: the run is refused, the edit kept.
TEST(DataLoss, EditedOutputAndAnotherCommandsOutputAreNotReplaced) {
  Scratch tmp;
  const std::string vehicle = source_path("vehicles/finken3.yaml");
  ASSERT_EQ(run_quadgen({"derive", vehicle, "--out", tmp / "d"}, tmp.dir).rc, 0);
  const std::string edited = read(tmp / "d/derivation.md") + "\nmy review notes\n";
  write(tmp / "d/derivation.md", edited);
  expect_one_line_error(run_quadgen({"derive", vehicle, "--out", tmp / "d"}, tmp.dir), "changed since quadgen wrote them (derivation.md)",
                        "edited output");
  EXPECT_EQ(read(tmp / "d/derivation.md"), edited);
  // Another command's folder (a diagnosis, a fit) is not thrown away by a derive, nor the reverse.
  ASSERT_EQ(run_quadgen({"derive", vehicle, "--out", tmp / "e"}, tmp.dir).rc, 0);
  const CliResult fit = run_quadgen({"fit", vehicle, source_path("data/finken3_motor_steps.csv"), "--out", tmp / "e"}, tmp.dir);
  expect_one_line_error(fit, "holds the output of 'quadgen derive'", "fit into a derivation");
  EXPECT_TRUE(out::complete_output_directory(tmp / "e"));
  EXPECT_NE(read(tmp / "e/.quadgen-manifest").find("\ncommand derive\n"), std::string::npos);
}

// An earlier run of the same command is replaced whole, and the run says so (a newcomer gave
// two diagnoses one --out and lost the first without a word); a first run says nothing.
TEST(DataLoss, ReplacingAnEarlierRunIsSaid) {
  Scratch tmp;
  const std::string vehicle = source_path("vehicles/finken3.yaml");
  const CliResult first = run_quadgen({"derive", vehicle, "--out", tmp / "d"}, tmp.dir);
  ASSERT_EQ(first.rc, 0);
  EXPECT_EQ(first.err.find("replaced"), std::string::npos) << first.err;
  const CliResult second = run_quadgen({"derive", vehicle, "--out", tmp / "d"}, tmp.dir);
  ASSERT_EQ(second.rc, 0);
  EXPECT_NE(second.err.find("quadgen: note: replaced the earlier derive output in " + (tmp / "d")), std::string::npos)
      << second.err;
  EXPECT_TRUE(out::complete_output_directory(tmp / "d"));
}

// simulate writes files among the user's: only a trajectory or a gnuplot plot is replaced.
TEST(DataLoss, SimulateReplacesOnlyItsOwnTrajectoryAndPlot) {
  Scratch tmp;
  const std::string vehicle = source_path("vehicles/finken3.yaml");
  const std::vector<std::string> hover = {"simulate", vehicle, "--scenario", "hover", "--duration", "0.1", "--out"};
  const auto with_out = [&](const std::string& out) {
    auto args = hover;
    args.push_back(out);
    return args;
  };
  write(tmp / "victim.yaml", "mass: 1\n");
  expect_one_line_error(run_quadgen(with_out(tmp / "victim.yaml"), tmp.dir), "expected a .csv file name", "--out .yaml");
  // A flight log of the user's looks like a trajectory; a plot of theirs may be gnuplot's too.
  const std::string flight = "t,u_A,u_B,u_C,u_D\n0,0.5,0.5,0.5,0.5\n";
  write(tmp / "flight07.csv", flight);
  expect_one_line_error(run_quadgen(with_out(tmp / "flight07.csv"), tmp.dir), "is not a file 'quadgen simulate' wrote there",
                        "the user's log");
  write(tmp / "traj.svg", "<svg><desc>Produced by GNUPLOT 5.4</desc></svg>");
  expect_one_line_error(run_quadgen(with_out(tmp / "traj.csv"), tmp.dir), "is not a file 'quadgen simulate' wrote there",
                        "the user's plot");
  EXPECT_EQ(read(tmp / "victim.yaml"), "mass: 1\n");
  EXPECT_EQ(read(tmp / "flight07.csv"), flight);
  EXPECT_EQ(read(tmp / "traj.svg"), "<svg><desc>Produced by GNUPLOT 5.4</desc></svg>");
  EXPECT_FALSE(fs::exists(tmp / "traj.csv"));
  // Its own earlier run is replaced, and that is said (a user trial, helper-82: derive said it,
  // simulate did not); once edited, it is the user's.
  const CliResult first = run_quadgen(with_out(tmp / "run.csv"), tmp.dir);
  ASSERT_EQ(first.rc, 0);
  EXPECT_EQ(first.err.find("replaced"), std::string::npos) << first.err;
  const CliResult again = run_quadgen(with_out(tmp / "run.csv"), tmp.dir);
  ASSERT_EQ(again.rc, 0);
  EXPECT_NE(again.err.find("quadgen: note: replaced the earlier simulate output " + (tmp / "run.csv")), std::string::npos)
      << again.err;
  EXPECT_EQ(read(tmp / "run.csv").substr(0, 2), "t,");
  // Where only the earlier plot is left, the note names the plot, not the trajectory.
  fs::remove(tmp / "run.csv");
  const CliResult plot_left = run_quadgen(with_out(tmp / "run.csv"), tmp.dir);
  ASSERT_EQ(plot_left.rc, 0);
  EXPECT_NE(plot_left.err.find("replaced the earlier simulate output " + (tmp / "run.svg") + "\n"), std::string::npos)
      << plot_left.err;
  write(tmp / "run.csv", read(tmp / "run.csv") + "my last row\n");
  expect_one_line_error(run_quadgen(with_out(tmp / "run.csv"), tmp.dir), "or it was changed since", "an edited trajectory");
  // Not into another run's output directory, which would then refuse its next run.
  ASSERT_EQ(run_quadgen({"derive", vehicle, "--out", tmp / "d"}, tmp.dir).rc, 0);
  expect_one_line_error(run_quadgen(with_out(tmp / "d/h.csv"), tmp.dir), "is the output directory of another quadgen run",
                        "into a derive folder");
  EXPECT_TRUE(out::complete_output_directory(tmp / "d"));
}

// The record beside simulate's files is "hash size name" per line. A --out name holding a line
// break could forge a line vouching for a user's file (found by a review: the next run then
// overwrote a flight log); a record with any line quadgen would not write vouches for nothing.
TEST(DataLoss, SimulateRecordCannotBeForgedThroughANameOrAnEdit) {
  Scratch tmp;
  const std::string vehicle = source_path("vehicles/finken3.yaml");
  const auto simulate_to = [&](const std::string& out) {
    return run_quadgen({"simulate", vehicle, "--scenario", "hover", "--duration", "0.1", "--out", out}, tmp.dir);
  };
  const std::string flight = "t,u_A,u_B,u_C,u_D\n0,0.5,0.5,0.5,0.5\n";
  write(tmp / "flight07.csv", flight);
  out::Fnv1a h;
  h.add(flight.data(), flight.size());
  const std::string forged = h.hex() + " " + std::to_string(flight.size()) + " flight07.csv";
  for (const std::string& name : std::vector<std::string>{"x\n" + forged + "\ny.csv", "x\r" + forged + "\ry.csv",
                                                          " run.csv", "tab\trun.csv", ".quadgen-files.csv"})
    expect_one_line_error(simulate_to(tmp / name), "cannot be an output file name", out::printable(name));
  expect_one_line_error(simulate_to(tmp / "run.csv "), "expected a .csv file name", "a blank at the end");
  expect_one_line_error(simulate_to(tmp / "flight07.csv"), "is not a file 'quadgen simulate' wrote there", "after the names");
  EXPECT_EQ(read(tmp / "flight07.csv"), flight);
  // A record holding a line quadgen would not write (here "hash size name" in the wrong
  // shape) vouches for nothing: not for the forged line beside it, not for simulate's own file.
  // (A well-formed line with the right hash cannot be told from quadgen's: whoever can write
  // the record can write the files.)
  ASSERT_EQ(simulate_to(tmp / "run.csv").rc, 0);
  ASSERT_EQ(simulate_to(tmp / "run.csv").rc, 0);
  write(tmp / ".quadgen-files", read(tmp / ".quadgen-files") + forged + "\nnot a record line\n");
  expect_one_line_error(simulate_to(tmp / "flight07.csv"), "is not a file 'quadgen simulate' wrote there", "forged line");
  expect_one_line_error(simulate_to(tmp / "run.csv"), "is not a file 'quadgen simulate' wrote there", "edited record");
  EXPECT_EQ(read(tmp / "flight07.csv"), flight);
}

// A record that is a directory or a link is refused before anything is written: a directory
// failed the run after its files were moved into place, every later run too, and a link was
// replaced without a word (a hostile-input review, helper-146).
TEST(DataLoss, ARecordThatIsNoRegularFileIsRefusedBeforeTheWork) {
  Scratch tmp;
  const std::string vehicle = source_path("vehicles/finken3.yaml");
  write(tmp / "elsewhere.txt", "the user's");
  for (const std::string record : {".quadgen-files", ".quadgen-files-pending"})
    for (const bool directory : {true, false}) {
      const fs::path dir = fs::path(tmp.dir) / (record.substr(1) + (directory ? "_dir" : "_link"));
      fs::create_directories(dir);
      if (directory) fs::create_directories(dir / record);
      else fs::create_symlink(tmp / "elsewhere.txt", dir / record);
      const auto r = run_quadgen({"simulate", vehicle, "--scenario", "hover", "--duration", "0.1", "--out",
                                  (dir / "run.csv").string()}, tmp.dir);
      expect_one_line_error(r, "is not a regular file", record + (directory ? " a directory" : " a link"));
      EXPECT_FALSE(fs::exists(dir / "run.csv")) << record;
      EXPECT_FALSE(fs::exists(dir / "run.svg")) << record;
    }
  EXPECT_EQ(read(tmp / "elsewhere.txt"), "the user's");
}

// The manifests' hash is FNV-1a 64 as published (test vectors of Fowler, Noll and Vo); a
// manifest written while quadgen used an offset basis with a digit dropped is still read as
// quadgen's, so an upgrade does not make every earlier output folder "changed since".
TEST(DataLoss, ManifestHashIsThePublishedFnv1aAndOlderManifestsStillRead) {
  EXPECT_EQ(out::fnv1a_hex(""), "cbf29ce484222325");
  EXPECT_EQ(out::fnv1a_hex("a"), "af63dc4c8601ec8c");
  EXPECT_EQ(out::fnv1a_hex("foobar"), "85944171f73967e8");
  Scratch tmp;
  const std::string vehicle = source_path("vehicles/finken3.yaml");
  ASSERT_EQ(run_quadgen({"derive", vehicle, "--out", tmp / "d"}, tmp.dir).rc, 0);
  // The manifest rewritten as the older quadgen wrote it: every hash under the old basis.
  std::istringstream lines(read(tmp / "d/.quadgen-manifest"));
  std::string line, older;
  while (std::getline(lines, line)) {
    std::istringstream ls(line);
    std::string hash, size, name;
    if (line == "quadgen output set 2") line = "quadgen output set 1";  // the header it wrote
    else if (line.rfind("command ", 0) != 0 && ls >> hash >> size >> name) {
      const std::string content = read(tmp / ("d/" + name));
      out::Fnv1a h(out::kFnv1aLegacyBasis);
      h.add(content.data(), content.size());
      ASSERT_EQ(hash, out::fnv1a_hex(content)) << name;
      line = h.hex() + " " + size + " " + name;
    }
    older += line + "\n";
  }
  // Old hashes under the new header are not quadgen's: the old basis is read under the old
  // header only.
  write(tmp / "d/.quadgen-manifest", "quadgen output set 2" + older.substr(older.find('\n')));
  EXPECT_FALSE(out::complete_output_directory(tmp / "d"));
  write(tmp / "d/.quadgen-manifest", older);
  EXPECT_TRUE(out::complete_output_directory(tmp / "d"));
  EXPECT_EQ(run_quadgen({"derive", vehicle, "--out", tmp / "d"}, tmp.dir).rc, 0);
  // Replaced by a manifest under the published basis.
  EXPECT_NE(read(tmp / "d/.quadgen-manifest").find(out::fnv1a_hex(read(tmp / "d/model.hpp")) + " "), std::string::npos);
}

// An output folder gets the mode mkdir would give it (0777 less the umask) or keeps that of
// the folder it replaces. Staging folders are private (mkdtemp's 0700), and every output
// folder used to stay so, unreadable to a group that could read its parent (helper-54,
// 2026-12-01).
TEST(DataLoss, AnOutputFolderHasTheModeMkdirWouldGiveIt) {
  Scratch tmp;
  const std::string vehicle = source_path("vehicles/finken3.yaml");
  const auto mode = [](const fs::path& p) {
    struct stat st {};
    EXPECT_EQ(::stat(p.c_str(), &st), 0) << p;
    return st.st_mode & 07777;
  };
  struct Umask {  // the run inherits it; neither 0700 nor the usual 0755
    mode_t saved = ::umask(027);
    ~Umask() { ::umask(saved); }
  } umask_027;
  ASSERT_EQ(run_quadgen({"derive", vehicle, "--out", tmp / "new"}, tmp.dir).rc, 0);
  EXPECT_EQ(mode(tmp / "new"), 0750u);
  fs::create_directories(tmp / "mine");
  ::chmod((tmp / "mine").c_str(), 0751);  // an empty folder of the user's
  ASSERT_EQ(run_quadgen({"derive", vehicle, "--out", tmp / "mine"}, tmp.dir).rc, 0);
  EXPECT_EQ(mode(tmp / "mine"), 0751u);
  ::chmod((tmp / "new").c_str(), 0711);  // an earlier run's folder, replaced
  ASSERT_EQ(run_quadgen({"derive", vehicle, "--out", tmp / "new"}, tmp.dir).rc, 0);
  EXPECT_EQ(mode(tmp / "new"), 0711u);
}

// A run that fails leaves nothing behind, not even the folders --out needed: a bad vehicle
// file into a nested --out, for each command that writes an output set (found by a review:
// derive and predict, which had started to create the set before reading the vehicle, left
// a/ and a/b/). The vehicle file's error is the one reported, whatever --out holds.
TEST(DataLoss, AFailedRunLeavesNoFoldersBehind) {
  Scratch tmp;
  write(tmp / "bad.yaml", "name: [\n");
  const std::string log = source_path("data/finken3_motor_steps.csv");
  for (const auto& command : std::vector<std::vector<std::string>>{
           {"derive", tmp / "bad.yaml"}, {"predict", tmp / "bad.yaml", log}, {"diagnose", tmp / "bad.yaml", log},
           {"fit", tmp / "bad.yaml", log}}) {
    auto args = command;
    args.insert(args.end(), {"--out", tmp / "a/b/c"});
    expect_one_line_error(run_quadgen(args, tmp.dir), "bad.yaml", command.front());
    EXPECT_FALSE(fs::exists(tmp / "a")) << command.front();
  }
  fs::create_directories(tmp / "mine");
  write(tmp / "mine/notes.txt", "mine\n");
  expect_one_line_error(run_quadgen({"derive", tmp / "bad.yaml", "--out", tmp / "mine"}, tmp.dir), "bad.yaml",
                        "a bad vehicle into a folder of the user's");
  EXPECT_EQ(read(tmp / "mine/notes.txt"), "mine\n");
}

// A run whose reader has gone (`quadgen derive ... 2>&1 | head -1`) dies of SIGPIPE at its
// next line of progress; its staging directory and the folders made for --out go first, as
// for the signals below (helper-54 found them left, 2026-12-01).
TEST(DataLoss, ARunWhoseReaderHasGoneLeavesNoFoldersBehind) {
  Scratch tmp;
  Interrupt gone;
  gone.reader_gone = true;
  const auto r = run_quadgen({"derive", source_path("vehicles/crazyflie21.yaml"), "--out", tmp / "a/b/out"}, tmp.dir, gone);
  EXPECT_EQ(r.rc, 128 + SIGPIPE);
  EXPECT_FALSE(fs::exists(tmp / "a"));
}

// Interrupted (Ctrl-C, a terminal closed, a job killed politely), a long run leaves nothing
// behind: its empty staging directory and the folders made for --out go before it dies of
// the signal. Before, they stayed until the next run into the same place.
TEST(DataLoss, AnInterruptedRunLeavesNoFoldersBehind) {
  Scratch tmp;
  const std::string vehicle = source_path("vehicles/finken3.yaml");
  ASSERT_EQ(run_quadgen({"simulate", vehicle, "--closed-loop", "--duration", "30", "--out", tmp / "f.csv"}, tmp.dir).rc, 0);
  for (int sig : {SIGINT, SIGTERM}) {
    const auto r = run_quadgen({"diagnose", vehicle, tmp / "f.csv", "--out", tmp / "a/b/c"}, tmp.dir,
                               {-1, tmp / "a/b", sig});
    EXPECT_EQ(r.rc, 128 + sig) << "the run must still be working when it is interrupted: " << r.err;
    EXPECT_FALSE(fs::exists(tmp / "a")) << strsignal(sig);
  }
}

// Interrupted in its last moments, with its files staged (a signal raised where the staging
// is complete and nothing has moved into place, or where an earlier run in the way has been
// checked and not yet exchanged), a run still leaves nothing behind: the staged files are
// remembered as they are named. Before, the staging directory and its files stayed until
// the next run into the same place. Once exchanged, the staging path holds the earlier
// run's files, which the interrupt must not remove.
TEST(DataLoss, ARunInterruptedWithItsFilesStagedLeavesNothingBehind) {
  Scratch tmp;
  const std::string vehicle = source_path("vehicles/finken3.yaml");
  const auto staging_folders = [&] {
    std::vector<fs::path> found;
    for (const auto& e : fs::directory_iterator(tmp.dir))
      if (e.path().filename().string().find(".quadgen-tmp.") != std::string::npos) found.push_back(e.path());
    return found;
  };
  for (int sig : {SIGINT, SIGTERM}) {
    const auto at = [&](const std::string& place) { return "QUADGEN_TEST_SIGNAL=" + place + ":" + std::to_string(sig); };
    const auto fresh = run_quadgen({"derive", vehicle, "--out", tmp / "a/b/c"}, tmp.dir, {}, {at("before-commit")});
    EXPECT_EQ(fresh.rc, 128 + sig) << fresh.err;
    EXPECT_FALSE(fs::exists(tmp / "a")) << strsignal(sig);
    const fs::path kept = tmp / ("kept" + std::to_string(sig));
    ASSERT_EQ(run_quadgen({"derive", vehicle, "--out", kept}, tmp.dir).rc, 0);
    const std::string earlier = read(kept / "model.hpp");
    for (const char* place : {"before-commit", "before-exchange"}) {
      const auto over = run_quadgen({"derive", vehicle, "--out", kept, "--effects", "motor_lag"}, tmp.dir, {}, {at(place)});
      EXPECT_EQ(over.rc, 128 + sig) << place << ": " << over.err;
      EXPECT_EQ(read(kept / "model.hpp"), earlier) << place << ", " << strsignal(sig);
      EXPECT_TRUE(staging_folders().empty()) << place << ", " << strsignal(sig);
    }
    const auto after = run_quadgen({"derive", vehicle, "--out", kept, "--effects", "motor_lag"}, tmp.dir, {},
                                   {at("after-exchange")});
    EXPECT_EQ(after.rc, 128 + sig) << after.err;
    EXPECT_NE(read(kept / "model.hpp"), earlier) << "the new run is in place";
    const auto left = staging_folders();  // the earlier run, as after SIGKILL: the next run removes it
    ASSERT_EQ(left.size(), 1u) << strsignal(sig);
    EXPECT_EQ(read(left.front() / "model.hpp"), earlier) << "the earlier run's files are not the interrupt's to remove";
    fs::remove_all(left.front());
  }
  const auto traj = run_quadgen({"simulate", vehicle, "--scenario", "hover", "--duration", "0.2", "--out",
                                 tmp / "s/t/f.csv"}, tmp.dir, {}, {"QUADGEN_TEST_SIGNAL=before-commit:15"});
  EXPECT_EQ(traj.rc, 128 + SIGTERM) << traj.err;
  EXPECT_FALSE(fs::exists(tmp / "s"));

  // Killed (SIGKILL: no handler runs) with its trajectory moved into place and its plot not
  // yet, beside the earlier run's record: the next run to the path takes the files as
  // simulate's (the commit's pending record vouches for them) and sweeps the dead run's
  // staging folder (a red-team review: every later run was refused).
  const auto flight = [&](const std::string& duration, std::vector<std::string> env) {
    return run_quadgen({"simulate", vehicle, "--scenario", "hover", "--duration", duration, "--out", tmp / "k/f.csv"},
                       tmp.dir, {}, std::move(env));
  };
  ASSERT_EQ(flight("0.2", {}).rc, 0);
  const std::string first = read(tmp / "k/f.csv");
  const auto killed = flight("0.3", {"QUADGEN_TEST_SIGNAL=after-a-file-moved:9"});
  EXPECT_EQ(killed.rc, 128 + SIGKILL) << killed.err;
  EXPECT_NE(read(tmp / "k/f.csv"), first) << "the killed run's trajectory is in place";
  const auto next = flight("0.25", {});
  EXPECT_EQ(next.rc, 0) << next.err;
  std::vector<std::string> left;
  for (const auto& e : fs::directory_iterator(tmp / "k"))
    if (e.path().filename().string().rfind(".quadgen-files", 0) != 0) left.push_back(e.path().filename().string());
  std::sort(left.begin(), left.end());
  EXPECT_EQ(left, (std::vector<std::string>{"f.csv", "f.svg"})) << "no staging folder left";
  EXPECT_FALSE(fs::exists(tmp / "k/.quadgen-files-pending"));
  // Killed so again, and then another path in the folder committed first: the killed run's
  // files are still vouched for (a review: the other run's pending record replaced the one
  // that vouched for them, and the next run to f.csv was refused).
  EXPECT_EQ(flight("0.3", {"QUADGEN_TEST_SIGNAL=after-a-file-moved:9"}).rc, 128 + SIGKILL);
  ASSERT_EQ(run_quadgen({"simulate", vehicle, "--scenario", "hover", "--duration", "0.2", "--out", tmp / "k/g.csv"}, tmp.dir).rc, 0);
  const auto after_other = flight("0.25", {});
  EXPECT_EQ(after_other.rc, 0) << after_other.err;
  // A file the record and the pending record know nothing of is still refused.
  write(tmp / "k/f.csv", "t,x\n0,1\n");
  const auto refused = flight("0.2", {});
  EXPECT_NE(refused.rc, 0);
  EXPECT_NE(refused.err.find("is not a file 'quadgen simulate' wrote there"), std::string::npos) << refused.err;
}

// motor_lag_spread scales motor_lag's time constant: asked for without it, derive and
// diagnose --candidates say to add motor_lag, and write nothing.
TEST(Cli, ALagSpreadAloneIsRefusedWithWhatToAdd) {
  Scratch tmp;
  const std::string vehicle = source_path("vehicles/finken3.yaml");
  ASSERT_EQ(run_quadgen({"simulate", vehicle, "--scenario", "hover", "--duration", "1", "--out", tmp / "f.csv"}, tmp.dir).rc, 0);
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"derive", vehicle, "--effects", "motor_lag_spread", "--out", tmp / "out"},
        std::vector<std::string>{"diagnose", vehicle, tmp / "f.csv", "--candidates", "motor_gain,motor_lag_spread", "--out",
                                 tmp / "out"}}) {
    const CliResult r = run_quadgen(args, tmp.dir);
    EXPECT_EQ(r.rc, 2) << args.front() << ": " << r.err;
    EXPECT_NE(r.err.find("add motor_lag too"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(tmp / "out")) << args.front();
  }
}

// Numbers that overflow a double never reach the generated code as "inf" or "nan" (an
// identifier the including project may define): derive refuses and writes nothing.
TEST(Sinks, OverflowingVehicleNumbersAreRefusedNotEmitted) {
  Scratch tmp;
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"radius: 0.0635", "radius: 1e200"},  // rotor constants overflow in the thrust law
      {"upper_body, mass: 0.099", "upper_body, mass: 1.7e308"}};  // the blocks' total mass
  for (const auto& [from, to] : cases) {
    std::string text = finken3_with(from, to);
    if (to == "upper_body, mass: 1.7e308") {
      const auto at = text.find("lower_body, mass: 0.132");
      ASSERT_NE(at, std::string::npos);
      text.replace(at, 23, "lower_body, mass: 1.7e308");
    }
    write(tmp / "v.yaml", text);
    const auto r = run_quadgen({"derive", tmp / "v.yaml", "--out", tmp / "out"}, tmp.dir);
    expect_one_line_error(r, "not finite", to);
    EXPECT_FALSE(fs::exists(tmp / "out")) << to;
  }
  EXPECT_THROW(quadgen::codegen::double_literal(std::numeric_limits<double>::infinity()), std::domain_error);
  EXPECT_THROW(quadgen::codegen::double_literal(std::nan("")), std::domain_error);
  EXPECT_EQ(quadgen::codegen::double_literal(2.0), "2.0");
}

// Killed at random moments, a run leaves its --out directory holding one complete run: the
// earlier one or the new one, every file matching the manifest. The kill times are drawn over
// 1.2x the duration of an uninterrupted run measured here, so they fall into every phase
// (reading, deriving or fitting, staging, switching) whatever the machine's load.
TEST(DataLoss, SigkillAtRandomMomentsLeavesOneCompleteRun) {
  Scratch tmp;
  const std::string vehicle = source_path("vehicles/finken3.yaml");
  const std::string dir = tmp / "out", fit_dir = tmp / "fit";  // one command's output per directory
  const std::vector<std::vector<std::string>> runs = {
      {"derive", vehicle, "--out", dir, "--effects", "motor_lag"},
      {"fit", vehicle, source_path("data/finken3_motor_steps.csv"), "--out", fit_dir},
      {"derive", vehicle, "--out", dir, "--effects", "wind"}};
  const std::vector<std::string> out_of = {dir, fit_dir, dir};
  std::vector<double> seconds;
  for (const auto& args : runs) {
    const auto t0 = std::chrono::steady_clock::now();
    ASSERT_EQ(run_quadgen(args, tmp.dir).rc, 0);
    seconds.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  std::mt19937 rng(20261123);
  quadgen::runtime::UniformReal fraction(0.0, 1.2);
  for (int k = 0; k < 12; ++k) {
    const size_t which = static_cast<size_t>(k) % runs.size();
    run_quadgen(runs[which], tmp.dir, {fraction(rng) * seconds[which]});
    std::string why;
    EXPECT_TRUE(out::complete_output_directory(out_of[which], &why)) << "after kill " << k << ": " << why;
  }
  // After the kills, whole runs still go through and clear what the killed ones left.
  ASSERT_EQ(run_quadgen(runs[1], tmp.dir).rc, 0);
  ASSERT_EQ(run_quadgen(runs[0], tmp.dir).rc, 0);
  EXPECT_TRUE(out::complete_output_directory(dir));
  EXPECT_TRUE(out::complete_output_directory(fit_dir));
  EXPECT_NE(read(fs::path(dir) / "model.hpp").find("motor_lag"), std::string::npos);
  for (const auto& e : fs::directory_iterator(tmp.dir))
    EXPECT_EQ(e.path().filename().string().find(".quadgen-tmp."), std::string::npos) << e.path();
}

TEST(DataLoss, TwoRunsIntoOneDirectoryLeaveOneWhole) {
  Scratch tmp;
  const std::string vehicle = source_path("vehicles/finken3.yaml");
  const std::string dir = tmp / "out";
  for (int round = 0; round < 3; ++round) {
    CliResult a{}, b{};
    std::thread ta([&] { a = run_quadgen({"derive", vehicle, "--out", dir}, tmp.dir); });
    std::thread tb([&] { b = run_quadgen({"derive", vehicle, "--out", dir, "--effects", "motor_lag"}, tmp.dir); });
    ta.join();
    tb.join();
    EXPECT_EQ(a.rc, 0) << a.err;
    EXPECT_EQ(b.rc, 0) << b.err;
    std::string why;
    EXPECT_TRUE(out::complete_output_directory(dir, &why)) << why;
  }
  for (const auto& e : fs::directory_iterator(tmp.dir))
    EXPECT_EQ(e.path().filename().string().find(".quadgen-tmp."), std::string::npos) << e.path();
}

// A prediction whose errors are not finite is no success: exit 4 with the reason, files kept.
TEST(Cli, PredictExitsNonZeroWhenTheModelLeavesItsRange) {
  Scratch tmp;
  const std::string vehicle = source_path("vehicles/finken3.yaml");
  ASSERT_EQ(run_quadgen({"simulate", vehicle, "--closed-loop", "--duration", "6", "--out", tmp / "f.csv"}, tmp.dir).rc, 0);
  write(tmp / "bad.json", R"({"vehicle": "finken3", "estimates": {"J_xx": {"value": 1e-12}, "J_yy": {"value": 1e-12}}})");
  const CliResult r = run_quadgen({"predict", vehicle, tmp / "f.csv", "--params", tmp / "bad.json", "--out", tmp / "p"}, tmp.dir);
  EXPECT_EQ(r.rc, 4) << r.err;
  EXPECT_NE(r.err.find("is not finite: the model left its range"), std::string::npos) << r.err;
  EXPECT_TRUE(out::complete_output_directory(tmp / "p"));
  write(tmp / "good.json", R"({"vehicle": "finken3", "estimates": {}})");
  EXPECT_EQ(run_quadgen({"predict", vehicle, tmp / "f.csv", "--params", tmp / "good.json", "--out", tmp / "q"}, tmp.dir).rc, 0);
}

// Values from outside the vehicle file (predict --params, simulate --set) that no model can
// run with were taken as they were: a negative mass predicted and flew with exit 0, a zero
// inertia ended in "state x = nan" naming neither the file nor the option. Refused with the
// parameter named; predict also holds a value to its bounds, as derive --params does.
TEST(Cli, ParameterValuesFromOutsideAreChecked) {
  Scratch tmp;
  const std::string vehicle = source_path("vehicles/finken3.yaml");
  ASSERT_EQ(run_quadgen({"simulate", vehicle, "--closed-loop", "--duration", "2", "--out", tmp / "f.csv"}, tmp.dir).rc, 0);
  const auto params = [&](const std::string& name, const std::string& entries) {
    write(tmp / name, R"({"vehicle": "finken3", "estimates": {)" + entries + "}}");
    return tmp / name;
  };
  const auto predict = [&](const std::string& file) {
    return run_quadgen({"predict", vehicle, tmp / "f.csv", "--params", file, "--out", tmp / "p"}, tmp.dir);
  };
  expect_one_line_error(predict(params("negative.json", R"("mass": {"value": -1})")),
                        "negative.json: estimates.mass = -1 is outside its bounds", "mass -1");
  expect_one_line_error(predict(params("zero.json", R"("J_zz": {"value": 0})")),
                        "zero.json: estimates.J_zz = 0: a mass and a principal moment of inertia must be positive", "J_zz 0");
  expect_one_line_error(predict(params("lag.json", R"("motor_lag.tau": {"value": 5})")),
                        "lag.json: estimates.motor_lag.tau = 5 is outside its bounds", "tau 5");
  // read as 0 by the JSON parser, without a word (one rule for numbers, output/numbers.hpp)
  expect_one_line_error(predict(params("tiny.json", R"("J_xy": {"value": 1e-400})")),
                        "tiny.json: the number 1e-400 is below the smallest number a double holds, so it would read as 0",
                        "J_xy 1e-400");
  // A unit other than the model's (kappa in mm was taken as metres), a number beyond a double
  // (nlohmann's bare message named no file) and a key given twice (the last kept without a
  // word): a review, helper-135.
  expect_one_line_error(predict(params("mm.json", R"("kappa": {"value": 2, "unit": "mm"})")),
                        "mm.json: estimates.kappa is in m, the file says 'mm'", "kappa in mm");
  EXPECT_EQ(run_quadgen({"predict", vehicle, tmp / "f.csv", "--params", params("m.json", R"("kappa": {"value": 0.002, "unit": "m"})"),
                         "--validation", "1", "--out", tmp / "p"},
                        tmp.dir)
                .rc,
            0);  // the model's own unit is taken
  fs::remove_all(tmp / "p");
  expect_one_line_error(predict(params("huge.json", R"("J_xy": {"value": 1e400})")),
                        "huge.json: a number in it is beyond a double's range", "J_xy 1e400");
  expect_one_line_error(predict(params("huge_negative.json", R"("J_xy": {"value": -1e400})")),
                        "huge_negative.json: a number in it is beyond a double's range", "J_xy -1e400");
  expect_one_line_error(predict(params("twice.json", R"("kappa": {"value": 0.002}, "kappa": {"value": 0.003})")),
                        "twice.json: the key 'kappa' is given twice in one object", "kappa twice");
  EXPECT_FALSE(fs::exists(tmp / "p"));
  const auto simulate = [&](const std::string& setting) {
    return run_quadgen({"simulate", vehicle, "--closed-loop", "--duration", "1", "--set", setting, "--out", tmp / "s.csv"},
                       tmp.dir);
  };
  expect_one_line_error(simulate("mass=-1"), "--set: mass = -1: a mass and a principal moment of inertia must be positive",
                        "--set mass=-1");
  expect_one_line_error(simulate("J_xx=0"), "--set: J_xx = 0: a mass", "--set J_xx=0");
  expect_one_line_error(simulate("c_t=nan"), "'nan' is not a finite number", "--set c_t=nan");  // the command line's own check
  // The vehicle file's rule (output/numbers.hpp): 1e-400 read as 0 here, and 0x10 as 16.
  expect_one_line_error(simulate("J_xy=1e-400"), "'1e-400' is below the smallest number a double holds, so it would read as 0",
                        "--set J_xy=1e-400");
  expect_one_line_error(simulate("c_t=0x10"), "'0x10' is not a finite number; hexadecimal is not read, write it in decimal",
                        "--set c_t=0x10");
  // Values each within its own limits that together make no body (a sixth audit, helper-86: the
  // closed loop flew J_xy = 0.01 until it was lost), and an exposed area below zero.
  expect_one_line_error(simulate("J_xy=0.01"),
                        "--set: with these values the inertia tensor's principal moments are ", "--set J_xy=0.01");
  expect_one_line_error(simulate("A_x=-0.01"), "--set: A_x = -0.01: an exposed area cannot be negative", "--set A_x<0");
  EXPECT_FALSE(fs::exists(tmp / "s.csv"));
  // A negative delay read commands not yet sent (beyond the end of the record).
  const CliResult delay = run_quadgen({"simulate", vehicle, "--closed-loop", "--duration", "1", "--effects", "input_delay", "--set",
                                       "input_delay.seconds=-0.05", "--out", tmp / "s.csv"},
                                      tmp.dir);
  expect_one_line_error(delay, "input_delay.seconds = -0.05", "--set input_delay.seconds=-0.05");
  EXPECT_FALSE(fs::exists(tmp / "s.csv"));
  // In a scenario and a replay too (a review, helper-81: a negative delay and one longer than
  // the flight were flown with exit 0; a time constant of 0 ended in "state x = -nan"): a value
  // the physics cannot take is refused in every mode, as is a name given twice (the last had won).
  const auto scenario = [&](const std::string& effect, const std::vector<std::string>& settings) {
    std::vector<std::string> args{"simulate", vehicle, "--scenario", "hover", "--duration", "1", "--effects", effect};
    for (const auto& kv : settings) args.insert(args.end(), {"--set", kv});
    args.insert(args.end(), {"--out", tmp / "s.csv"});
    return run_quadgen(args, tmp.dir);
  };
  expect_one_line_error(scenario("input_delay", {"input_delay.seconds=-0.05"}),
                        "--set: input_delay.seconds = -0.05 must be at least 0: a delay below zero", "scenario, delay -0.05");
  expect_one_line_error(scenario("input_delay", {"input_delay.seconds=5"}),
                        "--set: input_delay.seconds = 5 s is as long as the flight or longer (--duration 1 s)",
                        "scenario, delay 5");
  expect_one_line_error(scenario("input_delay", {"input_delay.seconds=1"}), "is as long as the flight or longer",
                        "scenario, delay 1 of 1 s");
  expect_one_line_error(scenario("motor_lag", {"motor_lag.tau=0"}), "--set: motor_lag.tau = 0 must be above 0: ",
                        "scenario, tau 0");
  expect_one_line_error(scenario("motor_gain", {"motor_gain.C=-1.5"}), "--set: motor_gain.C = -1.5 must be at least -1: ",
                        "scenario, gain -150 %");
  // A decay whose factor 1 - rate t reaches 0 within the flight (the rotors would pull), and an
  // inflow that raises the thrust as the rotor climbs (the same audit).
  expect_one_line_error(scenario("thrust_decay", {"thrust_decay.rate=1"}),
                        "--set: thrust_decay.rate = 1 /s: the thrust factor 1 - rate t reaches 0 at t = 1 s, within the "
                        "flight (--duration 1 s)",
                        "scenario, decay 1/s");
  expect_one_line_error(scenario("inflow", {"inflow.k=-100"}), "--set: inflow.k = -100 must be at least 0: ",
                        "scenario, inflow -100");
  expect_one_line_error(scenario("input_delay", {"input_delay.seconds=0.01", "input_delay.seconds=0.02"}),
                        "--set: 'input_delay.seconds' is given twice", "scenario, delay twice");
  // The hint offers no name the mode refuses (it had offered 'mass', then refused it).
  const CliResult slip = scenario("input_delay", {"Mass=1"});
  expect_one_line_error(slip, "--set: no parameter 'Mass' in the model", "scenario, Mass");
  EXPECT_EQ(slip.err.find("did you mean 'mass'"), std::string::npos) << slip.err;
  EXPECT_FALSE(fs::exists(tmp / "s.csv"));
  // A value beyond a fit's bounds but within the physics is flown (a test flight's truth), as
  // is a dead motor (a gain of -100 %: no thrust; the review of this change found it refused).
  EXPECT_EQ(scenario("input_delay", {"input_delay.seconds=0.5"}).rc, 0);
  EXPECT_EQ(scenario("motor_gain", {"motor_gain.C=-1"}).rc, 0);
  // A time constant the physics allows but RK4's step cannot follow: the divergence says why.
  expect_one_line_error(run_quadgen({"simulate", vehicle, "--scenario", "yaw", "--duration", "1", "--effects", "motor_lag",
                                     "--set", "motor_lag.tau=1e-4", "--out", tmp / "s.csv"},
                                    tmp.dir),
                        "motor_lag.tau = 0.0001 s is too fast for RK4 at --step 0.001 s", "tau 1e-4 at a 1 ms step");
  // The fastest rotor's constant is the one that diverges (a spread of -0.9999 had no note),
  // and a constant no step follows says so rather than "lower --step".
  expect_one_line_error(run_quadgen({"simulate", vehicle, "--scenario", "yaw", "--duration", "1", "--effects",
                                     "motor_lag,motor_lag_spread", "--set", "motor_lag.tau=0.05", "--set",
                                     "motor_lag_spread.A=-0.9999", "--out", tmp / "s.csv"},
                                    tmp.dir),
                        "the fastest rotor's time constant (motor_lag.tau times 1 + its spread) = 5e-06 s is too fast for RK4",
                        "spread -0.9999");
  expect_one_line_error(run_quadgen({"simulate", vehicle, "--scenario", "yaw", "--duration", "1", "--effects", "motor_lag",
                                     "--set", "motor_lag.tau=1e-12", "--out", tmp / "s.csv"},
                                    tmp.dir),
                        "no step simulate takes follows it", "tau 1e-12");
  fs::remove(tmp / "s.csv");
  fs::remove(tmp / "s.svg");
  // A channel listed twice was weighted twice.
  expect_one_line_error(run_quadgen({"fit", vehicle, tmp / "f.csv", "--channels", "ax,qdot,ax", "--out", tmp / "o"}, tmp.dir),
                        "--channels: 'ax' is given twice", "--channels ax,qdot,ax");
  EXPECT_FALSE(fs::exists(tmp / "o"));
  // An empty name was skipped without a word, where an effect list refused one (one splitter
  // for every option's list since the sixty-third session).
  expect_one_line_error(run_quadgen({"fit", vehicle, tmp / "f.csv", "--channels", "ax,,qdot", "--out", tmp / "o"}, tmp.dir),
                        "--channels 'ax,,qdot' has an empty name", "--channels ax,,qdot");
  EXPECT_FALSE(fs::exists(tmp / "o"));
  // A misspelt effect given twice is named as unknown, with the nearest, not as a repeat.
  expect_one_line_error(run_quadgen({"fit", vehicle, tmp / "f.csv", "--effects", "motor_lagg,motor_lagg", "--out", tmp / "o"}, tmp.dir),
                        "unknown effect 'motor_lagg'", "--effects motor_lagg twice");
  EXPECT_FALSE(fs::exists(tmp / "o"));
  // --validation 0, inside its range, always failed with "no stretch of the log is long enough
  // ... is t in seconds?" (a review, helper-135): now nothing is held out; a held-out part too
  // short to evaluate is said to be that.
  const CliResult all = run_quadgen({"fit", vehicle, tmp / "f.csv", "--validation", "0", "--profiles", "none", "--out", tmp / "o"}, tmp.dir);
  EXPECT_EQ(all.rc, 0) << all.err;
  EXPECT_NE(all.err.find("no validation: nothing held out (--validation 0)"), std::string::npos) << all.err;
  EXPECT_EQ(nlohmann::json::parse(read(fs::path(tmp / "o") / "fit.json"))["validation"]["samples"], 0);
  fs::remove_all(tmp / "o");
  expect_one_line_error(run_quadgen({"fit", vehicle, tmp / "f.csv", "--validation", "0.001", "--out", tmp / "o"}, tmp.dir),
                        "the held-out part (--validation 0.001: the last ", "--validation 0.001");
  EXPECT_FALSE(fs::exists(tmp / "o"));
}

// A manoeuvre whose rule picks no rotor of the vehicle flew as a hover and was written as the
// manoeuvre, exit 0 (a sixth audit, helper-86: `forward` on four rotors in a line along x).
TEST(Cli, AScenarioThatRaisesNoRotorIsRefused) {
  Scratch tmp;
  std::string text = read(source_path("vehicles/finken3.yaml"));
  const std::pair<const char*, const char*> moves[] = {{"[-0.07465, -0.07465, 0]", "[-0.3, 0, 0]"},
                                                        {"[0.07465, -0.07465, 0]", "[-0.1, 0, 0]"},
                                                        {"[0.07465, 0.07465, 0]", "[0.1, 0, 0]"},
                                                        {"[-0.07465, 0.07465, 0]", "[0.3, 0, 0]"}};
  for (const auto& [from, to] : moves) {
    ASSERT_NE(text.find(from), std::string::npos) << from;
    text.replace(text.find(from), std::string(from).size(), to);
  }
  text.replace(text.find("name: finken3"), std::string("name: finken3").size(), "name: in_line");
  write(tmp / "line.yaml", text);
  const auto fly = [&](const char* scenario) {
    return run_quadgen({"simulate", tmp / "line.yaml", "--scenario", scenario, "--duration", "2", "--out", tmp / "s.csv"},
                       tmp.dir);
  };
  expect_one_line_error(fly("forward"), "line.yaml: scenario 'forward' (", "forward on rotors in a line");
  EXPECT_NE(fly("forward").err.find("changes no rotor of this vehicle: it would fly as a hover"), std::string::npos);
  EXPECT_FALSE(fs::exists(tmp / "s.csv"));
  EXPECT_EQ(fly("right").rc, 0);  // the rotors on -x and +x: it raises some
}

// A flight that ended before its manoeuvre's first change flew as a hover and was written as the
// manoeuvre, and a divergence from a --set value far beyond its physics named only the state it
// ended in, "x = -nan" (notes of the forty-second session).
TEST(Cli, AFlightEndingBeforeItsManoeuvreAndAnImplausibleValueAreSaid) {
  Scratch tmp;
  const std::string vehicle = source_path("vehicles/crazyflie21.yaml");
  const auto fly = [&](std::vector<std::string> extra) {
    std::vector<std::string> args = {"simulate", vehicle, "--out", tmp / "s.csv"};
    args.insert(args.end(), extra.begin(), extra.end());
    return run_quadgen(args, tmp.dir);
  };
  const CliResult short_flight = fly({"--scenario", "right", "--duration", "0.3"});
  expect_one_line_error(short_flight, "--duration 0.3 s ends before scenario 'right' (", "right for 0.3 s");
  EXPECT_NE(short_flight.err.find("first changes a rotor, at 0.5 s: it would fly as a hover"), std::string::npos)
      << short_flight.err;
  expect_one_line_error(fly({"--scenario", "right", "--duration", "0.6", "--effects", "input_delay", "--set",
                             "input_delay.seconds=0.2"}),
                        "first changes a rotor, at 0.7 s (its input delay included)", "right for 0.6 s, delayed 0.2 s");
  const CliResult gale = fly({"--scenario", "hover", "--duration", "1", "--effects", "wind", "--set", "wind.x=1e300"});
  expect_one_line_error(gale, "simulation diverged at t = ", "wind 1e300");
  EXPECT_NE(gale.err.find("; outside its plausible range, --set wind.x = 1e+300 (plausible -15 to 15: "), std::string::npos)
      << gale.err;
  EXPECT_FALSE(fs::exists(tmp / "s.csv"));
  // A value beyond its plausible range is flown, and said before the flight (a user trial:
  // motor_gain.M3=0.93, meant as 93 %, flew a rotor at 193 % without a word).
  const CliResult strong = fly({"--scenario", "hover", "--duration", "0.1", "--effects", "motor_gain", "--set", "motor_gain.M3=0.93"});
  EXPECT_EQ(strong.rc, 0) << strong.err;
  EXPECT_NE(strong.err.find("note: flown as set, though outside its plausible range, --set motor_gain.M3 = 0.93 (plausible "),
            std::string::npos)
      << strong.err;
  EXPECT_EQ(fly({"--scenario", "right", "--duration", "0.6"}).rc, 0);
  EXPECT_EQ(fly({"--scenario", "climb", "--duration", "0.1"}).rc, 0);  // it climbs from the start
  EXPECT_EQ(fly({"--scenario", "hover", "--duration", "0.1"}).rc, 0);
}

// --resample judged only the pair of rows it interpolated between and walked past rows whose
// time went back (a sixth audit, helper-86: 100 reversed rows were fitted without a word), and
// a rate too low for a flight log was blamed on the log's time unit.
TEST(Cli, ResampleJudgesEveryRowAndNamesItsRate) {
  Scratch tmp;
  const std::string vehicle = source_path("vehicles/finken3.yaml");
  ASSERT_EQ(run_quadgen({"simulate", vehicle, "--closed-loop", "--duration", "2", "--out", tmp / "f.csv"}, tmp.dir).rc, 0);
  std::istringstream in(read(tmp / "f.csv"));
  std::vector<std::string> lines;
  for (std::string l; std::getline(in, l);) lines.push_back(l);
  ASSERT_GT(lines.size(), 150u);
  std::reverse(lines.begin() + 51, lines.begin() + 101);  // rows 50..99 (lines 52..101) backwards
  std::string reversed;
  for (const auto& l : lines) reversed += l + "\n";
  write(tmp / "r.csv", reversed);
  const auto fit = [&](const std::string& log, const char* rate) {
    return run_quadgen({"fit", vehicle, tmp / log, "--resample", rate, "--profiles", "none", "--out", tmp / "o"}, tmp.dir);
  };
  expect_one_line_error(fit("r.csv", "100"), "r.csv:53: time not strictly increasing", "reversed rows, --resample 100");
  expect_one_line_error(fit("f.csv", "1"), "f.csv: --resample 1 gives samples 1 s apart", "--resample 1");
  EXPECT_FALSE(fs::exists(tmp / "o"));
}

// A newcomer's likely mistakes (a review that used the tool as a new user would): each gets one
// line that names the word, the file or the missing piece, and what would work.
TEST(Cli, NewcomerMistakesAreNamed) {
  Scratch tmp;
  const std::string f3 = source_path("vehicles/finken3.yaml"), cf = source_path("vehicles/crazyflie21.yaml");
  const auto expect_error = [&](const std::vector<std::string>& args, int rc, const std::string& says) {
    const CliResult r = run_quadgen(args, tmp.dir);
    EXPECT_EQ(r.rc, rc) << args.front() << ": " << r.err;
    EXPECT_NE(r.err.find(says), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(tmp / "o")) << r.err;
  };
  // A misspelt or imagined command.
  expect_error({"diagnos", f3, "--out", tmp / "o"}, 106, "unknown command 'diagnos' (commands: derive, simulate, fit, "
                                                          "diagnose, predict, compare); did you mean 'diagnose'?");
  expect_error({"generate", f3, "--out", tmp / "o"}, 106, "'derive' writes the generated C++");
  // An empty path (an unset shell variable) and a log whose name begins with '-' (read as an
  // option: "logs is required" alone; a review, helper-135).
  expect_error({"derive", "", "--out", tmp / "o"}, 2, "an empty path where a vehicle file was expected");
  write(tmp / "-x.csv", "t,u_A\n");
  {
    const CliResult r = run_quadgen({"predict", f3, "-x.csv", "--out", tmp / "o"}, tmp.dir);
    EXPECT_NE(r.rc, 0);
    EXPECT_NE(r.err.find("'-x.csv' is a file whose name reads as an option: write ./-x.csv"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(tmp / "o"));
  }
  // A misspelt required option: CLI11 alone says only that --out is missing.
  expect_error({"derive", f3, "--ouut", tmp / "o"}, 106,
               "--out is required (not understood: --ouut); did you mean '--out' for '--ouut'?");
  // Letters too many are a slip too (a newcomer's trial, helper-143: --ouput got nothing).
  expect_error({"derive", f3, "--ouput", tmp / "o"}, 106, "did you mean '--out' for '--ouput'?");
  expect_error({"derive", f3, "--output", tmp / "o"}, 106, "did you mean '--out' for '--output'?");
  EXPECT_FALSE(quadgen::cli::within_three_extra_letters("--outputs", "--out"));
  EXPECT_FALSE(quadgen::cli::within_three_extra_letters("--tuo", "--out"));
  // Its first letter kept: "--count" and "--about" are no slips for "--out", "--offset" none for "--set".
  EXPECT_FALSE(quadgen::cli::within_three_extra_letters("--count", "--out"));
  EXPECT_FALSE(quadgen::cli::within_three_extra_letters("--about", "--out"));
  EXPECT_FALSE(quadgen::cli::within_three_extra_letters("--offset", "--set"));
  // A misspelt option gets the nearest of that command's options back; a word near none, nothing.
  expect_error({"diagnose", f3, "x.csv", "--maping", "M.yaml", "--out", tmp / "o"}, 109,
               "not expected: --maping; did you mean '--mapping' for '--maping'?");
  expect_error({"predict", f3, "x.csv", "--calibrat", "--out", tmp / "o"}, 109, "did you mean '--calibrate'");
  const CliResult far = run_quadgen({"predict", f3, "x.csv", "--zzzzzzzz", "--out", tmp / "o"}, tmp.dir);
  EXPECT_EQ(far.err.find("did you mean"), std::string::npos) << far.err;
  // Short words are not slips for other short words ('w' for 't', '--x' for '--dt').
  EXPECT_EQ(quadgen::output::nearest_word("w", {"t", "x", "vbat"}), "");
  EXPECT_EQ(quadgen::output::nearest_word("--x", {"--dt", "--out"}), "");
  EXPECT_EQ(quadgen::output::nearest_word("motor_motor_M3", {"motor_motor_m3", "motor_motor_m4"}), "motor_motor_m3");
  // A name spelt with a look-alike letter is no slip of a few bytes: found by its Unicode
  // look-alike skeleton, and said with what sets it apart (else "unknown 'аy'; did you mean
  // 'ay'?" reads as nonsense).
  using quadgen::output::did_you_mean;
  const std::string cyrillic_a = "\xD0\xB0";
  EXPECT_EQ(did_you_mean(cyrillic_a + "y", {"ax", "ay", "az"}),
            "; did you mean 'ay'? (they look alike, but '" + cyrillic_a + "y' has U+0430 CYRILLIC SMALL LETTER A (character 1))");
  // Both sides said: the precomposed and the combining accent.
  EXPECT_EQ(did_you_mean("cafe\xCC\x81", {"caf\xC3\xA9", "cafe"}),
            "; did you mean 'caf\xC3\xA9'? (they look alike, but 'cafe\xCC\x81' has U+0301 COMBINING ACUTE ACCENT "
            "(character 5); 'caf\xC3\xA9' has U+00E9 LATIN SMALL LETTER E WITH ACUTE (character 4))");
  // The odd letter in the candidate (a log's header with a zero-width space), not the word.
  EXPECT_EQ(did_you_mean("gyro_x", {"gyro\xE2\x80\x8B_x", "gyro_y"}),
            "; did you mean 'gyro\xE2\x80\x8B_x'? (they look alike, but 'gyro\xE2\x80\x8B_x' has U+200B ZERO WIDTH SPACE "
            "(character 5))");
  // Letters in another order are placed; a thousand of them do not make a message of kB.
  EXPECT_NE(did_you_mean("a" + cyrillic_a + "b", {cyrillic_a + "ab"}).find("(character 2)"), std::string::npos);
  std::string many;
  for (int i = 0; i < 1000; ++i) many += cyrillic_a;
  const std::string long_note = did_you_mean(many, {std::string(1000, 'a')});
  EXPECT_NE(long_note.find("(character 5) and 995 more"), std::string::npos) << long_note.substr(0, 300);
  EXPECT_LT(long_note.size(), 2 * 1000 + 2 * 1000 + 400u);  // the two words and five characters, no more
  EXPECT_EQ(did_you_mean("sise", {"size", "mass"}), "; did you mean 'size'?");  // a slip: no look-alike note
  EXPECT_EQ(did_you_mean("zzzz", {"size", "mass"}), "");
  expect_error({"derive", f3, "--effects", "rotor_dr" + cyrillic_a + "g", "--out", tmp / "o"}, 2,
               "did you mean 'rotor_drag'? (they look alike, but 'rotor_dr" + cyrillic_a +
                   "g' has U+0430 CYRILLIC SMALL LETTER A (character 9))");
  expect_error({"diagnose", f3, "x.csv", "--m" + cyrillic_a + "pping", "M.yaml", "--out", tmp / "o"}, 109,
               "'--mapping' for '--m" + cyrillic_a + "pping' (they look alike, but '--m" + cyrillic_a +
                   "pping' has U+0430 CYRILLIC SMALL LETTER A (character 4))");
  // The edits are counted within a band of the limit: the same counts as the whole table
  // (an independent one here) for every pair of short words over a small alphabet, and two
  // names of 200 kB are compared in length x 5 steps, not 4e10.
  const auto full_table = [](const std::string& a, const std::string& b) {
    std::vector<std::vector<size_t>> d(a.size() + 1, std::vector<size_t>(b.size() + 1));
    for (size_t i = 0; i <= a.size(); ++i) d[i][0] = i;
    for (size_t j = 0; j <= b.size(); ++j) d[0][j] = j;
    for (size_t i = 1; i <= a.size(); ++i)
      for (size_t j = 1; j <= b.size(); ++j)
        d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + (a[i - 1] != b[j - 1])});
    return d[a.size()][b.size()];
  };
  std::vector<std::string> words = {""};
  for (size_t len = 1; len <= 4; ++len)
    for (size_t code = 0; code < (1u << (2 * len)) && words.size() < 200; code += 3) {
      std::string w;
      for (size_t k = 0; k < len; ++k) w += "abcd"[(code >> (2 * k)) & 3];
      words.push_back(w);
    }
  for (const auto& a : words)
    for (const auto& b : words)
      for (size_t limit : {0u, 1u, 2u, 3u})
        ASSERT_EQ(quadgen::output::edit_distance(a, b, limit), std::min(full_table(a, b), limit + 1))
            << "'" << a << "' '" << b << "' " << limit;
  const std::string huge(200000, 'x');
  EXPECT_EQ(quadgen::output::edit_distance(huge, huge + "y", 2), 1u);
  EXPECT_EQ(quadgen::output::edit_distance("y" + huge, huge + "y", 1), 2u);  // beyond the limit
  EXPECT_EQ(quadgen::output::nearest_word(huge + "y", {huge + "z", "x"}), huge + "z");
  // Files that are not logs are named as what they should have been.
  ASSERT_EQ(run_quadgen({"simulate", cf, "--closed-loop", "--duration", "4", "--out", tmp / "f.csv"}, tmp.dir).rc, 0);
  expect_error({"fit", cf, tmp / "f.csv", "--mapping", tmp / "missing.yaml", "--out", tmp / "o"}, 2,
               "missing.yaml: cannot open a column mapping (YAML)");
  expect_error({"predict", cf, tmp / "f.csv", "--params", tmp / "nope.json", "--out", tmp / "o"}, 2,
               "nope.json: cannot open a diagnosis.json or fit.json");
  // A log of another layout without its mapping; a vehicle file given as the log.
  write(tmp / "other.csv", "time,m1,m2,m3,m4\n0,0.5,0.5,0.5,0.5\n0.01,0.5,0.5,0.5,0.5\n");
  expect_error({"fit", cf, tmp / "other.csv", "--out", tmp / "o"}, 2,
               "other.csv:1: missing columns 't', 'u_M1', 'u_M2', 'u_M3', 'u_M4': the time and the rotor commands; a "
               "log in another layout is read with --mapping M.yaml");
  expect_error({"diagnose", cf, f3, "--out", tmp / "o"}, 2, "finken3.yaml:1: no CSV header");
  // A stray comma in an effect list; a thrust-stand fit given as a flight model's values.
  expect_error({"derive", f3, "--effects", "motor_lag,", "--out", tmp / "o"}, 2, "has an empty name");
  expect_error({"derive", f3, "--effects", "all,wind", "--out", tmp / "o"}, 2, "'all' stands alone");
  // Lists nested past the YAML reader's depth guard: said as such, not as its "bad file".
  write(tmp / "deep.yaml", "name: deep\nblocks: " + std::string(600, '[') + std::string(600, ']') + "\n");
  expect_error({"derive", tmp / "deep.yaml", "--out", tmp / "o"}, 2, "deep.yaml:2: malformed YAML: nested more deeply than");
  // A NUL after a backslash: the parser's message quotes it, and the error ended there.
  write(tmp / "nul.yaml", std::string("name: \"fin\\\0ken\"\n", 17));
  expect_error({"derive", tmp / "nul.yaml", "--out", tmp / "o"}, 2, "nul.yaml:1: malformed YAML: unknown escape character: \\x00");
  write(tmp / "stand.json", R"({"kind": "thrust_stand", "summary": {}, "thrust_vs_speed": {"estimates": {}}})");
  expect_error({"predict", cf, tmp / "f.csv", "--params", tmp / "stand.json", "--out", tmp / "o"}, 2,
               "a thrust-stand fit describes the motors");
  // A wrong --airframe file is said before the logs are read (here one that does not exist).
  expect_error({"diagnose", cf, tmp / "missing.csv", "--airframe", tmp / "stand.json", "--out", tmp / "o"}, 2,
               "not a diagnosis.json of quadgen");
  // One of the right shape with an entry of another type: the file named, not the JSON
  // library's bare message.
  write(tmp / "typed.json", R"({"airframe_fit": {}, "flight_parameters": [], "findings": [{"effect": 123, "parameters": {}}]})");
  expect_error({"diagnose", cf, tmp / "missing.csv", "--airframe", tmp / "typed.json", "--out", tmp / "o"}, 2,
               "typed.json: not the diagnosis.json layout quadgen writes (type must be string, but is number)");
  // A finding's value outside its parameter's bounds (an infinite one broke the comparison's
  // test with the statistics library's bare message), an effect the catalogue lacks.
  const auto finding = [&](const std::string& name, const std::string& effect, const std::string& value) {
    write(tmp / name, R"({"airframe_fit": {}, "flight_parameters": [], "findings": [{"effect": ")" + effect +
                          R"(", "parameters": {"motor_lag.tau": {"value": )" + value + "}}}]}");
    return tmp / name;
  };
  expect_error({"diagnose", cf, tmp / "missing.csv", "--airframe", finding("huge.json", "motor_lag", "1e308"), "--out", tmp / "o"},
               2, "huge.json: findings: motor_lag.tau = 1e+308 is outside its bounds");
  expect_error({"diagnose", cf, tmp / "missing.csv", "--airframe", finding("negative.json", "motor_lag", "-5"), "--out", tmp / "o"},
               2, "negative.json: findings: motor_lag.tau = -5 is outside its bounds");
  expect_error({"diagnose", cf, tmp / "missing.csv", "--airframe", finding("unknown.json", "wind2", "0.05"), "--out", tmp / "o"},
               2, "unknown.json: findings: unknown effect 'wind2'");
  // A value too small for a double, which the JSON parser alone reads as 0 (as --params' test).
  expect_error({"diagnose", cf, tmp / "missing.csv", "--airframe", finding("tiny.json", "motor_lag", "1e-400"), "--out", tmp / "o"},
               2, "tiny.json: the number 1e-400 is below the smallest number a double holds, so it would read as 0");
  // A unit other than the model's (as --params' test), in the airframe's values and in a finding.
  write(tmp / "mm_airframe.json", R"({"airframe_fit": {"kappa": {"value": 2, "unit": "mm"}}, "flight_parameters": [], "findings": []})");
  expect_error({"diagnose", cf, tmp / "missing.csv", "--airframe", tmp / "mm_airframe.json", "--out", tmp / "o"}, 2,
               "mm_airframe.json: airframe_fit.kappa is in m, the file says 'mm'");
  write(tmp / "ms_finding.json", R"({"airframe_fit": {}, "flight_parameters": [], "findings": [{"effect": "motor_lag", )"
                                 R"("parameters": {"motor_lag.tau": {"value": 30, "unit": "ms"}}}]})");
  expect_error({"diagnose", cf, tmp / "missing.csv", "--airframe", tmp / "ms_finding.json", "--out", tmp / "o"}, 2,
               "ms_finding.json: findings: motor_lag.tau is in s, the file says 'ms'");
}

// A user trial of the less-trodden paths (helper-79, 2026-12-03): simulate ignored --effects
// outside a closed loop (--set needed one), a --set name slip blamed a missing effect, fit
// listed no channel names, a closed loop out of authority said nothing, and fit pulled a 25 ms
// delay to 30 ms from the accelerometer's samples without a word.
TEST(Cli, UserTrialFindingsAreSaid) {
  Scratch tmp;
  const std::string f3 = source_path("vehicles/finken3.yaml");
  const auto slurp = [](const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
  };
  // A scenario flies the values --set gives; an effect without one stays neutral.
  const auto fly = [&](const std::string& name, std::vector<std::string> extra) {
    std::vector<std::string> args = {"simulate", f3, "--scenario", "hover", "--duration", "1", "--out", tmp / name};
    args.insert(args.end(), extra.begin(), extra.end());
    const CliResult r = run_quadgen(args, tmp.dir);
    EXPECT_EQ(r.rc, 0) << r.err;
    return slurp(tmp / name);
  };
  const std::string plain = fly("plain.csv", {}), neutral = fly("neutral.csv", {"--effects", "motor_gain"}),
                    weak = fly("weak.csv", {"--effects", "motor_gain", "--set", "motor_gain.C=-0.1"});
  EXPECT_EQ(plain.substr(plain.find('\n')), neutral.substr(neutral.find('\n')));  // the header names no effect
  EXPECT_NE(neutral, weak);
  // A base parameter there would be half applied (the commands, start and plot are the file's).
  expect_one_line_error(run_quadgen({"simulate", f3, "--scenario", "hover", "--duration", "1", "--set", "c_t=0.02",
                                     "--out", tmp / "x.csv"}, tmp.dir),
                        "only an effect's parameters may be set there", "--set c_t in a scenario");
  // A slip in a --set name is named as one; a parameter of an effect not added names the effect.
  expect_one_line_error(run_quadgen({"simulate", f3, "--scenario", "hover", "--duration", "1", "--effects", "motor_gain",
                                     "--set", "motor_gain.c=-0.1", "--out", tmp / "x.csv"}, tmp.dir),
                        "no parameter 'motor_gain.c' in the model; did you mean 'motor_gain.C'?", "--set motor_gain.c");
  expect_one_line_error(run_quadgen({"simulate", f3, "--scenario", "hover", "--duration", "1", "--set",
                                     "motor_gain.C=-0.1", "--out", tmp / "x.csv"}, tmp.dir),
                        "(its effect motor_gain is not in the model: add it with --effects)", "--set without --effects");
  // A closed loop that ran out of authority says so; one within reach does not.
  const CliResult hard = run_quadgen({"simulate", f3, "--closed-loop", "--duration", "10", "--excitation", "1", "--out",
                                      tmp / "hard.csv"}, tmp.dir);
  EXPECT_EQ(hard.rc, 0) << hard.err;
  EXPECT_NE(hard.err.find("note: a motor command is at its limit (0 or 1) in "), std::string::npos) << hard.err;
  const CliResult easy = run_quadgen({"simulate", f3, "--closed-loop", "--duration", "20", "--effects", "input_delay",
                                      "--set", "input_delay.seconds=0.025", "--out", tmp / "delay.csv"}, tmp.dir);
  EXPECT_EQ(easy.rc, 0) << easy.err;
  EXPECT_EQ(easy.err.find("at its limit"), std::string::npos) << easy.err;
  // fit names its channels; with the accelerometer a delay between two sample intervals comes
  // out at one, which fit says, and the differentiated velocity finds it.
  expect_one_line_error(run_quadgen({"fit", f3, tmp / "delay.csv", "--channels", "ax,p_dot", "--out", tmp / "o"}, tmp.dir),
                        "(channels: ax, ay, az, pdot, qdot, rdot); did you mean 'pdot'?", "--channels ax,p_dot");
  const auto delay_fit = [&](const std::string& name, std::vector<std::string> extra) {
    std::vector<std::string> args = {"fit", f3, tmp / "delay.csv", "--effects", "input_delay", "--free",
                                     "input_delay.seconds,c_t", "--profiles", "none", "--out", tmp / name};
    args.insert(args.end(), extra.begin(), extra.end());
    const CliResult r = run_quadgen(args, tmp.dir);
    EXPECT_EQ(r.rc, 0) << r.err;
    const auto j = nlohmann::json::parse(slurp(tmp / name + "/fit.json"));
    return std::make_pair(j["estimates"]["input_delay.seconds"]["value"].get<double>(), r.err);
  };
  const auto [from_accelerometer, said] = delay_fit("acc", {});
  EXPECT_NEAR(from_accelerometer, 0.030, 5e-4);
  EXPECT_NE(said.find("is a whole number of the accelerometer's sample intervals (10 ms)"), std::string::npos) << said;
  const auto [from_pose, quiet] = delay_fit("pose", {"--translational", "pose"});
  EXPECT_NEAR(from_pose, 0.025, 5e-4);
  EXPECT_EQ(quiet.find("whole number"), std::string::npos) << quiet;
  // No delay at all is no whole number of intervals to warn of.
  ASSERT_EQ(run_quadgen({"simulate", f3, "--closed-loop", "--duration", "20", "--out", tmp / "delay.csv"}, tmp.dir).rc, 0);
  const auto [none, none_said] = delay_fit("none", {});
  EXPECT_LT(none, 1e-3);
  EXPECT_EQ(none_said.find("whole number"), std::string::npos) << none_said;
}

// A log whose evaluated part is too short for one rollout is the input's problem: refused with
// what would work, nothing written (before, every horizon read NaN and predict blamed the model).
TEST(Cli, PredictRefusesALogTooShortForOneRollout) {
  Scratch tmp;
  const std::string vehicle = source_path("vehicles/finken3.yaml");
  ASSERT_EQ(run_quadgen({"simulate", vehicle, "--closed-loop", "--duration", "3", "--out", tmp / "f.csv"}, tmp.dir).rc, 0);
  const CliResult r = run_quadgen({"predict", vehicle, tmp / "f.csv", "--out", tmp / "p"}, tmp.dir);
  EXPECT_EQ(r.rc, 2) << r.err;
  EXPECT_NE(r.err.find("no rollout could start"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("give a longer flight or a larger --validation"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(tmp / "p"));
  // All of it evaluated, there is room for rollouts.
  EXPECT_EQ(run_quadgen({"predict", vehicle, tmp / "f.csv", "--validation", "1", "--out", tmp / "q"}, tmp.dir).rc, 0);
  // A log without a pose has no rollouts at all, whatever its length: its one-step errors are
  // measured, and that is no refusal (the ARPL log is one).
  const quadgen::runtime::CsvTable flight = quadgen::runtime::read_csv(tmp / "f.csv");
  const auto write_columns = [&](const std::string& path, const std::vector<std::string>& names) {
    std::vector<int> kept;
    for (const auto& name : names) kept.push_back(flight.column(name));
    ASSERT_EQ(std::count(kept.begin(), kept.end(), -1), 0);
    std::ostringstream out;
    out.precision(17);
    for (size_t i = 0; i < kept.size(); ++i) out << (i ? "," : "") << names[i];
    for (const auto& row : flight.rows) {
      out << "\n";
      for (size_t i = 0; i < kept.size(); ++i) out << (i ? "," : "") << row[kept[i]];
    }
    write(path, out.str() + "\n");
  };
  const std::vector<std::string> imu{"t", "u_A", "u_B", "u_C", "u_D", "p", "q", "r", "ax", "ay", "az", "vbat"};
  write_columns(tmp / "imu.csv", imu);
  const CliResult r_imu = run_quadgen({"predict", vehicle, tmp / "imu.csv", "--out", tmp / "i"}, tmp.dir);
  EXPECT_EQ(r_imu.rc, 0) << r_imu.err;
  EXPECT_NE(r_imu.err.find("no pose logged: one-step errors only"), std::string::npos) << r_imu.err;
  // Part of a pose (positions and a lone qw) is read as none, and said before the work.
  std::vector<std::string> part = imu;
  part.insert(part.end(), {"x", "y", "z", "qw"});
  write_columns(tmp / "part.csv", part);
  const CliResult r_part = run_quadgen({"predict", vehicle, tmp / "part.csv", "--out", tmp / "j"}, tmp.dir);
  EXPECT_EQ(r_part.rc, 0) << r_part.err;
  EXPECT_NE(r_part.err.find("part.csv:1: no pose is read, only the accelerometer: a pose needs x, y, z and qw, qx, qy, qz or "
                            "phi, theta, psi; it has qw but not qx, qy, qz\n"),
            std::string::npos)
      << r_part.err;
  EXPECT_NE(r_part.err.find("part.csv: one-step errors only"), std::string::npos) << r_part.err;
}

// ---- options -------------------------------------------------------------------------------

TEST(Options, EveryNumberIsCheckedAndNothingIsSilentlyIgnored) {
  Scratch tmp;
  const std::string f3 = source_path("vehicles/finken3.yaml");
  const std::string steps = source_path("data/finken3_motor_steps.csv");
  // A thrust-stand log (the columns of Bitcraze's stand, as in the shared data): its own few
  // rows, so that the test needs nothing outside the repository.
  const std::string stand = tmp / "stand.csv";
  {
    std::ofstream out(stand);
    out << "weight[g],pwm,vbat[V],rpm1,rpm2,rpm3,rpm4,v[V],i[A],p[W]\n"
           "0.0,0,3.874,0,0,0,0,3.903,0.189,0.657\n"
           "10.2,20000,3.85,9000,9100,8950,9050,3.88,1.1,4.2\n"
           "25.1,40000,3.80,15000,15100,14900,15050,3.83,2.9,11.1\n";
  }
  const std::string traj = tmp / "t.csv";
  const std::vector<std::pair<std::vector<std::string>, std::string>> cases = {
      {{"simulate", f3, "--scenario", "hover", "--duration", "nan", "--out", traj}, "--duration"},
      {{"simulate", f3, "--scenario", "hover", "--duration", "inf", "--out", traj}, "--duration"},
      {{"simulate", f3, "--scenario", "hover", "--duration", "1", "--rate", "nan", "--out", traj}, "--rate"},
      {{"simulate", f3, "--scenario", "hover", "--duration", "1", "--step", "-1", "--out", traj}, "--step"},
      {{"simulate", f3, "--closed-loop", "--duration", "1", "--pose-noise", "-1", "--out", traj}, "--pose-noise"},
      {{"simulate", f3, "--closed-loop", "--duration", "1", "--set", "c_t=abc", "--out", traj}, "--set"},
      {{"simulate", f3, "--closed-loop", "--duration", "1", "--set", "c_t=nan", "--out", traj}, "--set"},
      {{"simulate", f3, "--scenario", "hover", "--duration", "1", "--seed", "3", "--out", traj}, "--seed"},
      {{"simulate", f3, "--scenario", "hover", "--duration", "1", "--set", "mass=-1", "--out", traj}, "--set"},
      {{"simulate", f3, "--scenario", "hover", "--duration", "1", "--pose-noise", "0.1", "--out", traj}, "--pose-noise"},
      {{"simulate", f3, "--closed-loop", "--duration", "1", "--step", "0.01", "--out", traj}, "--step"},
      {{"simulate", f3, "--scenario", "hover", "--duration", "1e8", "--out", traj}, "--no-size-limit"},
      {{"simulate", f3, "--scenario", "hover", "--duration", "1e12", "--out", traj}, "--duration"},
      {{"simulate", f3, "--scenario", "hover", "--duration", "2", "--step", "1e-7", "--out", traj}, "integration steps"},
      {{"fit", f3, steps, "--out", tmp / "f", "--effects", "motor_lag"}, "--effects: not used when fitting a motor-step log"},
      {{"fit", f3, steps, "--out", tmp / "f", "--free", "c_t"}, "--free"},
      {{"fit", f3, steps, "--out", tmp / "f", "--validation", "0.2"}, "--validation"},
      {{"fit", f3, steps, "--out", tmp / "f", "--validation", "nan"}, "--validation"},
      {{"fit", f3, stand, "--out", tmp / "f", "--channels", "ax"}, "--channels: not used when fitting a thrust-stand log"},
      {{"diagnose", f3, steps, "--out", tmp / "g", "--alpha", "nan"}, "--alpha"},
  };
  for (const auto& [args, expected] : cases) {
    const CliResult r = run_quadgen(args, tmp.dir);
    std::string joined;
    for (const auto& a : args) joined += a + " ";
    EXPECT_NE(r.rc, 0) << joined;
    EXPECT_NE(r.err.find(expected), std::string::npos) << joined << "\n" << r.err;
    EXPECT_FALSE(fs::exists(traj)) << joined;
    EXPECT_FALSE(fs::exists(tmp / "f")) << joined;
  }
}

TEST(Options, ReplayLongerThanTheLogIsRefused) {
  Scratch tmp;
  const std::string f3 = source_path("vehicles/finken3.yaml");
  ASSERT_EQ(run_quadgen({"simulate", f3, "--scenario", "hover", "--duration", "0.5", "--out", tmp / "log.csv"}, tmp.dir).rc, 0);
  const CliResult r = run_quadgen({"simulate", f3, "--inputs", tmp / "log.csv", "--duration", "10000", "--out", tmp / "r.csv"}, tmp.dir);
  expect_one_line_error(r, "holds 0.5", "long replay");
  EXPECT_FALSE(fs::exists(tmp / "r.csv"));
}

// Colours reach the script only as #rrggbb (anything else is left to gnuplot's default), and
// a panel's marks become dashed vertical lines that do not carry over to the next panel.
TEST(Sinks, PlotColoursAndMarksAreDataNotScript) {
  using quadgen::runtime::Panel;
  using quadgen::runtime::Series;
  Series base{"base model", {0, 1}, {0, 1}, false, "#d62728"};
  Series bad{"x", {0, 1}, {0, 1}, false, "#00'; system 'touch PWNED"};
  const std::string script =
      quadgen::runtime::gnuplot_script("t", {Panel{"a", "t", "m", {base, bad}, {0.5}}, Panel{"b", "t", "m", {base}}});
  EXPECT_NE(script.find("lc rgb '#d62728'"), std::string::npos);
  EXPECT_EQ(script.find("system"), std::string::npos);
  EXPECT_EQ(script.find("PWNED"), std::string::npos);
  const size_t arrow = script.find("set arrow from 0.5");
  ASSERT_NE(arrow, std::string::npos);
  EXPECT_NE(script.find("unset arrow", arrow), std::string::npos);  // cleared before the second panel
}

// A plot's axes read as a person reads a unit ("m/s²"), the CSV beside it keeps the label as
// declared ("m/s^2", what a script compares), and a hostile label is still one gnuplot string.
TEST(Sinks, APlotsAxesRaiseTheirPowersAndItsCsvKeepsThem) {
  using quadgen::runtime::Panel;
  using quadgen::runtime::Series;
  const std::vector<Panel> panels{{"a", "k [N s^2]", "m/s^2'; system('touch PWNED')", {Series{"s", {0, 1}, {0, 1}}}}};
  const std::string script = quadgen::runtime::gnuplot_script("t", panels);
  EXPECT_NE(script.find("set xlabel 'k [N s²]' noenhanced"), std::string::npos) << script;
  EXPECT_NE(script.find("set ylabel 'm/s²'.\"'\".'; system('.\"'\".'touch PWNED'.\"'\".')' noenhanced"), std::string::npos)
      << script;
  const std::string csv = quadgen::runtime::panels_csv("t", panels);
  EXPECT_NE(csv.find("k [N s^2]"), std::string::npos) << csv;
  EXPECT_EQ(csv.find("²"), std::string::npos) << csv;
}

// gnuplot refuses a series whose every point is undefined ("all points y value undefined"):
// such a series (a horizon no rollout reached) is left out, and the figure is drawn.
TEST(Sinks, ASeriesWithoutOneFinitePointIsLeftOutOfThePlot) {
  using quadgen::runtime::Panel;
  using quadgen::runtime::Series;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const Series drawn{"drawn", {0.1, 0.5}, {0.01, nan}}, undefined{"undefined", {0.1, 0.5}, {nan, nan}};
  const std::string script = quadgen::runtime::gnuplot_script("t", {Panel{"a", "h", "m", {drawn, undefined}}});
  EXPECT_NE(script.find("'drawn'"), std::string::npos);
  EXPECT_EQ(script.find("'undefined'"), std::string::npos);
  std::string svg, err;
  EXPECT_TRUE(quadgen::runtime::render_svg("t", {Panel{"a", "h", "m", {drawn, undefined}}}, &svg, &err)) << err;
  EXPECT_TRUE(quadgen::runtime::render_svg("t", {Panel{"a", "h", "m", {undefined}}}, &svg, &err)) << err;
}

// The thesis' manoeuvres are flown as fractions of each vehicle's own hover thrust, so every
// scenario flies the 27 g Crazyflie too (in newtons it was asked for 17 times its weight).
// The climb's start is checked against its closed form: (1.1 / 0.9491 - 1) g upwards, the
// thesis' 1.1 N per rotor on its 0.9491 N hover, whatever the vehicle.
TEST(Cli, EveryScenarioFliesAnyVehicle) {
  Scratch tmp;
  for (const char* file : {"vehicles/finken3.yaml", "vehicles/crazyflie21.yaml"}) {
    for (const char* scenario : {"hover", "climb", "right", "forward", "yaw", "new_height"}) {
      const std::string out = tmp / (std::string(scenario) + ".csv");
      const CliResult r =
          run_quadgen({"simulate", source_path(file), "--scenario", scenario, "--duration", "3", "--out", out}, tmp.dir);
      ASSERT_EQ(r.rc, 0) << file << " " << scenario << ": " << r.err;
    }
    const quadgen::runtime::CsvTable climb = quadgen::runtime::read_csv(tmp / "climb.csv");
    const double t_end = 0.3, a = (1.1 / 0.9491 - 1) * 9.81;
    size_t k = 0;
    while (k + 1 < climb.rows.size() && climb.rows[k][climb.column("t")] < t_end - 1e-9) ++k;
    ASSERT_NEAR(climb.rows[k][climb.column("t")], t_end, 1e-9);
    EXPECT_NEAR(climb.rows[k][climb.column("z")], 0.5 * a * t_end * t_end, 0.05 * 0.5 * a * t_end * t_end) << file;
    for (const char* scenario : {"hover", "climb", "right", "forward", "yaw", "new_height"})
      fs::remove(tmp / (std::string(scenario) + ".csv")), fs::remove(tmp / (std::string(scenario) + ".svg"));
    fs::remove(tmp / ".quadgen-files");
  }
}

// An earlier output that still holds files quadgen did not write is kept aside, under a name
// beside the output; where "<name>.previous-<pid>" would pass the file system's name limit
// (255 bytes), under a short one. Marked either way, so no later run takes it for a stale
// staging folder.
TEST(DataLoss, AnEarlierOutputIsKeptAsideEvenUnderALongName) {
  Scratch tmp;
  const std::string pid = std::to_string(::getpid());
  for (const size_t length : {size_t{8}, size_t{250}}) {
    const fs::path target = tmp.dir / std::string(length, 'o');
    const fs::path staged = tmp.dir / ".staged";
    fs::create_directories(staged);
    write((staged / "notes.txt").string(), "a user's file\n");
    const fs::path kept = quadgen::output::detail::keep_aside(staged, target);
    const std::string expected = length < 200 ? target.filename().string() + ".previous-" + pid : "quadgen-previous-" + pid;
    EXPECT_EQ(kept, tmp.dir / expected) << length;
    EXPECT_FALSE(fs::exists(staged));
    EXPECT_EQ(read(kept / "notes.txt"), "a user's file\n");
    EXPECT_TRUE(fs::exists(kept / ".quadgen-keep"));
    fs::remove_all(kept);
  }
  // A link planted under the marker's name by whoever could write to the earlier output:
  // replaced, the file it points to untouched (std::ofstream followed it).
  const fs::path staged = tmp.dir / ".staged";
  fs::create_directories(staged);
  write((staged / "notes.txt").string(), "a user's file\n");
  write((tmp.dir / "victim.txt").string(), "someone's file\n");
  fs::create_symlink(tmp.dir / "victim.txt", staged / ".quadgen-keep");
  const fs::path kept = quadgen::output::detail::keep_aside(staged, tmp.dir / "out");
  EXPECT_EQ(read(tmp.dir / "victim.txt"), "someone's file\n");
  EXPECT_FALSE(fs::is_symlink(kept / ".quadgen-keep"));
  EXPECT_NE(read(kept / ".quadgen-keep").find("an earlier quadgen output"), std::string::npos);
}

// Only folders named as quadgen names its staging folders are removed as stale: a user's
// ".res.quadgen-tmp.notes" beside --out res survives a run (it did not, when any name with
// that start and no live pid in it counted), and a long output name's folders are not
// another long name's with the same first 100 characters.
TEST(DataLoss, OnlyQuadgensOwnStagingFoldersAreRemovedAsStale) {
  using quadgen::output::detail::staging_pid;
  using quadgen::output::detail::staging_stem;
  const std::string stem = staging_stem("res");
  EXPECT_EQ(stem, ".res.quadgen-tmp.");
  EXPECT_EQ(staging_pid(stem + "4242.aB3xY9", stem), 4242);
  for (const std::string& other : {stem + "notes", stem + "4242", stem + "4242.abc", stem + "4242.abcdefg",
                                   stem + ".abcdef", stem + "42x2.abcdef", stem + "4242.abc/ef", std::string(".res.quadgen-tmp.1.quadgen-tmp.4242.abcdef")})
    EXPECT_EQ(staging_pid(other, stem), -1) << other;
  const std::string a = std::string(120, 'o') + "a", b = std::string(120, 'o') + "b";
  EXPECT_NE(staging_stem(a), staging_stem(b));
  EXPECT_EQ(staging_stem(a).rfind(staging_stem(b), 0), std::string::npos);
  EXPECT_LT(staging_stem(a).size() + 25, size_t{255});

  Scratch tmp;
  const fs::path users = tmp.dir / ".res.quadgen-tmp.notes";
  fs::create_directories(users);
  write((users / "keep.txt").string(), "mine\n");
  const fs::path stale = tmp.dir / ".res.quadgen-tmp.999999999.abcdef";  // beyond any pid_max: a dead run's
  fs::create_directories(stale);
  write((stale / "f.csv").string(), "left by a killed run\n");
  ASSERT_EQ(run_quadgen({"derive", source_path("vehicles/crazyflie21.yaml"), "--out", tmp / "res"}, tmp.dir).rc, 0);
  EXPECT_EQ(read(users / "keep.txt"), "mine\n");
  EXPECT_FALSE(fs::exists(stale));
}

// derive's summary says where the mass properties it prints come from, and counts the vehicle's
// warnings (a user trial, helper-82: "centre of gravity of the blocks" printed a value the file
// gave, and "audit passed" stood above warnings that a vehicle cannot fly).
TEST(Cli, DeriveSaysWhereItsMassPropertiesComeFrom) {
  Scratch tmp;
  const std::string text = read(source_path("vehicles/finken3.yaml"));
  const std::string mass = "  mass: {fit: false, bounds: [0.2, 0.8]}\n";
  ASSERT_NE(text.find(mass), std::string::npos);
  std::string given = text;
  given.replace(given.find(mass), mass.size(), "  mass: {value: 520, unit: g}\n  J_xy: {value: 0.002, unit: kg m^2}\n");
  write(tmp.dir / "given.yaml", given);
  const auto derive = [&](const std::string& vehicle, const char* out) {  // stdout and stderr, the exit status
    FILE* p = ::popen((std::string(QUADGEN_BINARY) + " derive '" + vehicle + "' --out '" + (tmp / out) + "' 2>&1").c_str(), "r");
    std::string said;
    char buf[1024];
    while (p && std::fgets(buf, sizeof buf, p)) said += buf;
    const int status = p ? ::pclose(p) : -1;
    return std::make_pair(status, said);
  };
  const auto [blocks_status, blocks] = derive(source_path("vehicles/finken3.yaml"), "a");
  ASSERT_EQ(blocks_status, 0) << blocks;
  EXPECT_NE(blocks.find(" checks); derived"), std::string::npos) << blocks;
  EXPECT_NE(blocks.find("kg (the blocks'); centre of gravity ("), std::string::npos) << blocks;
  const auto [file_status, file] = derive(tmp / "given.yaml", "b");
  ASSERT_EQ(file_status, 0) << file;  // a vehicle's warning is no failed derivation
  EXPECT_NE(file.find(" checks; 1 vehicle warning below); derived"), std::string::npos) << file;
  EXPECT_NE(file.find("mass 0.52 kg (the file's `derived:`); centre of gravity ("), std::string::npos) << file;
  EXPECT_NE(file.find(" kg m² (the blocks'; the file's `derived:`: J_xy)"), std::string::npos) << file;
  EXPECT_NE(file.find("the inertia the model uses is a body's: no"), std::string::npos) << file;
  // simulate refuses such a tensor at the line that gives it (it named the file alone;
  // helper-88): the message a closed loop of `file` ends in, and the line of `given` in it.
  const auto refusal_at = [&](const std::string& file, const std::string& content, const std::string& given) {
    write(tmp.dir / file, content);
    const auto line = std::count(content.begin(), content.begin() + static_cast<long>(content.find(given)), '\n') + 1;
    const auto r = run_quadgen({"simulate", tmp / file, "--closed-loop", "--duration", "1", "--out", tmp / "s.csv"}, tmp.dir);
    EXPECT_NE(r.rc, 0);
    EXPECT_NE(r.err.find(file + ":" + std::to_string(line) + ": the inertia tensor's principal moments are "),
              std::string::npos)
        << r.err;
    EXPECT_FALSE(fs::exists(tmp / "s.csv"));
    return r.err;
  };
  refusal_at("given.yaml", given, "  J_xy: {value: 0.002");
  // A moment too large for the other two (the triangle rule) is a moment's line, not that of a
  // harmless product of inertia the file also gives (a review, helper-89).
  std::string lopsided = text;
  lopsided.replace(lopsided.find(mass), mass.size(), "  J_xy: {value: 0, unit: kg m^2}\n  J_zz: {value: 0.1, unit: kg m^2}\n");
  const std::string lopsided_said = refusal_at("lopsided.yaml", lopsided, "  J_zz: {value: 0.1");
  EXPECT_NE(lopsided_said.find("the largest exceeds the sum of the other two"), std::string::npos) << lopsided_said;
  // A fitted value (--params) is said as fitted, not as the blocks'.
  write(tmp.dir / "fitted.yaml", "vehicle: finken3\neffects: []\nparameters:\n  mass: {value: 0.4, unit: kg}\n");
  FILE* p = ::popen((std::string(QUADGEN_BINARY) + " derive '" + source_path("vehicles/finken3.yaml") + "' --params '" +
                     (tmp / "fitted.yaml") + "' --out '" + (tmp / "c") + "' 2>&1")
                        .c_str(),
                    "r");
  ASSERT_NE(p, nullptr);
  std::string fitted;
  char buf[1024];
  while (std::fgets(buf, sizeof buf, p)) fitted += buf;
  EXPECT_EQ(::pclose(p), 0) << fitted;
  EXPECT_NE(fitted.find("mass 0.4 kg (fitted); centre of gravity ("), std::string::npos) << fitted;
  // A fitted value replaces a `derived:` one too, and is said as fitted, in the summary, in
  // derivation.md and in model.json's mass (a sixth audit, helper-86: all three said the file's).
  const auto [both_status, both] = [&] {
    FILE* q = ::popen((std::string(QUADGEN_BINARY) + " derive '" + (tmp / "given.yaml") + "' --params '" +
                       (tmp / "fitted.yaml") + "' --out '" + (tmp / "d") + "' 2>&1")
                          .c_str(),
                      "r");
    std::string said;
    while (q && std::fgets(buf, sizeof buf, q)) said += buf;
    return std::make_pair(q ? ::pclose(q) : -1, said);
  }();
  ASSERT_EQ(both_status, 0) << both;
  EXPECT_NE(both.find("mass 0.4 kg (fitted); centre of gravity ("), std::string::npos) << both;
  EXPECT_NE(read(tmp / "d/derivation.md").find("`mass` = 0.52 kg (replaced by the fitted 0.4 kg)"), std::string::npos);
  const auto model = nlohmann::json::parse(read(tmp / "d/model.json"));
  EXPECT_EQ(model.at("mass").get<double>(), 0.4);
  EXPECT_NEAR(model.at("from_blocks").at("mass").get<double>(), 0.387, 1e-9);
  EXPECT_EQ(model.at("inertia")[0][1].get<double>(), 0.002);  // the file's J_xy, not the blocks' 0
  EXPECT_EQ(model.at("units"), nlohmann::json::parse(R"({"mass": "kg", "cog": "m", "inertia": "kg m^2", "areas": "m^2",
                                                          "inertia_about_origin": "kg m^2"})"));
  // A given mass or principal moment that no body has is refused at its line (it passed the
  // audit, and the trim blamed a motor map in rpm).
  std::string zero = text;
  zero.replace(zero.find(mass), mass.size(), "  mass: {value: 0, unit: kg}\n");
  write(tmp.dir / "zero.yaml", zero);
  const size_t line = static_cast<size_t>(std::count(zero.begin(), zero.begin() + static_cast<long>(zero.find("  mass: {value: 0")), '\n')) + 1;
  const auto [zero_status, zero_said] = derive(tmp / "zero.yaml", "e");
  EXPECT_NE(zero_status, 0);
  EXPECT_NE(zero_said.find("zero.yaml:" + std::to_string(line) + ":"), std::string::npos) << zero_said;
  EXPECT_NE(zero_said.find("derived quantity mass = 0: a mass and a principal moment of inertia must be positive"),
            std::string::npos)
      << zero_said;
  EXPECT_FALSE(fs::exists(tmp / "e"));
}

// A manoeuvre on a vehicle whose centre of gravity is off the rotors' centre (a user trial,
// helper-82): each raised rotor's step scaled by its own trim turned the vehicle about axes the
// manoeuvre does not mean (yaw tilted it 0.27 rad and moved it 0.55 m in 2 s). With that part
// taken out, what is left is the inertia's own coupling (the off-centre block's products of
// inertia turn a yaw moment into a little roll and pitch): under a tenth of the yaw.
TEST(Cli, ManoeuvresTurnAnOffCentreVehicleOnlyAboutTheirAxis) {
  Scratch tmp;
  std::string text = read(source_path("vehicles/finken3.yaml"));
  const std::string upper = "centre: [0, 0, 0.036]", name = "name: finken3";
  ASSERT_NE(text.find(upper), std::string::npos);
  text.replace(text.find(upper), upper.size(), "centre: [0.02, 0.015, 0.036]");
  text.replace(text.find(name), name.size(), "name: off_centre");
  write(tmp.dir / "off_centre.yaml", text);
  const auto end_of = [&](const char* scenario) {
    const fs::path out = tmp / (std::string(scenario) + ".csv");
    const CliResult r = run_quadgen({"simulate", tmp / "off_centre.yaml", "--scenario", scenario, "--duration", "2", "--out", out},
                                    tmp.dir);
    EXPECT_EQ(r.rc, 0) << scenario << ": " << r.err;
    const quadgen::runtime::CsvTable t = quadgen::runtime::read_csv(out);
    std::map<std::string, double> last;
    for (const char* c : {"x", "y", "phi", "theta", "psi"}) last[c] = t.rows.back()[t.column(c)];
    return last;
  };
  auto yaw = end_of("yaw");
  EXPECT_LT(yaw["psi"], -0.2);
  EXPECT_LT(std::hypot(yaw["phi"], yaw["theta"]), 0.15 * std::fabs(yaw["psi"])) << yaw["phi"] << " " << yaw["theta"];
  EXPECT_LT(std::hypot(yaw["x"], yaw["y"]), 0.1) << yaw["x"] << " " << yaw["y"];
  // Guards the axis each tilt means (a roll flag for `right` would take its pitch out), not
  // the fix: the raised rotors' own pitch dominates here.
  auto right = end_of("right");
  EXPECT_GT(right["x"], 0.2);
  EXPECT_LT(std::fabs(right["y"]), 0.05 * right["x"]);
  EXPECT_LT(std::fabs(right["psi"]), 0.01);
  // Where the rule's rotors balance about the other axes the thrusts keep their bits: on the
  // FINken 3 during `yaw`, B and D stay at the hover command exactly. hexa_plus's `right` raises
  // two ccw and one cw rotor: the yaw that adds is taken out.
  const fs::path yaw_csv = tmp / "f3_yaw.csv";
  ASSERT_EQ(run_quadgen({"simulate", source_path("vehicles/finken3.yaml"), "--scenario", "yaw", "--duration", "2", "--out",
                         yaw_csv},
                        tmp.dir)
                .rc,
            0);
  const quadgen::runtime::CsvTable f3 = quadgen::runtime::read_csv(yaw_csv);
  const double u_hover = f3.rows.front()[f3.column("u_B")];
  for (const auto& row : f3.rows) {
    EXPECT_EQ(row[f3.column("u_B")], u_hover);
    EXPECT_EQ(row[f3.column("u_D")], u_hover);
  }
  const fs::path hexa_csv = tmp / "hexa_right.csv";
  ASSERT_EQ(run_quadgen({"simulate", source_path("vehicles/hexa_plus.yaml"), "--scenario", "right", "--duration", "2",
                         "--out", hexa_csv},
                        tmp.dir)
                .rc,
            0);
  const quadgen::runtime::CsvTable hexa = quadgen::runtime::read_csv(hexa_csv);
  EXPECT_LT(std::fabs(hexa.rows.back()[hexa.column("psi")]), 1e-9);
  EXPECT_GT(hexa.rows.back()[hexa.column("x")], 0.05);
}

// Scenarios on other layouts: the tilt and yaw manoeuvres turn every vehicle the way they
// turn the FINken 3 (right towards +x, forward towards -y, yaw clockwise seen from above),
// a hexacopter included (it was refused them, when rotors took the thesis' A..D roles by
// their order), and a quad whose centre of gravity is off the middle hovers level on its
// trimmed thrusts.
TEST(Cli, ScenariosFollowTheVehiclesLayout) {
  Scratch tmp;
  const std::string finken = read(source_path("vehicles/finken3.yaml"));
  const size_t rotors_at = finken.find("\nrotors:");
  ASSERT_NE(rotors_at, std::string::npos);
  std::string hexa = finken.substr(0, rotors_at) + "\nrotors:\n";
  for (int i = 0; i < 6; ++i) {
    const double a = M_PI / 6 + i * M_PI / 3, r = 0.1056;
    char line[200];
    std::snprintf(line, sizeof line, "  - {name: R%d, position: [%.6f, %.6f, 0], spin: %s, radius: 0.0635, disc_area: 1.646e-3}\n",
                  i + 1, r * std::cos(a), r * std::sin(a), i % 2 ? "cw" : "ccw");
    hexa += line;
  }
  write(tmp.dir / "hexa.yaml", hexa);
  const std::vector<std::string> vehicles = {source_path("vehicles/finken3.yaml"), source_path("vehicles/crazyflie21.yaml"),
                                             tmp / "hexa.yaml", source_path("vehicles/hexa_plus.yaml")};
  for (const std::string& vehicle : vehicles) {
    const auto end_of = [&](const char* scenario) {
      const fs::path out = tmp / (std::string(scenario) + ".csv");
      const CliResult r = run_quadgen({"simulate", vehicle, "--scenario", scenario, "--duration", "2", "--out", out}, tmp.dir);
      EXPECT_EQ(r.rc, 0) << vehicle << " " << scenario << ": " << r.err;
      const quadgen::runtime::CsvTable t = quadgen::runtime::read_csv(out);
      const auto at = [&](const char* c) { return t.rows.back()[t.column(c)]; };
      for (const char* f : {".csv", ".svg"}) fs::remove(tmp / (std::string(scenario) + f));
      return std::array<double, 3>{at("x"), at("y"), at("psi")};
    };
    const auto right = end_of("right"), forward = end_of("forward"), yaw = end_of("yaw");
    EXPECT_GT(right[0], 0.05) << vehicle;
    EXPECT_LT(std::fabs(right[1]), 0.01 * right[0]) << vehicle;
    EXPECT_LT(forward[1], -0.05) << vehicle;
    EXPECT_LT(std::fabs(forward[0]), 0.01 * std::fabs(forward[1])) << vehicle;
    EXPECT_LT(yaw[2], -0.02) << vehicle;
    EXPECT_LT(std::hypot(yaw[0], yaw[1]), 1e-3) << vehicle;
  }
  fs::remove(tmp / ".quadgen-files");

  std::string off_centre = finken;  // the upper body 2 cm towards +x: the CoG 5.1 mm off the middle
  const std::string upper = "centre: [0, 0, 0.036]";
  ASSERT_NE(off_centre.find(upper), std::string::npos);
  off_centre.replace(off_centre.find(upper), upper.size(), "centre: [0.02, 0, 0.036]");
  write(tmp.dir / "off_centre.yaml", off_centre);
  // Every rotor alike, about its own trim: level and in place (hover) or straight up.
  for (const char* file : {"hexa.yaml", "off_centre.yaml"})
    for (const char* scenario : {"hover", "climb", "new_height"}) {
      const std::string out = tmp / (std::string(file) + "_" + scenario + ".csv");
      const CliResult r = run_quadgen({"simulate", tmp / file, "--scenario", scenario, "--duration", "3", "--out", out}, tmp.dir);
      ASSERT_EQ(r.rc, 0) << file << " " << scenario << ": " << r.err;
      const quadgen::runtime::CsvTable t = quadgen::runtime::read_csv(out);
      const auto& last = t.rows.back();
      for (const char* c : {"x", "y", "qx", "qy"}) EXPECT_NEAR(last[t.column(c)], 0.0, 1e-6) << file << " " << scenario << " " << c;
      if (std::string(scenario) == "hover") EXPECT_NEAR(last[t.column("z")], 0.0, 1e-6) << file;
      else EXPECT_GT(last[t.column("z")], 0.1) << file << " " << scenario;
    }
}

// A library call checks its inputs as the command line does (a review, helper-138: the ground's
// limit and the fit's lists were the command line's alone): a ground 1e9 m away is refused by
// run_simulate_job before any work, and every option's list of names is split by one rule.
// A fit as a library call refuses what the log's kind does not read, as the command line
// refuses the flag: effects on motor steps were dropped silently (a review, helper-142).
TEST(LibraryCalls, AFitRefusesWhatItsLogsKindDoesNotRead) {
  const quadgen::Vehicle f3 = quadgen::load_vehicle(source_path("vehicles/finken3.yaml"));
  const std::string steps = source_path("data/finken3_motor_steps.csv");
  const auto kind = quadgen::fit::log_kind(steps);
  ASSERT_EQ(kind, quadgen::fit::LogKind::kMotorSteps);
  const auto refused = [&](const quadgen::app::FitJob& job, const std::string& expected) {
    try {
      quadgen::app::run_fit_job(job, f3, kind);
      ADD_FAILURE() << expected << ": fitted";
    } catch (const std::invalid_argument& e) {
      EXPECT_EQ(std::string(e.what()).rfind("fit: " + expected + ": not used when fitting a motor-step log", 0), 0u)
          << e.what();
    }
  };
  refused({steps, "motor_lag", {}}, "effects");
  quadgen::fit::FitJobOptions mapped;
  mapped.mapping = source_path("data/mappings/nanobench.yaml");
  refused({steps, "", mapped}, "mapping");
  EXPECT_THROW(quadgen::fit::why_unused("windows", quadgen::fit::LogKind::kFlight, "equation_error"), std::logic_error);
}

// derive numbers its progress from the job's own count of steps, the writing last.
TEST(Cli, DeriveNumbersItsStepsFromTheJobsCount) {
  Scratch tmp;
  const CliResult r = run_quadgen({"derive", source_path("vehicles/finken3.yaml"), "--out", tmp / "o"}, tmp.dir);
  ASSERT_EQ(r.rc, 0) << out::printable(r.err);
  const auto occurrences = [](const std::string& text, const std::string& part) {
    int n = 0;
    for (size_t at = text.find(part); at != std::string::npos; at = text.find(part, at + 1)) ++n;
    return n;
  };
  const int steps = quadgen::app::kDeriveJobSteps + 1;
  const std::string of = "/" + std::to_string(steps) + "] ";
  for (int k = 1; k <= steps; ++k)
    EXPECT_EQ(occurrences(r.err, "[" + std::to_string(k) + of), 1) << k << "\n" << out::printable(r.err);
  EXPECT_EQ(occurrences(r.err, "[" + std::to_string(steps + 1) + of), 0) << out::printable(r.err);
  EXPECT_NE(r.err.find("[" + std::to_string(steps) + of + "writing"), std::string::npos) << out::printable(r.err);
}

TEST(LibraryCalls, CheckTheirInputsAsTheCommandLineDoes) {
  quadgen::app::SimulateJob job;
  job.vehicle = source_path("vehicles/finken3.yaml");
  job.scenario = "hover";
  job.duration = 0.01;
  job.ground_height = 1e9;
  try {
    quadgen::app::run_simulate_job(job);
    ADD_FAILURE() << "a ground 1e9 m away was simulated";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("--ground 1e+09: expected a height within +-10000 m"), std::string::npos) << e.what();
  }
  // Every number of the job, checked by the job with the ranges --help shows (they were the
  // command line's alone: a caller's excitation of 50 rad/s was flown).
  std::string why;
  job.ground_height.reset();
  EXPECT_TRUE(job.IsValid(&why)) << why;
  job.flight.excitation = 6;
  EXPECT_FALSE(job.IsValid(&why));
  EXPECT_EQ(why, "--excitation: 0 to 5");
  EXPECT_THROW(quadgen::app::run_simulate_job(job), std::invalid_argument);
  job.flight.excitation = 0;
  job.rate = std::nan("");
  EXPECT_FALSE(job.IsValid(&why));
  EXPECT_EQ(why, "--rate: 0.001 to 1e+06 Hz");
  job.rate = 100;
  job.duration = 0;  // the job's default: a caller must say how long
  EXPECT_FALSE(job.IsValid(&why));
  EXPECT_EQ(why.rfind("--duration", 0), 0u) << why;
  using quadgen::output::split_name_list;
  EXPECT_EQ(split_name_list("", "--channels"), std::vector<std::string>{});
  EXPECT_EQ(split_name_list("ax,qdot", "--channels"), (std::vector<std::string>{"ax", "qdot"}));
  const auto refused = [](const std::string& text, const std::string& expected) {
    try {
      split_name_list(text, "--channels");
      ADD_FAILURE() << "'" << text << "' accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
    }
  };
  refused("ax,,qdot", "has an empty name");  // fit skipped it, derive refused it
  refused(",ax", "has an empty name");
  refused("ax,", "has an empty name");
  refused("ax,qdot,ax", "--channels: 'ax' is given twice");
  refused("a\x1b[2J,a\x1b[2J", "'a\\x1B[2J' is given twice");  // quoted printable
}
