#include "audit/audit.hpp"

#include <algorithm>
#include <cmath>
#include <set>
#include <sstream>

#include <Eigen/Dense>

#include "audit/dimension_checker.hpp"
#include "derive/effects/effect_catalogue.hpp"
#include "derive/kinematics.hpp"
#include "runtime/rigid_body_state.hpp"

namespace quadgen {
using namespace GiNaC;

bool AuditResult::all_passed() const {
  for (const auto& c : checks)
    if (!c.passed && !c.advisory) return false;
  return true;
}

std::vector<const AuditCheck*> AuditResult::warnings() const {
  std::vector<const AuditCheck*> out;
  for (const auto& c : checks)
    if (!c.passed && c.advisory) out.push_back(&c);
  return out;
}

namespace {

AuditCheck make(const std::string& group, const std::string& name, bool ok, const std::string& detail) {
  return AuditCheck{group, name, ok, detail};
}

// sin(x)^2 -> 1 - cos(x)^2 until no sine is squared: GiNaC evaluates sin and cos of multiples
// of Pi/4 and Pi/6 to radicals but keeps cos(1/8 Pi) as a function, and normal() treats
// sin(x) and cos(x) as independent, so an identity that needs sin^2 + cos^2 = 1 (a rotated
// block of an octocopter's 22.5 deg arm) would not normalise to 0. Reduced to degree <= 1 in
// each sine, a polynomial in sines and cosines of the same angles is zero iff it vanishes.
ex reduce_trigonometry(const ex& e) {
  const ex sin2 = pow(sin(wild(0)), 2) == 1 - pow(cos(wild(0)), 2);
  ex r = expand(e);
  for (int pass = 0; pass < 8; ++pass) {
    const ex next = expand(r.subs(sin2, subs_options::algebraic));
    if (next.is_equal(r)) break;
    r = next;
  }
  return r;
}

bool is_zero_matrix(const matrix& m) {
  for (unsigned i = 0; i < m.rows(); ++i)
    for (unsigned j = 0; j < m.cols(); ++j)
      if (!normal(reduce_trigonometry(m(i, j))).is_zero()) return false;
  return true;
}

DimensionChecker dimension_checker(const SymbolicModel& m) {
  DimensionChecker dc;
  for (const auto* list : {&m.states, &m.inputs, &m.params, &m.constants})
    for (const auto& v : *list) dc.declare(v.sym, v.dim);
  return dc;
}

std::vector<AuditCheck> check_quaternion_norm(const SymbolicModel& m) {
  // d/dt |q|^2 = 2 q . dq/dt must vanish identically for the model's own quaternion rows.
  ex s = 0;
  for (int i = 0; i < 4; ++i) s += m.states[runtime::rigid_body::kAttitude + i].sym * m.f(runtime::rigid_body::kAttitude + i, 0);
  const bool ok = expand(s).is_zero();
  return {make("rotation", "quaternion kinematics preserve |q|", ok,
               "q . dq/dt of the model's rows 7-10 expands to 0")};
}

}  // namespace

std::vector<AuditCheck> check_rotation(const AttitudeForms& forms) {
  std::vector<AuditCheck> out;
  realsymbol phi("phi"), theta("theta"), psi("psi");
  const matrix R = forms.zyx(psi, theta, phi);
  matrix RtR = R.transpose().mul(R);
  bool orth = true;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (!reduce_trig(RtR(i, j) - (i == j ? 1 : 0), {phi, theta, psi}).is_zero()) orth = false;
  out.push_back(make("rotation", "Z-Y-X matrix orthogonal", orth,
                     "R = Rz(psi) Ry(theta) Rx(phi); every entry of R^T R - I reduces to 0 modulo sin^2 + cos^2 = 1"));
  const ex det = reduce_trig(R.determinant() - 1, {phi, theta, psi});
  out.push_back(make("rotation", "Z-Y-X matrix proper (det = +1)", det.is_zero(),
                     "det R - 1 reduces to 0 modulo sin^2 + cos^2 = 1"));

  realsymbol qw("qw"), qx("qx"), qy("qy"), qz("qz");
  const matrix q = quaternion(qw, qx, qy, qz);
  const matrix Rq = forms.from_quaternion(q);
  const matrix QtQ = Rq.transpose().mul(Rq);
  bool qorth = true;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (!reduce_unit_quaternion(QtQ(i, j) - (i == j ? 1 : 0), qw, qx, qy, qz).is_zero()) qorth = false;
  out.push_back(make("rotation", "quaternion matrix orthogonal", qorth,
                     "R(q)^T R(q) - I reduces to 0 modulo |q|^2 = 1"));
  out.push_back(make("rotation", "quaternion matrix proper (det = +1)",
                     reduce_unit_quaternion(Rq.determinant() - 1, qw, qx, qy, qz).is_zero(),
                     "det R(q) - 1 reduces to 0 modulo |q|^2 = 1"));
  // R(q) for the Z-Y-X quaternion equals the Z-Y-X matrix: the two attitude forms agree.
  const matrix qzyx = quaternion_product(quaternion_product(axis_quaternion(2, psi), axis_quaternion(1, theta)),
                                         axis_quaternion(0, phi));
  lst half;
  for (const ex& a : {ex(phi), ex(theta), ex(psi)}) {
    half.append(sin(a) == 2 * sin(a / 2) * cos(a / 2));
    half.append(cos(a) == 1 - 2 * pow(sin(a / 2), 2));
  }
  const matrix diff = forms.from_quaternion(qzyx).sub(ex_to<matrix>(ex(R).subs(half)));
  bool same = true;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (!reduce_trig(diff(i, j), {phi / 2, theta / 2, psi / 2}).is_zero()) same = false;
  out.push_back(make("rotation", "quaternion and Z-Y-X matrix agree", same,
                     "R(q_z(psi) q_y(theta) q_x(phi)) - Rz Ry Rx reduces to 0 (half-angle identities)"));
  return out;
}

PrincipalMoments principal_moments(const Mat3& J) {
  Eigen::Matrix3d M;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) M(i, j) = J[static_cast<size_t>(i)][static_cast<size_t>(j)];
  const Eigen::Vector3d l = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(M).eigenvalues();
  PrincipalMoments pm;
  pm.moments = {l(0), l(1), l(2)};
  pm.positive = l.minCoeff() > 0;
  pm.triangle = l(0) + l(1) >= l(2) * (1 - 1e-12);
  return pm;
}

