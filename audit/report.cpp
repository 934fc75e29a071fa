#include "audit/report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>

#include <nlohmann/json.hpp>

#include "audit/tex_writer.hpp"
#include "derive/runtime_view.hpp"
#include "runtime/allocation_matrix.hpp"
#include "derive/effects/effect_catalogue.hpp"
#include "output/joined.hpp"
#include "output/json_document.hpp"
#include "output/numbers.hpp"
#include "output/sinks.hpp"

namespace quadgen {
using namespace GiNaC;

namespace {

// Nodes of an expression tree, counted up to `limit` (then limit + 1).
size_t tree_size(const ex& e, size_t limit) {
  size_t n = 1;
  for (size_t i = 0; i < e.nops() && n <= limit; ++i) n += tree_size(e.op(i), limit - n);
  return n;
}

void section_vehicle(std::ostringstream& md, const Derivation& d) {
  md << "## 1. Vehicle\n\n" << output::markdown_text(d.vehicle.description) << "\n\n";
  md << "| block | mass [kg] | size a × b × c [m] | centre [m] | yaw, pitch, roll [deg] |\n|---|---|---|---|---|\n";
  for (const Block& b : d.vehicle.blocks)
    md << "| " << output::markdown_text(b.name) << " | " << output::six_digits(b.mass) << " | " << output::six_digits(b.size[0]) << " × " << output::six_digits(b.size[1]) << " × "
       << output::six_digits(b.size[2]) << " | (" << output::six_digits(b.centre[0]) << ", " << output::six_digits(b.centre[1]) << ", " << output::six_digits(b.centre[2])
       << ") | " << output::six_digits(b.yaw_pitch_roll_deg[0]) << ", " << output::six_digits(b.yaw_pitch_roll_deg[1]) << ", "
       << output::six_digits(b.yaw_pitch_roll_deg[2]) << " |\n";
  md << "\n| rotor | position [m] | spin (from above) | r_p [m] | A_p [m²] |\n|---|---|---|---|---|\n";
  for (const Rotor& r : d.vehicle.rotors)
    md << "| " << output::markdown_text(r.name) << " | (" << output::six_digits(r.position[0]) << ", " << output::six_digits(r.position[1]) << ", "
       << output::six_digits(r.position[2]) << ") | " << (r.spin == Spin::ccw ? "ccw" : "cw") << " | " << output::six_digits(r.radius)
       << " | " << output::six_digits(r.disc_area) << " |\n";
  md << "\n";
}

// Values the vehicle file's `derived:` section gives (measured) in place of the blocks': the
// model uses them, as they are (a given tensor is not moved to a given centre of gravity),
// unless fitted values (--params, a `fitted:` section) replace them in turn: then said.
void given_values(std::ostringstream& md, const Derivation& d) {
  if (d.vehicle.derived_given.empty()) return;
  md << "The vehicle file's `derived:` section gives measured values in place of the blocks', and the model "
        "uses these (as given: a tensor is not moved to another centre of gravity; J_xy, J_xz, J_yz are tensor "
        "entries, minus the products of inertia):";
  const char* separator = " ";
  for (const DerivedQuantity& q : kDerivedQuantities)
    if (d.vehicle.derived_given.count(q.name)) {
      const double given = d.vehicle.derived_overrides.at(q.name).nominal;
      const double used = d.model.params[d.model.param_index(q.name)].nominal;
      md << separator << "`" << q.name << "` = " << output::six_digits(given) << " " << output::unit_for_reading(q.unit);
      if (!output::equal_but_for_rounding(used, given))
        md << " (replaced by the fitted " << output::six_digits(used) << " " << output::unit_for_reading(q.unit) << ")";
      separator = "; ";
    }
  md << ".\n\n";
}

// What one newton of each rotor does about the centre of gravity the model uses: the
// allocation the closed loop and the hover trim solve with, printed so that a reader checks
// arms, spins and signs by eye (a referee asked for it: only its rank was printed, helper-151).
void allocation_table(std::ostringstream& md, const Derivation& d) {
  const Eigen::MatrixXd B = runtime::allocation_matrix(nominal_controller_belief(d.vehicle, d.model));
  md << "What one newton of each rotor's thrust does about that centre of gravity (the allocation the closed loop "
        "and the hover trim solve with; section 7 checks its rank): roll and pitch moments are the rotor's arms, "
        "the yaw moment its reaction, -kappa per newton for a counter-clockwise rotor (it turns the body "
        "clockwise), +kappa for a clockwise one:\n\n| per newton of | "
     << output::joined(d.vehicle.rotors, " | ", [](const Rotor& r) { return output::markdown_text(r.name); }) << " |\n|---|";
  for (Eigen::Index i = 0; i < B.cols(); ++i) md << "---|";
  const char* rows[4] = {"thrust [N]", "roll moment [N m]", "pitch moment [N m]", "yaw moment [N m]"};
  for (Eigen::Index r = 0; r < 4; ++r) {
    md << "\n| " << rows[r] << " |";
    for (Eigen::Index i = 0; i < B.cols(); ++i) md << " " << output::six_digits(B(r, i)) << " |";
  }
  md << "\n\n";
}

void section_mass(std::ostringstream& md, const Derivation& d, TexWriter& tex) {
  const MassProperties& mp = d.mass;
  md << "## 2. Mass properties by exact integration\n\n"
     << "Each block is a cuboid of constant density $\\rho_i = m_i/(a_i b_i c_i)$. In its own frame GiNaC "
        "integrates the second moment $S = \\int \\xi \\xi^T \\mathrm{d}m$ exactly over "
        "$[-a/2,a/2]\\times[-b/2,b/2]\\times[-c/2,c/2]$";
  if (!mp.blocks.empty()) {
    md << "; for block " << output::markdown_code(mp.blocks[0].name) << ":\n\n```math\nS = " << tex.matrix(mp.blocks[0].local_second_moment)
       << "\n```\n\n";
  }
  md << "It is rotated by the block's orientation, $R = R_z(\\mathrm{yaw}) R_y(\\mathrm{pitch}) R_x(\\mathrm{roll})$ "
        "(Z-Y-X, as the vehicle file's `orientation_deg: [yaw, pitch, roll]`), and moved to its centre $c$ in the "
        "body frame, $S_b = R S R^T + m c c^T$; the inertia tensor about the origin is "
        "$J_o = \\operatorname{tr}(S_b) I - S_b$.";
  if (!mp.blocks.empty())
    md << " For " << output::markdown_code(mp.blocks[0].name) << ":\n\n```math\nJ_o = " << tex.matrix(mp.blocks[0].inertia_origin) << "\n```\n\n";
  md << "Contributions of every block about the body origin [kg m²] and projected areas [m²]:\n\n"
     << "| block | J_xx | J_yy | J_zz | J_xy | J_xz | J_yz | A_x | A_y | A_z |\n|---|---|---|---|---|---|---|---|---|---|\n";
  for (const auto& b : mp.blocks) {
    const auto& J = b.inertia_origin_value;
    md << "| " << output::markdown_text(b.name) << " | " << output::six_digits(J[0][0]) << " | " << output::six_digits(J[1][1]) << " | " << output::six_digits(J[2][2]) << " | "
       << output::six_digits(J[0][1]) << " | " << output::six_digits(J[0][2]) << " | " << output::six_digits(J[1][2]) << " | " << output::six_digits(b.areas_value[0])
       << " | " << output::six_digits(b.areas_value[1]) << " | " << output::six_digits(b.areas_value[2]) << " |\n";
  }
  const auto& Jc = mp.inertia_cog_value;
  // $`...`$: GitHub's Markdown would read the TeX's "\_" in $...$ as an escaped "_" (a subscript).
  md << "\nTotals: $`m = " << tex.tex(mp.mass) << "`$ = **" << output::six_digits(mp.mass_value) << " kg**; centre of gravity "
     << "$c = \\frac{1}{m}\\sum m_i c_i$ = **(" << output::six_digits(mp.cog_value[0]) << ", " << output::six_digits(mp.cog_value[1]) << ", "
     << output::six_digits(mp.cog_value[2]) << ") m**; exposed areas **(" << output::six_digits(mp.areas_value[0]) << ", "
     << output::six_digits(mp.areas_value[1]) << ", " << output::six_digits(mp.areas_value[2]) << ") m²**.\n\n"
     << "Inertia about the centre of gravity, $J_{cg} = J_o - m(|c|^2 I - c c^T)$ [kg m²]:\n\n"
     << "```math\nJ_{cg} = \\begin{pmatrix}" << output::six_digits(Jc[0][0]) << " & " << output::six_digits(Jc[0][1]) << " & " << output::six_digits(Jc[0][2])
     << " \\\\ " << output::six_digits(Jc[1][0]) << " & " << output::six_digits(Jc[1][1]) << " & " << output::six_digits(Jc[1][2]) << " \\\\ "
     << output::six_digits(Jc[2][0]) << " & " << output::six_digits(Jc[2][1]) << " & " << output::six_digits(Jc[2][2]) << "\\end{pmatrix}\n```\n\n"
     << "These stay expressions in the block symbols ($m_i, a_i, b_i, c_i, x_i, y_i, z_i$): a changed "
        "vehicle file re-derives them. They enter the dynamics as parameters `mass`, `cog_*`, `J_*`, `A_*` "
        "with these nominal values, so that a fit may free them.\n\n";
  given_values(md, d);
  allocation_table(md, d);
}

// An equation a reader can follow: up to this many nodes it is written out, beyond it named.
constexpr size_t kReadable = 1500;
// MathJax (GitHub's renderer too) takes at most 5 KB of TeX in one formula and shows a longer
// one as raw text: a vector beyond that is written one component per formula, a component
// beyond it is named only (scripts/render_derivation.sh checks the result in a browser).
constexpr size_t kMathJaxLimit = 4800;  // characters, with room for the left-hand side

void write_equation(std::ostringstream& md, const std::string& lhs, const std::string& rhs) {
  if (rhs.size() > kMathJaxLimit)
    md << "$" << lhs << "$: " << rhs.size() << " characters of TeX, more than MathJax renders in one formula; the "
       << "generated code holds it in full.\n\n";
  else
    md << "```math\n" << lhs << " = " << rhs << "\n```\n\n";
}

void section_kinematics(std::ostringstream& md) {
  md << "## 3. Kinematics\n\n"
     << "Attitude is the unit quaternion $q = (q_w, q_x, q_y, q_z)$, body → world (Hamilton); the state "
        "named `q` in section 6 is not it but the body rate about y, $\\omega = (p, q, r)$. Its rotation "
        "matrix and rate:\n\n"
     << "```math\nR(q) = \\begin{pmatrix} 1-2(q_y^2+q_z^2) & 2(q_xq_y-q_wq_z) & 2(q_xq_z+q_wq_y) \\\\ "
        "2(q_xq_y+q_wq_z) & 1-2(q_x^2+q_z^2) & 2(q_yq_z-q_wq_x) \\\\ 2(q_xq_z-q_wq_y) & 2(q_yq_z+q_wq_x) & "
        "1-2(q_x^2+q_y^2)\\end{pmatrix},\\qquad \\dot q = \\tfrac12\\, q \\otimes (0, \\omega)\n```\n\n"
     << "For reports, Z-Y-X Euler angles give $R = R_z(\\psi) R_y(\\theta) R_x(\\phi)$; the audit shows both "
        "forms agree.\n\n";
}

// Section 4: the named quantities (air velocity, rotor speeds and thrusts, moments, drag),
// each written with the ones before it as symbols.
void section_forces_and_torques(std::ostringstream& md, const SymbolicModel& m, TexWriter& tex) {
  md << "## 4. Forces and torques\n\n";
  md << "The air velocity in body axes $v_a = R^T (v - v_{wind})$ ($v_{wind}$ the wind effect's, zero without it); each rotor's speed $\\omega_i$ and thrust "
        "$F_i$ (along body $+z$ at its hub); the moment $\\tau_i$ of that thrust about the centre of gravity with "
        "the reaction moment of the spin (a counter-clockwise rotor, seen from above, turns the body with "
        "$-\\kappa F_i$ about $z$, a clockwise one with $+\\kappa F_i$); and the frame's drag on $v_a$, acting at "
        "the centre of gravity. Each quantity is written with the ones before it as symbols (an effect's factor "
        "of a thrust is written out); the generated code holds them substituted.\n\n";
  bool effect_terms = false;
  for (const auto& eq : m.named_equations) {
    if (!eq.rhs_tex.empty()) {
      effect_terms = effect_terms || eq.rhs_tex.find("\\Delta") != std::string::npos;
      md << "```math\n" << eq.lhs << " = " << eq.rhs_tex << "\n```\n\n";
      continue;
    }
    const ex& e = eq.rhs;
    if (tree_size(e, kReadable) > kReadable) {
      md << "$" << eq.lhs << "$: more than " << kReadable << " terms and factors, too long to read here; the generated "
         << "code holds it in full.\n\n";
      continue;
    }
    if (!is_a<matrix>(e)) {
      write_equation(md, eq.lhs, tex.tex(e));
      continue;
    }
    const matrix& v = ex_to<matrix>(e);
    const std::string whole = tex.matrix(v);
    if (whole.size() <= kMathJaxLimit || v.cols() != 1 || v.rows() != 3) {
      write_equation(md, eq.lhs, whole);
      continue;
    }
    for (unsigned i = 0; i < 3; ++i) write_equation(md, "\\left(" + eq.lhs + "\\right)_" + "xyz"[i], tex.tex(v(i, 0)));
  }
  if (effect_terms)
    md << "$\\Delta F_{body}$ and $\\Delta \\tau$ are the sums of what the effects add below.\n\n";
}

// What each effect adds, applied alone to the base model.
void section_effect_terms(std::ostringstream& md, const SymbolicModel& m, TexWriter& tex) {
  if (m.effect_formulas.empty()) return;
  md << "### What each effect adds\n\nEach effect applied alone to the base model, in body axes ($R = I$; "
        "$v_a$ is the air velocity, in body axes unless said), with the quantity it changes: a rotor's thrust is "
        "$s c_t \\rho A_p r_p^2 \\omega(\\omega - \\omega_{\\mathrm{loss}})$, $\\Delta c$ moves the centre of "
        "gravity, $\\Delta F_{body}$ and $\\Delta\\tau$ add to the body force and the moment about the centre of "
        "gravity.\n\n";
  for (const auto& f : m.effect_formulas) {
    md << "**" << output::markdown_text(f.effect) << "**" << (f.note.empty() ? "" : " (" + output::markdown_text(f.note) + ")")
       << (f.lines.empty() ? "\n\n" : ":\n\n");
    for (const auto& [lhs, value] : f.lines)
      write_equation(md, lhs, is_a<matrix>(value) ? tex.matrix(ex_to<matrix>(value)) : tex.tex(value));
  }
}

void section_equations_of_motion(std::ostringstream& md, const SymbolicModel& m, TexWriter& tex) {
  md << "## 5. Equations of motion\n\n"
     << "Translation (D'Alembert: the inertial force balances the applied forces) for the centre of "
        "gravity, expressed for the body origin that the logs record:\n\n"
     << "```math\n\\dot v = R\\left(\\frac{F_{body}}{m} - \\dot\\omega\\times c - \\omega\\times(\\omega\\times c)\\right) - "
        "g\\,e_z\n```\n\n"
     << "Rotation (angular-momentum balance about the centre of gravity, body axes):\n\n"
     << "```math\nJ\\dot\\omega = \\tau - \\omega \\times J\\omega\n```\n\n"
     << "For a diagonal J (principal axes along the body axes) its rows are Euler's equations, which section 7 "
        "checks the model's rows against:\n\n"
     << "```math\n\\dot p = \\frac{\\tau_x + (J_{yy} - J_{zz})\\,q\\,r}{J_{xx}},\\quad "
        "\\dot q = \\frac{\\tau_y + (J_{zz} - J_{xx})\\,r\\,p}{J_{yy}},\\quad "
        "\\dot r = \\frac{\\tau_z + (J_{xx} - J_{yy})\\,p\\,q}{J_{zz}}\n```\n\n"
     << "Not modelled: the rotors' own angular momentum. A spinning rotor adds a gyroscopic moment "
        "J_r Ω_i (ω × e_z) as the body turns and a reaction moment J_r dΩ_i/dt as it speeds up; the rotors "
        "here are massless discs whose only moments are their thrust's arm and κF_i (both small on a "
        "vehicle whose rotors cancel in pairs, and absorbed by a fitted κ where they are not).\n\n"
     << "Right-hand side rows short enough to read (the others are these vector equations written out; "
        "the generated code holds them in full):\n\n";
  for (size_t i = 0; i < m.states.size(); ++i) {
    if (tree_size(m.f(i, 0), 400) > 400) continue;  // far beyond a readable row
    const std::string t = tex.tex(m.f(i, 0));
    if (t.size() < 600) md << "```math\n\\dot{" << tex.tex(m.states[i].sym) << "} = " << t << "\n```\n\n";
  }
  md << "Measured outputs: position and the logged attitude quaternion";
  for (const std::string& e : m.effects)  // what acts on them, as its formula below shows
    if (find_effect(e).acts_on == Effect::ActsOn::kMeasurement) md << "; " << output::markdown_code(e) << " acts on them";
  md << ".\n\n";
}

void section_equations(std::ostringstream& md, const Derivation& d, TexWriter& tex) {
  section_kinematics(md);
  section_forces_and_torques(md, d.model, tex);
  section_effect_terms(md, d.model, tex);
  section_equations_of_motion(md, d.model, tex);
}

void variable_table(std::ostringstream& md, const std::string& title, const std::vector<Variable>& vars, bool params) {
  md << "### " << title << "\n\n";
  if (params) md << "| # | name | unit | nominal | bounds | fit | meaning |\n|---|---|---|---|---|---|---|\n";
  else md << "| # | name | unit | meaning |\n|---|---|---|---|\n";
  for (size_t i = 0; i < vars.size(); ++i) {
    const auto& v = vars[i];
    md << "| " << i << " | " << output::markdown_code(v.name) << " | " << output::markdown_text(output::unit_for_reading(v.unit)) << " | ";
    if (params)
      md << output::six_digits(v.nominal) << " | " << (v.lower == v.upper ? std::string("-") : "[" + output::six_digits(v.lower) + ", " + output::six_digits(v.upper) + "]")
         << " | " << (v.fit ? "yes" : "no") << " | ";
    md << output::markdown_text(v.doc)
       << (v.as_written.empty() ? "" : " (the vehicle file: " + output::markdown_text(v.as_written) + ")") << " |\n";
  }
  md << "\n";
}

void section_audit(std::ostringstream& md, const Derivation& d) {
  const size_t warnings = d.audit.warnings().size();
  md << "## 7. Audit\n\n**" << (d.audit.all_passed() ? "All checks of the derivation passed." : "SOME CHECKS FAILED.") << "**";
  if (warnings)
    md << " **" << warnings << " warning" << (warnings > 1 ? "s" : "")
       << " about the vehicle** (group `vehicle`: the derivation holds, but the vehicle as described cannot fly, "
          "or is most likely described wrongly)";
  // What the units checks cannot see (a reviewer's trial, helper-103).
  md << "\n\nThe units checks count an angle as dimensionless (rad = 1, as SI does): they cannot tell degrees "
        "from radians or rev/s from rad/s. Such a slip shows only in numbers against a reference"
     << (d.thesis.empty() ? "" : " (section 8 finds one in the thesis so, rad/s² printed as deg/s², and likely a second, rotor speeds in rev/s where rad/s were meant)") << ".";
  md << "\n\n| group | check | result | how |\n|---|---|---|---|\n";
  for (const auto& c : d.audit.checks)
    md << "| " << output::markdown_text(c.group) << " | " << output::markdown_text(c.name) << " | "
       << (c.passed ? "pass" : c.advisory ? "**warning**" : "**FAIL**") << " | "
       << output::markdown_text(c.group == "units" ? output::unit_for_reading(c.detail) : c.detail) << " |\n";
  md << "\n";
  if (!d.why_trim_does_not_hold.empty())
    md << "**The hover trim above is the base model's and does not hold this model:** "
       << output::markdown_text(d.why_trim_does_not_hold) << ". The header declares none (`kHasHoverTrim = false`).\n\n";
  if (!d.trim_moved_by_effects.empty()) {
    md << "**The hover trim above is the base model's; the header declares this model's own:** "
       << output::markdown_text(d.trim_moved_by_effects) << ". Commands";
    for (size_t i = 0; i < d.hover_trim.commands.size() && i < d.vehicle.rotors.size(); ++i)
      md << (i ? ", " : " ") << output::markdown_text(d.vehicle.rotors[i].name) << " " << output::six_digits(d.hover_trim.commands[i]);
    md << "; |f| = " << output::short_number(d.hover_residual) << " there.\n\n";
  }
}

void section_thesis(std::ostringstream& md, const Derivation& d) {
  if (d.thesis.empty()) return;
  md << "## 8. Comparison with the thesis\n\n"
     << "The thesis: " << output::markdown_text(kThesisCitation) << " (equation and section numbers below are its own). "
     << "Its equations and numbers are encoded in quadgen's `audit/thesis_reference.cpp`; each row compares "
        "them with the derived model at its nominal parameters. *Verdict from* says how each verdict was reached: "
        "computed from the derived model (its equations or an integration of them), computed by arithmetic on the "
        "quantities quadgen derives (mass, inertia, areas), or read from the equations' form (stated in "
        "`thesis_reference.cpp`, not computed). Roll here is the turn about x (phi) and pitch about y "
        "(theta); the thesis (2.2.4.1) names them the other way round, Nicken about x and Rollen about y.\n\n"
     << "| ref | topic | thesis | derived | verdict | verdict from | cause | size |\n|---|---|---|---|---|---|---|---|\n";
  for (const auto& t : d.thesis)
    md << "| " << output::markdown_text(t.ref) << " | " << output::markdown_text(t.topic) << " | " << output::markdown_text(t.thesis)
       << " | " << output::markdown_text(t.derived) << " | " << (t.agrees ? "agrees" : "**differs**") << " | "
       << output::markdown_text(t.basis) << " | " << output::markdown_text(t.cause) << " | " << output::markdown_text(t.size)
       << " |\n";
  md << "\n";
}

}  // namespace

std::string derivation_markdown(const Derivation& d) {
  std::ostringstream md;
  md << "# Derivation of the flight model: " << output::markdown_text(d.vehicle.name) << "\n\n"
     << "Generated by quadgen " << QUADGEN_VERSION << " from " << output::markdown_text(d.vehicle.source_path) << " (SHA-256 "
     << d.vehicle.content_hash << "). Effects: "
     << (d.model.effects.empty() ? std::string("none (base model)") : output::joined(d.model.effects))
     << ".\n\n";
  section_vehicle(md, d);
  TexWriter tex(d.model);
  section_mass(md, d, tex);
  section_equations(md, d, tex);
  md << "## 6. Variables\n\n";
  variable_table(md, "States x", d.model.states, false);
  variable_table(md, "Inputs u", d.model.inputs, false);
  variable_table(md, "Parameters p", d.model.params, true);
  section_audit(md, d);
  section_thesis(md, d);
  return md.str();
}

// The hover trim as the header declares it, 12 digits (a user trial, helper-82: the audit's
// text rounds it to four digits, which leaves a compiled model's roll acceleration at 7e-3
// rad/s^2 instead of about 1e-10), a motor lag's rotor speeds there in full: each rotor's thrust and command, as simulate's scenarios fly it; `why_not` says
// why there is none (then the thrusts are the least-norm balance and there are no commands).
static nlohmann::ordered_json hover_trim_json(const Derivation& d) {
  const runtime::HoverTrim& trim = d.hover_trim;
  nlohmann::ordered_json j;
  j["rotors"] = rotor_names(d.vehicle);
  j["thrust_N"] = trim.thrusts;
  // Where it does not hold the model (a review, helper-88: a consumer that read an empty
  // why_not took commands that left |f| = 8.4), no commands and the reason, as in the header.
  const bool holds = d.why_trim_does_not_hold.empty();
  j["command"] = holds ? trim.commands : std::vector<double>{};
  j["why_not"] = holds ? trim.why_not : d.why_trim_does_not_hold;
  if (!holds) j["base_model_command"] = trim.commands;
  // rad/s, a motor lag's rotor-speed states at the trim (the header's kHoverRotorSpeed).
  if (holds && !trim.rotor_speeds.empty()) j["rotor_speed_rad_s"] = trim.rotor_speeds;
  // The largest |f| at the commands under "command" (or, where there are none, at the base
  // model's trim, which then does not hold this model: how far it is off).
  j["largest_f_at_trim"] = d.hover_residual;
  // Where the trim is the model's own (fitted effect values moved the base model's): how, and
  // the base trim's commands and how far they are off.
  if (!d.trim_moved_by_effects.empty()) {
    j["moved_by_effects"] = d.trim_moved_by_effects;
    j["base_model_command"] = d.base_trim_commands;
    j["largest_f_at_base_model_command"] = d.base_trim_residual;
  }
  return j;
}

// The mass properties the model uses (a review found the blocks' here beside a hover trim for
// the file's given mass): the blocks', or the file's `derived:` values, or fitted ones; the
// blocks' own are under "from_blocks".
static void add_mass_properties(nlohmann::ordered_json& j, const Derivation& d) {
  const auto used = [&](const char* name) { return d.model.params[d.model.param_index(name)].nominal; };
  j["mass"] = used("mass");
  j["cog"] = {used("cog_x"), used("cog_y"), used("cog_z")};
  j["inertia"] = {{used("J_xx"), used("J_xy"), used("J_xz")},
                  {used("J_xy"), used("J_yy"), used("J_yz")},
                  {used("J_xz"), used("J_yz"), used("J_zz")}};
  j["from_blocks"] = {{"mass", d.mass.mass_value},
                      {"cog", d.mass.cog_value},
                      {"inertia", d.mass.inertia_cog_value},
                      {"areas", d.mass.areas_value},
                      {"inertia_about_origin", d.mass.inertia_origin_value}};
  j["areas"] = {used("A_x"), used("A_y"), used("A_z")};
  // Each quantity's unit, from the parameter it is (a reviewer: model.json had none).
  const auto unit = [&](const char* name) { return d.model.params[d.model.param_index(name)].unit; };
  j["units"] = {{"mass", unit("mass")},
                {"cog", unit("cog_x")},
                {"inertia", unit("J_xx")},
                {"areas", unit("A_x")},
                {"inertia_about_origin", unit("J_xx")}};
}

// States, inputs, parameters or outputs: name, unit, meaning; a parameter's value, bounds and
// whether fits estimate it.
static nlohmann::ordered_json variables_json(const std::vector<Variable>& vs, bool params) {
  nlohmann::ordered_json a = nlohmann::ordered_json::array();
  for (const auto& v : vs) {
    nlohmann::ordered_json o;
    o["name"] = v.name;
    if (params) o["value"] = v.nominal;
    o["unit"] = v.unit;
    if (params) {
      o["lower"] = v.lower;
      o["upper"] = v.upper;
      o["fit"] = v.fit;
    }
    o["meaning"] = v.doc;
    a.push_back(o);
  }
  return a;
}

static nlohmann::ordered_json audit_json(const Derivation& d) {
  nlohmann::ordered_json checks = nlohmann::ordered_json::array();
  for (const auto& c : d.audit.checks)
    checks.push_back({{"group", c.group}, {"check", c.name}, {"passed", c.passed}, {"advisory", c.advisory}, {"detail", c.detail}});
  return {{"passed", d.audit.all_passed()}, {"checks", checks}};
}

static nlohmann::ordered_json thesis_json(const Derivation& d) {
  nlohmann::ordered_json th = nlohmann::ordered_json::array();
  for (const auto& t : d.thesis)
    th.push_back({{"ref", t.ref}, {"topic", t.topic}, {"thesis", t.thesis}, {"derived", t.derived},
                  {"agrees", t.agrees}, {"basis", t.basis}, {"cause", t.cause}, {"size", t.size}});
  return th;
}

std::string model_json(const Derivation& d) {
  nlohmann::ordered_json j;
  j["quadgen_version"] = QUADGEN_VERSION;
  j["vehicle"] = d.vehicle.name;
  j["vehicle_hash"] = d.vehicle.content_hash;
  j["effects"] = d.model.effects;
  add_mass_properties(j, d);
  j["states"] = variables_json(d.model.states, false);
  j["inputs"] = variables_json(d.model.inputs, false);
  j["parameters"] = variables_json(d.model.params, true);
  j["outputs"] = variables_json(d.model.outputs, false);
  nlohmann::ordered_json blocks = nlohmann::ordered_json::array();
  for (const auto& b : d.mass.blocks)
    blocks.push_back({{"name", b.name}, {"inertia_about_origin", b.inertia_origin_value}, {"areas", b.areas_value}});
  j["blocks"] = blocks;
  j["audit"] = audit_json(d);
  j["hover_trim"] = hover_trim_json(d);
  j["thesis_comparison"] = thesis_json(d);
  return output::json_document(j);
}

}  // namespace quadgen
