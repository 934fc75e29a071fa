// quadgen compare: two derivations side by side (audit/derivation_comparison.hpp). The
// expectations come from the physics of the change, not from the comparison's own output: a
// rotor moved along body x changes the pitch torque and nothing about the kinematics; an
// expression rewritten is the same function; one changed by a part in 1e7 is not.
#include <filesystem>
#include <cstdio>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "audit/derivation_comparison.hpp"
#include "derive/dynamics.hpp"
#include "derive/effects/effect_catalogue.hpp"
#include "tests/test_helpers.hpp"

namespace {

using quadgen::test::source_path;

std::string finken3_text() {
  std::ifstream in(source_path("vehicles/finken3.yaml"));
  return std::string(std::istreambuf_iterator<char>(in), {});
}

std::string replaced(std::string s, const std::string& from, const std::string& to) {
  const auto at = s.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return at == std::string::npos ? s : s.replace(at, from.size(), to);
}

struct Side {
  quadgen::Vehicle vehicle;
  quadgen::SymbolicModel model;
};

Side derive(const std::string& text, const std::string& effects = "") {
  Side s{quadgen::parse_vehicle(text, "vehicles/x.yaml"), {}};
  quadgen::DeriveOptions opt;
  opt.effects = quadgen::parse_effect_list(effects);
  s.model = quadgen::derive_model(s.vehicle, quadgen::derive_mass_properties(s.vehicle), opt);
  return s;
}

quadgen::DerivationComparison compare(const Side& a, const Side& b) {
  return quadgen::compare_derivations({a.vehicle, a.model}, {b.vehicle, b.model});
}

const quadgen::EquationComparison& equation(const quadgen::DerivationComparison& c, const std::string& name) {
  for (const auto& e : c.equations)
    if (e.name == name) return e;
  throw std::out_of_range("no equation " + name);
}

TEST(DerivationComparison, AFileIsTheSameAsItself) {
  const Side a = derive(finken3_text()), b = derive(finken3_text());
  const auto c = compare(a, b);
  EXPECT_TRUE(c.same()) << quadgen::comparison_text(c, "a", "b");
  // f (13 states), h (7 outputs), the four thrusts and the three-vectors drag, F_body, tau.
  EXPECT_EQ(c.equations.size(), 13u + 7u + 4u + 9u);
  EXPECT_NE(quadgen::comparison_text(c, "a", "b").find("the two derivations are the same"), std::string::npos);
}

// Rotor A moved along body x only, its thrust along body z: r x F = (y F, -x F, 0), so the
// pitch torque changes, the roll torque and the yaw (drag) torque do not, nor any thrust or
// kinematic row; the angular accelerations all change (the inertia couples them through the
// gyroscopic terms and the off-diagonal entries), and so do the translation rows, which
// carry the origin's transport acceleration (dω/dt × r_cog).
TEST(DerivationComparison, ARotorMovedAlongXChangesThePitchTorqueOnly) {
  const std::string from = "{name: A, position: [-0.07465, -0.07465, 0]";
  const Side a = derive(finken3_text()), b = derive(replaced(finken3_text(), from, "{name: A, position: [-0.08, -0.07465, 0]"));
  const auto c = compare(a, b);
  EXPECT_FALSE(c.same());
  ASSERT_EQ(c.rotors_changed.size(), 1u);
  EXPECT_EQ(c.rotors_changed[0], "A: position x -0.07465 -> -0.08 m");
  ASSERT_EQ(c.constants.size(), 1u);
  EXPECT_EQ(c.constants[0].name, "A.x");
  EXPECT_TRUE(c.parameter_values.empty()) << "no block moved: the mass properties are the same";
  EXPECT_FALSE(equation(c, "tau[1]").same);
  EXPECT_TRUE(equation(c, "tau[0]").same);
  EXPECT_TRUE(equation(c, "tau[2]").same);
  for (const char* same : {"F_A", "F_body[2]", "dx/dt", "dqw/dt", "x", "qw"}) EXPECT_TRUE(equation(c, same).same) << same;
  EXPECT_FALSE(equation(c, "dq/dt").same);
  for (const auto& e : c.equations) EXPECT_TRUE(e.only_in_a.empty() && e.only_in_b.empty()) << e.name;
  const std::string text = quadgen::comparison_text(c, "a", "b");
  EXPECT_NE(text.find("differs: tau[1] (intermediate)"), std::string::npos) << text;
  EXPECT_NE(text.find("the same symbols, other numbers"), std::string::npos) << text;
}

// A value alone: every equation is the same function; what differs is the value.
TEST(DerivationComparison, AParameterValueLeavesTheEquationsTheSame) {
  const Side a = derive(finken3_text()),
             b = derive(replaced(finken3_text(), "c_t: {value: 0.14175,", "c_t: {value: 0.15,"));
  const auto c = compare(a, b);
  EXPECT_FALSE(c.same());
  ASSERT_EQ(c.parameter_values.size(), 1u);
  EXPECT_EQ(c.parameter_values[0].name, "c_t");
  EXPECT_EQ(c.parameter_values[0].b, 0.15);
  for (const auto& e : c.equations) EXPECT_TRUE(e.same) << e.name;
  // A block's mass: the mass properties derived from the blocks differ, said as values.
  const Side d = derive(replaced(finken3_text(), "{name: motor_A, mass: 0.02,", "{name: motor_A, mass: 0.025,"));
  const auto m = compare(a, d);
  ASSERT_EQ(m.blocks_changed.size(), 1u);
  EXPECT_EQ(m.blocks_changed[0], "motor_A: mass 0.02 -> 0.025 kg");
  std::vector<std::string> names;
  for (const auto& v : m.parameter_values) names.push_back(v.name);
  for (const char* derived : {"mass", "cog_x", "cog_y", "J_xx", "J_zz"})
    EXPECT_NE(std::find(names.begin(), names.end(), derived), names.end()) << derived;
  EXPECT_NEAR(m.parameter_values[0].b - m.parameter_values[0].a, 0.005, 1e-15);  // the mass first, up by the block's
  EXPECT_TRUE(m.parameter_settings.empty()) << "held quantities' bounds are their values, said once";
}

TEST(DerivationComparison, AnEffectAddsItsParametersToTheRowsItChanges) {
  const Side a = derive(finken3_text()), b = derive(finken3_text(), "rotor_drag");
  const auto c = compare(a, b);
  EXPECT_EQ(c.effects_only_b, std::vector<std::string>{"rotor_drag"});
  EXPECT_EQ(c.parameters_only_b, std::vector<std::string>{"rotor_drag.k"});
  const auto& vx = equation(c, "dvx/dt");
  EXPECT_FALSE(vx.same);
  EXPECT_EQ(vx.only_in_b, std::vector<std::string>{"rotor_drag.k"});
  EXPECT_TRUE(equation(c, "dqw/dt").same);
}

// The test is of functions, not of text: f's first velocity row expanded is the same
// function; changed by a part in 1e7 it is not.
TEST(DerivationComparison, FunctionsNotTextAreCompared) {
  const Side a = derive(finken3_text());
  Side b = derive(finken3_text());
  const size_t vx = b.model.state_index("vx");
  b.model.f(vx, 0) = b.model.f(vx, 0).expand();
  ASSERT_NE(b.model.f(vx, 0), a.model.f(vx, 0)) << "expanding changed nothing: the test tests nothing";
  EXPECT_TRUE(compare(a, b).same());
  b.model.f(vx, 0) = b.model.f(vx, 0) * GiNaC::numeric(10000001, 10000000);
  const auto c = compare(a, b);
  EXPECT_FALSE(equation(c, "dvx/dt").same);
  EXPECT_NEAR(equation(c, "dvx/dt").largest_relative_difference, 1e-7, 1e-9);
  // A side that is no number at a point is counted as not compared, not thrown: the rest of
  // the comparison stands. Here a pole (x^2 - |x|^2 is 0 at every real point, which GiNaC
  // cannot see while x may be complex, and throws on at a point) and a symbol neither
  // model gives a value.
  Side p = derive(finken3_text());
  const GiNaC::ex x_state = p.model.states[p.model.state_index("x")].sym;
  p.model.f(vx, 0) = p.model.f(vx, 0) + 1 / (GiNaC::pow(x_state, 2) - GiNaC::pow(GiNaC::abs(x_state), 2));
  p.model.f(vx + 1, 0) = p.model.f(vx + 1, 0) + GiNaC::symbol("orphan");
  const auto poles = compare(a, p);
  EXPECT_EQ(equation(poles, "dvx/dt").points_not_compared, poles.points);
  EXPECT_EQ(equation(poles, "dvy/dt").points_not_compared, poles.points);
  EXPECT_FALSE(equation(poles, "dvx/dt").same);
  EXPECT_TRUE(equation(poles, "dvz/dt").same);
  EXPECT_EQ(static_cast<long>(GiNaC::Digits), 17) << "the working precision was not restored";
  // Evaluated exactly: a part in 1e15 is a difference too (a tolerance of 1e-9 hid a rotor
  // moved by 1e-8 m from the translation rows).
  Side d = derive(finken3_text());
  d.model.f(vx, 0) = d.model.f(vx, 0) * GiNaC::numeric(1000000000000001, 1000000000000000);
  EXPECT_FALSE(equation(compare(a, d), "dvx/dt").same);
}

// The generated arrays follow the order of the inputs: rotors listed in another order are a
// change, though every name and equation is the same.
TEST(DerivationComparison, RotorsInAnotherOrderAreAChange) {
  const std::string a_line = "  - {name: A, position: [-0.07465, -0.07465, 0], spin: ccw, radius: 0.0635, disc_area: 1.646e-3}\n";
  const std::string b_line = "  - {name: B, position: [0.07465, -0.07465, 0], spin: cw, radius: 0.0635, disc_area: 1.646e-3}\n";
  const Side a = derive(finken3_text()), b = derive(replaced(finken3_text(), a_line + b_line, b_line + a_line));
  const auto c = compare(a, b);
  EXPECT_FALSE(c.same());
  ASSERT_EQ(c.order_changes.size(), 1u) << quadgen::comparison_text(c, "a", "b");
  EXPECT_EQ(c.order_changes[0], "inputs: u_A, u_B, u_C, u_D -> u_B, u_A, u_C, u_D");
  for (const auto& e : c.equations) EXPECT_TRUE(e.same) << e.name;
}

// What one side alone has is said: a vehicle file's motor-map pivot (a constant of the
// Crazyflie's NanoBench file only), and another vehicle name (it goes into the generated code).
TEST(DerivationComparison, WhatOneSideAloneHasIsSaid) {
  std::ifstream in(source_path("vehicles/crazyflie21.yaml"));
  const std::string cf((std::istreambuf_iterator<char>(in)), {});
  std::ifstream in_nb(source_path("vehicles/crazyflie21_nanobench.yaml"));
  const std::string nb((std::istreambuf_iterator<char>(in_nb)), {});
  const auto c = compare(derive(cf), derive(nb));
  const std::string text = quadgen::comparison_text(c, "a", "b");
  EXPECT_EQ(c.constants_only_b, std::vector<std::string>{"motor_pivot"}) << text;
  EXPECT_EQ(c.parameters_only_b, std::vector<std::string>{"motor_slope"}) << text;
  EXPECT_NE(text.find("constants only in B: motor_pivot"), std::string::npos) << text;
  const auto renamed = compare(derive(finken3_text()), derive(replaced(finken3_text(), "name: finken3", "name: finken3b")));
  EXPECT_FALSE(renamed.same());
  EXPECT_NE(quadgen::comparison_text(renamed, "a", "b").find("vehicle name (in the generated code): finken3 -> finken3b"),
            std::string::npos);
}

// Names from the files reach the terminal: what they hold is shown, never executed.
TEST(DerivationComparison, NamesFromTheFilesArePrintedHarmlessly) {
  quadgen::DerivationComparison c;
  c.blocks_only_a = {"arm\x1b]0;owned\x07\nIn short: the two derivations are the same."};
  c.parameter_values = {{"c_t\r", "1\x1b[2J", 1, 2}};
  const std::string text = quadgen::comparison_text(c, "a\x1b[31m.yaml", "b.yaml");
  EXPECT_EQ(text.find('\x1b'), std::string::npos) << text;
  EXPECT_EQ(text.find('\r'), std::string::npos) << text;
  EXPECT_EQ(text.find('\x07'), std::string::npos) << text;
  EXPECT_EQ(text.find("\nIn short: the two derivations are the same."), std::string::npos) << text;
}

int run(const std::string& args, std::string* out) {
  FILE* p = ::popen((std::string(QUADGEN_BINARY) + " compare " + args + " 2>&1").c_str(), "r");
  char buf[4096];
  size_t n;
  while ((n = fread(buf, 1, sizeof buf, p)) > 0) out->append(buf, n);
  const int status = ::pclose(p);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST(DerivationComparison, TheCommandSaysSameDifferentOrWrongByItsExitCodeWhenAsked) {
  const std::string f3 = "'" + source_path("vehicles/finken3.yaml") + "'";
  std::string out;
  EXPECT_EQ(run(f3 + " " + f3 + " --exit-code", &out), 0) << out;
  const std::string dir = ::testing::TempDir();
  const std::string moved = dir + "/quadgen_compare_moved.yaml", broken = dir + "/quadgen_compare_broken.yaml";
  std::ofstream(moved) << replaced(finken3_text(), "c_t: {value: 0.14175,", "c_t: {value: 0.15,");
  out.clear();
  EXPECT_EQ(run(f3 + " '" + moved + "' --exit-code", &out), 1) << out;
  EXPECT_NE(out.find("parameter values (A -> B): c_t 0.14175 -> 0.15 (+5.82 %)"), std::string::npos) << out;
  out.clear();
  EXPECT_EQ(run(f3 + " '" + moved + "'", &out), 0) << "a comparison done is a success: " << out;
  std::ofstream(broken) << replaced(finken3_text(), "c_t: {value: 0.14175,", "c_t: {value: fast,");
  out.clear();
  EXPECT_EQ(run(f3 + " '" + broken + "'", &out), 2) << out;
  EXPECT_NE(out.find("quadgen_compare_broken.yaml:29"), std::string::npos) << out;
  // A comparison that could not be written is an error, not a success (it exited 0 on a full
  // disk: helper-161); its error goes to the same full device here, so only the code tells.
  if (std::filesystem::exists("/dev/full")) {
    out.clear();
    EXPECT_EQ(run(f3 + " " + f3 + " > /dev/full", &out), 2) << out;
  }
}

// A file with a `fitted:` section (as diagnose writes fitted_vehicle.yaml) is derived as derive
// would: its effects and its values. --effects beside it is refused with what to do instead.
TEST(DerivationComparison, AFittedSectionIsDerivedAsDeriveWould) {
  const std::string f3 = "'" + source_path("vehicles/finken3.yaml") + "'";
  const std::string fitted = ::testing::TempDir() + "/quadgen_compare_fitted.yaml";
  std::ofstream(fitted) << finken3_text()
                        << "\nfitted:\n  vehicle: finken3\n  effects: [rotor_drag]\n  parameters:\n"
                           "    c_t: {value: 0.15, unit: \"1\"}\n    rotor_drag.k: {value: 2.0e-5, unit: \"N s^2/m\"}\n";
  std::string out;
  EXPECT_EQ(run(f3 + " '" + fitted + "'", &out), 0) << out;
  EXPECT_NE(out.find("effects only in B: rotor_drag"), std::string::npos) << out;
  EXPECT_NE(out.find("c_t 0.14175 -> 0.15"), std::string::npos) << out;
  EXPECT_NE(out.find("rotor_drag.k"), std::string::npos) << out;
  out.clear();
  EXPECT_EQ(run(f3 + " '" + fitted + "' --effects wind", &out), 2) << out;
  EXPECT_NE(out.find("compare derives both files with --effects"), std::string::npos) << out;
}

}  // namespace