namespace {

std::vector<AuditCheck> check_inertia(const MassProperties& mp) {
  std::vector<AuditCheck> out;
  bool sym = true;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (!normal(mp.inertia_cog(i, j) - mp.inertia_cog(j, i)).is_zero()) sym = false;
  out.push_back(make("inertia", "symmetric", sym,
                     "J_cg - J_cg^T = 0 symbolically (true by construction, R S R^T and symmetric shifts: a guard "
                     "against a change of that construction, not evidence about the vehicle)"));

  const PrincipalMoments pm = principal_moments(mp.inertia_cog_value);
  const auto& l = pm.moments;
  std::ostringstream os;
  os << "principal moments " << l[0] << ", " << l[1] << ", " << l[2] << " kg m²";  // as derivation.md's units
  out.push_back(make("inertia", "positive definite", pm.positive, os.str()));
  out.push_back(make("inertia", "triangle inequalities of principal moments", pm.triangle,
                     "each principal moment <= sum of the other two"));

  bool closed = true;
  std::string bad;
  for (size_t b = 0; b < mp.blocks.size(); ++b) {
    const matrix d = closed_form_block_inertia(mp.symbols[b]).sub(mp.blocks[b].inertia_origin);
    if (!is_zero_matrix(d)) {
      closed = false;
      bad += mp.blocks[b].name + " ";
    }
  }
  out.push_back(make("inertia", "integrals match closed form + parallel axis", closed,
                     closed ? "for every block, symbolically: m/12 diag(b^2+c^2, a^2+c^2, a^2+b^2) rotated, "
                              "plus m(|c|^2 I - c c^T), equals the integrated tensor"
                            : "mismatch in " + bad));
  return out;
}

// The body -> world rotation of a unit quaternion (Hamilton, scalar first), written out here
// rather than taken from derive/kinematics, so that the momentum check below does not lean on
// the code it checks.
matrix body_to_world(const ex& w, const ex& x, const ex& y, const ex& z) {
  return matrix(3, 3, lst{1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),
                          2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
                          2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)});
}

// Without torques a rigid body keeps its angular momentum in the world frame, L = R(q) J ω.
// Only this check tells the sign of the gyroscopic term: ω·(ω × Jω) and (Jω)·(ω × Jω) vanish
// for every J, so the energy and |Jω| checks pass for J dω/dt = -ω × Jω, for the thesis' (35)
// sign +ω × Jω and with the term dropped alike (they are necessary conditions, kept because
// they do not involve the attitude). dL/dt takes the model's own quaternion rows (dR/dt =
// Σ ∂R/∂q_i dq_i/dt) and body-rate rows, so a kinematics written for world-frame rates fails
// it too. Since R is invertible, R^T dL/dt = R^T dR/dt J ω + J dω/dt is tested for zero, modulo
// |q|^2 = 1, for a general symmetric J.
AuditCheck check_world_angular_momentum(const SymbolicModel& m, const matrix& J, const lst& off) {
  using namespace runtime::rigid_body;
  ex q[4];
  for (int i = 0; i < 4; ++i) q[i] = m.states[kAttitude + i].sym;
  const matrix R = body_to_world(q[0], q[1], q[2], q[3]);
  matrix Rdot(3, 3), w(3, 1), wdot(3, 1);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      for (int i = 0; i < 4; ++i)
        Rdot(r, c) += R(r, c).diff(ex_to<symbol>(q[i])) * m.f(kAttitude + i, 0).subs(off);
  for (int i = 0; i < 3; ++i) {
    w(i, 0) = m.states[kBodyRate + i].sym;
    wdot(i, 0) = m.f(kBodyRate + i, 0).subs(off);
  }
  const matrix from_attitude = R.transpose().mul(Rdot).mul(J.mul(w)), from_rates = J.mul(wdot);
  bool kept = true;
  for (int i = 0; i < 3; ++i) {
    const ex sum = normal(reduce_unit_quaternion(from_attitude(i, 0), q[0], q[1], q[2], q[3]) + from_rates(i, 0));
    if (!reduce_unit_quaternion(numer(sum), q[0], q[1], q[2], q[3]).is_zero()) kept = false;
  }
  return make("energy", "angular momentum conserved in the world frame", kept,
              "R^T d/dt (R(q) J ω) of the model's quaternion and body-rate rows, torques off as above, reduces to 0 "
              "modulo |q|^2 = 1 for a general symmetric J (R(q) written out in the audit); the only one of the three "
              "that tells the sign of ω × Jω");
}

// The model's rotational rows without torques conserve 1/2 ω·Jω and |Jω|^2 (necessary
// conditions) and the world-frame angular momentum (the sharp one).
std::vector<AuditCheck> check_energy(const SymbolicModel& m) {
  using namespace runtime::rigid_body;
  const lst off = torque_free_substitutions(m);
  matrix w(3, 1), wdot(3, 1);
  for (int i = 0; i < 3; ++i) {
    w(i, 0) = m.states[kBodyRate + i].sym;
    wdot(i, 0) = m.f(kBodyRate + i, 0).subs(off);
  }
  auto P = [&](const char* n) { return m.params[m.param_index(n)].sym; };
  const matrix J(3, 3, lst{P("J_xx"), P("J_xy"), P("J_xz"), P("J_xy"), P("J_yy"), P("J_yz"),
                           P("J_xz"), P("J_yz"), P("J_zz")});
  const matrix Jw = J.mul(w), Jwdot = J.mul(wdot);
  ex dE = 0, dL = 0;
  for (int i = 0; i < 3; ++i) {
    dE += w(i, 0) * Jwdot(i, 0);
    dL += Jw(i, 0) * Jwdot(i, 0);
  }
  return {make("energy", "rotational kinetic energy conserved", normal(dE).is_zero(),
               "d/dt (1/2 ω^T J ω) = ω^T J dω/dt of the model's rows with c_t = g = 0 (and blade_flapping.k = 0) normalises "
               "to 0 for a general symmetric J (a necessary condition: it holds for either sign of ω × Jω)"),
          make("energy", "angular momentum magnitude conserved", normal(dL).is_zero(),
               "d/dt |Jω|^2 / 2 = (Jω)^T J dω/dt normalises to 0 (a necessary condition, as above)"),
          check_world_angular_momentum(m, J, off)};
}

// Two evaluated expressions that are numbers agreeing to 1e-12 of the larger (or of 1): how
// the audit compares a model's row with one written out apart, at generic points.
bool numbers_agree(const ex& a, const ex& b) {
  return is_a<numeric>(a) && is_a<numeric>(b) &&
         abs(ex_to<numeric>(a - b)).to_double() <=
             1e-12 * std::max({1.0, abs(ex_to<numeric>(a)).to_double(), abs(ex_to<numeric>(b)).to_double()});
}

// Every symbol of the model at a value of its own (0.5 to 1.5, no two alike, so that no
// difference such as J_yy - J_zz vanishes by accident), J's off-diagonal entries at 0.
exmap generic_values(const SymbolicModel& m, double step, const lst& diagonal) {
  exmap at;
  int n = 0;
  for (const auto* list : {&m.states, &m.inputs, &m.params, &m.constants})
    for (const auto& v : *list) at[v.sym] = 0.5 + std::fmod(step * ++n, 1.0);
  for (const ex& e : diagonal) at[e.lhs()] = 0;
  return at;
}

// With J diagonal the body-rate rows must be Euler's equations, J_xx dp/dt = τ_x + (J_yy - J_zz) q r
// and its cyclic permutations, written out here apart from the model's J^-1 (τ - ω × Jω). The
// energy checks switch the torques off; this one tells how they enter (through J^-1, with the
// moment about the CoG that the model names τ). Compared in numbers at two generic points, not
// normalised: with every effect's τ, normal() doubled the audit's time.
AuditCheck check_euler_equations(const SymbolicModel& m) {
  using namespace runtime::rigid_body;
  auto P = [&](const char* n) { return m.params[m.param_index(n)].sym; };
  const lst diagonal{P("J_xy") == 0, P("J_xz") == 0, P("J_yz") == 0};
  const ex& tau = m.intermediate("\\tau");
  const bool has_tau = is_a<matrix>(tau) && ex_to<matrix>(tau).rows() == 3 && ex_to<matrix>(tau).cols() == 1;
  const ex J[3] = {P("J_xx"), P("J_yy"), P("J_zz")};
  ex w[3];
  for (int i = 0; i < 3; ++i) w[i] = m.states[kBodyRate + i].sym;
  bool euler = has_tau;
  for (const double step : {0.6180339887498949, 0.4142135623730951}) {
    const exmap at = generic_values(m, step, diagonal);
    for (int i = 0; i < 3 && euler; ++i) {
      const int j = (i + 1) % 3, k = (i + 2) % 3;
      const ex written_out = (ex_to<matrix>(tau)(i, 0) + (J[j] - J[k]) * w[j] * w[k]) / J[i];
      euler = numbers_agree(evalf(m.f(kBodyRate + i, 0).subs(at)), evalf(written_out.subs(at)));
    }
  }
  return make("rotation", "body-rate rows are Euler's equations for a diagonal J", euler,
              has_tau ? "with J_xy = J_xz = J_yz = 0 each row equals (τ_i + (J_jj - J_kk) ω_j ω_k) / J_ii, (i, j, k) cyclic, "
                        "to 1e-12 at two generic points of every state, input and parameter (τ: the moment about the "
                        "CoG of section 4)"
                      : "the model's moment τ is not a 3-vector");
}

// a × b, written out here (not derive's cross) for the check below.
matrix cross3(const matrix& a, const matrix& b) {
  return matrix(3, 1, lst{a(1, 0) * b(2, 0) - a(2, 0) * b(1, 0), a(2, 0) * b(0, 0) - a(0, 0) * b(2, 0),
                          a(0, 0) * b(1, 0) - a(1, 0) * b(0, 0)});
}

// The symbols of `e` replaced by the model's of the same name: an effect's formula is derived
// on a scratch copy of the base model, whose symbols are its own.
void collect_symbols(const ex& e, exset& out) {
  if (is_a<symbol>(e)) out.insert(e);
  for (size_t i = 0; i < e.nops(); ++i) collect_symbols(e.op(i), out);
}
ex with_model_symbols(const SymbolicModel& m, const ex& e) {
  exset found;
  collect_symbols(e, found);
  exmap to_model;
  for (const ex& s : found)
    for (const auto* list : {&m.states, &m.inputs, &m.params, &m.constants})
      for (const auto& v : *list)
        if (v.name == ex_to<symbol>(s).get_name()) to_model[s] = v.sym;
  return e.subs(to_model);
}

// The CoG the model's translation rows take: the vehicle's (cog_x, cog_y, cog_z) moved by any
// effect's Δc (cog_offset's).
matrix model_cog(const SymbolicModel& m) {
  auto P = [&](const char* n) { return m.params[m.param_index(n)].sym; };
  matrix c(3, 1, lst{P("cog_x"), P("cog_y"), P("cog_z")});
  for (const auto& f : m.effect_formulas)
    for (const auto& line : f.lines)
      if (line.first == "\\Delta c" && is_a<matrix>(line.second))
        c = c.add(ex_to<matrix>(with_model_symbols(m, line.second)));
  return c;
}

// Every symbol at a generic value (generic_values), the attitude a unit quaternion (R(q) below
// is written for one), and dω/dt's symbols at the model's rows 10-12 there.
exmap generic_values_with_unit_quaternion(const SymbolicModel& m, double step) {
  using namespace runtime::rigid_body;
  exmap at = generic_values(m, step, lst{});
  double norm = 0;
  for (int i = 0; i < 4; ++i) norm += std::pow(ex_to<numeric>(at[m.states[kAttitude + i].sym]).to_double(), 2);
  for (int i = 0; i < 4; ++i)
    at[m.states[kAttitude + i].sym] = ex_to<numeric>(at[m.states[kAttitude + i].sym]).to_double() / std::sqrt(norm);
  for (size_t i = 0; i < m.omega_dot.size(); ++i) at[m.omega_dot[i]] = evalf(m.f(kBodyRate + i, 0).subs(at));
  return at;
}

// The velocity rows: dv/dt = R(q) (F_body / m - dω/dt × c - ω × (ω × c)) - g e_z, with R(q)
// written out in the audit, F_body the model's body force (section 4), c its CoG and dω/dt
// the model's rows 10-12, in f's rows and in f_split's (where dω/dt are symbols, for the
// Jacobians: equal to f once they are rows 10-12). Without this nothing in the
// audit tied the translation rows to the attitude: a transposed R, gravity of the wrong sign
// or a force not divided by the mass passed every other check, and the thesis comparison's
// rows on the direction of travel would have read "agrees" (a review, helper-141, 2026-12-07).
// Compared in numbers at two generic points, as Euler's equations are.
AuditCheck check_translation_rows(const SymbolicModel& m) {
  using namespace runtime::rigid_body;
  const char* const name = "velocity rows are R(q) F_body / m - g e_z with the CoG's transport";
  const ex& force = m.intermediate("F_{body}");
  if (!is_a<matrix>(force) || ex_to<matrix>(force).rows() != 3 || m.omega_dot.size() != 3 || m.f_split.rows() != m.f.rows())
    return make("translation", name, false, "the model's F_body is not a 3-vector, or dω/dt has no symbols of its own");
  const matrix c = model_cog(m);
  matrix w(3, 1), w_dot(3, 1);
  for (int i = 0; i < 3; ++i) w(i, 0) = m.states[kBodyRate + i].sym, w_dot(i, 0) = m.omega_dot[i];
  const ex mass = m.params[m.param_index("mass")].sym, g = m.params[m.param_index("g")].sym;
  ex q[4];
  for (int i = 0; i < 4; ++i) q[i] = m.states[kAttitude + i].sym;
  const matrix body = ex_to<matrix>(force).mul_scalar(1 / mass).sub(cross3(w_dot, c)).sub(cross3(w, cross3(w, c)));
  const matrix world = body_to_world(q[0], q[1], q[2], q[3]).mul(body).sub(matrix(3, 1, lst{0, 0, g}));
  bool rows = true;
  for (const double step : {0.6180339887498949, 0.4142135623730951}) {
    const exmap at = generic_values_with_unit_quaternion(m, step);
    for (int i = 0; i < 3; ++i)
      for (const matrix* f : {&m.f, &m.f_split})
        rows = rows && numbers_agree(evalf((*f)(kVelocity + i, 0).subs(at)), evalf(world(i, 0).subs(at)));
  }
  return make("translation", name, rows,
              "each row of dv/dt equals R(q) (F_body / m - dω/dt × c - ω × (ω × c)) - g e_z to 1e-12 at two generic "
              "points with a unit quaternion (R(q) written out in the audit; F_body of section 4; c the CoG with any "
              "effect's Δc; dω/dt the model's rows, in f and as f_split's symbols): the one check that ties the "
              "translation to the attitude");
}

}  // namespace

// The substitutions that leave a model without torques: thrust (c_t = 0), gravity (g = 0),
// every effect whose own formula adds a moment (Δτ: the flapping moment) and any term added
// beyond the catalogue (term_*: an external force or moment found in data) switched off.
// Rotor drag is a force at the CoG and adds none.
lst torque_free_substitutions(const SymbolicModel& m) {
  lst off{m.params[m.param_index("c_t")].sym == 0, m.params[m.param_index("g")].sym == 0};
  std::set<std::string> adds_moment;
  for (const auto& f : m.effect_formulas)
    for (const auto& line : f.lines)
      if (line.first == "\\Delta \\tau") adds_moment.insert(f.effect);
  for (const auto& p : m.params)
    if (adds_moment.count(effect_of_parameter(p.name)) || p.name.rfind("term_", 0) == 0) off.append(p.sym == 0);
  return off;
}

ex reduce_trig(const ex& e, const std::vector<ex>& angles) {
  // Replace sin(a), cos(a) by symbols s, c and divide out c^2 + s^2 - 1 as a polynomial in c.
  std::vector<std::pair<symbol, symbol>> sc;
  lst to_symbols;
  for (const ex& a : angles) {
    symbol s("s"), c("c");
    to_symbols.append(sin(a) == s);
    to_symbols.append(cos(a) == c);
    sc.push_back({s, c});
  }
  ex r = expand(e.subs(to_symbols));
  for (const auto& [s, c] : sc) r = expand(rem(r, pow(c, 2) + pow(s, 2) - 1, c));
  return r;
}

ex reduce_unit_quaternion(const ex& e, const ex& qw, const ex& qx, const ex& qy, const ex& qz) {
  const ex r = rem(expand(e), pow(qw, 2) + pow(qx, 2) + pow(qy, 2) + pow(qz, 2) - 1, qw);
  return expand(r);
}

matrix closed_form_block_inertia(const BlockSymbols& s) {
  const ex k = s.m / 12;
  const matrix Jc(3, 3, lst{k * (s.b * s.b + s.c * s.c), 0, 0, 0, k * (s.a * s.a + s.c * s.c), 0, 0, 0,
                            k * (s.a * s.a + s.b * s.b)});
  const matrix c = vec3(s.cx, s.cy, s.cz);
  const ex cc = s.cx * s.cx + s.cy * s.cy + s.cz * s.cz;
  matrix shift(3, 3);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) shift(i, j) = s.m * ((i == j ? cc : ex(0)) - c(i, 0) * c(j, 0));
  return s.R.mul(Jc).mul(s.R.transpose()).add(shift);
}

std::vector<AuditCheck> check_units(const SymbolicModel& m) {
  std::vector<AuditCheck> out;
  const DimensionChecker dc = dimension_checker(m);
  const Dimension per_second = parse_unit("1/s").dim;
  for (size_t i = 0; i < m.states.size(); ++i) {
    const std::string name = "d" + m.states[i].name + "/dt";
    try {
      const Dimension d = dc.infer(m.f(i, 0));
      const Dimension want = m.states[i].dim * per_second;
      out.push_back(make("units", name, d == want,
                         "every term has [" + d.str() + "], expected [" + want.str() + "]"));
    } catch (const UnitError& e) {
      out.push_back(make("units", name, false, e.what()));
    }
  }
  for (size_t i = 0; i < m.outputs.size(); ++i) {
    try {
      const Dimension d = dc.infer(m.h(i, 0));
      out.push_back(make("units", "output " + m.outputs[i].name, d == m.outputs[i].dim,
                         "[" + d.str() + "], expected [" + m.outputs[i].dim.str() + "]"));
    } catch (const UnitError& e) {
      out.push_back(make("units", "output " + m.outputs[i].name, false, e.what()));
    }
  }
  return out;
}

namespace {
std::vector<AuditCheck> check_mass_property_units(const MassProperties& mp) {
  DimensionChecker dc;
  const Dimension m = parse_unit("m").dim, kg = parse_unit("kg").dim;
  for (const auto& s : mp.symbols) {
    dc.declare(s.m, kg);
    for (const symbol* l : {&s.a, &s.b, &s.c, &s.cx, &s.cy, &s.cz}) dc.declare(*l, m);
  }
  std::vector<AuditCheck> out;
  auto check = [&](const std::string& what, const ex& e, const Dimension& want) {
    try {
      const Dimension d = dc.infer(e);
      out.push_back(make("units", what, d == want, "[" + d.str() + "], expected [" + want.str() + "]"));
    } catch (const UnitError& err) {
      out.push_back(make("units", what, false, err.what()));
    }
  };
  check("mass", mp.mass, kg);
  for (int i = 0; i < 3; ++i) check(std::string("centre of gravity c_") + "xyz"[i], mp.cog(i, 0), m);
  for (int i = 0; i < 3; ++i)
    for (int j = i; j < 3; ++j)
      check(std::string("inertia J_") + "xyz"[i] + "xyz"[j], mp.inertia_cog(i, j), kg * m * m);
  for (int i = 0; i < 3; ++i) check(std::string("area A_") + "xyz"[i], mp.areas(i, 0), m * m);
  return out;
}
}  // namespace

AuditResult audit(const SymbolicModel& m, const MassProperties& mp) {
  AuditResult r;
  auto add = [&](std::vector<AuditCheck> v) { r.checks.insert(r.checks.end(), v.begin(), v.end()); };
  add(check_units(m));
  add(check_mass_property_units(mp));
  add(check_rotation());
  add(check_quaternion_norm(m));
  add({check_euler_equations(m)});
  add({check_translation_rows(m)});
  add(check_inertia(mp));
  add(check_energy(m));
  return r;
}

}  // namespace quadgen
