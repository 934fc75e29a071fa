#include "geometry.hpp"

#include <cmath>

#include "exact_number.hpp"
#include "kinematics.hpp"

namespace quadgen {
using namespace GiNaC;

double to_double(const ex& e) {
  ex v = e.evalf();
  if (!is_a<numeric>(v)) throw std::runtime_error("expression does not evaluate to a number");
  return ex_to<numeric>(v).to_double();
}

Mat3 to_mat3(const matrix& m) {
  Mat3 r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r[i][j] = to_double(m(i, j));
  return r;
}

namespace {

// An angle in degrees as an exact multiple of Pi (to a thousandth of a degree),
// so that 45 deg gives cos = sqrt(2)/2 exactly.
ex exact_angle(double deg) {
  const long milli = std::lround(deg * 1000.0);
  return numeric(milli, 180000) * Pi;
}

std::string tex_name(const std::string& s) {
  std::string out;
  for (char c : s) out += (c == '_') ? std::string("\\_") : std::string(1, c);
  return out;
}

BlockSymbols make_symbols(const Block& b) {
  const std::string n = b.name;
  const std::string t = "{\\mathrm{" + tex_name(n) + "}}";
  return BlockSymbols{n,
                      symbol("m_" + n, "m_" + t),
                      symbol("a_" + n, "a_" + t),
                      symbol("b_" + n, "b_" + t),
                      symbol("c_" + n, "c_" + t),
                      symbol("cx_" + n, "x_" + t),
                      symbol("cy_" + n, "y_" + t),
                      symbol("cz_" + n, "z_" + t),
                      block_rotation(b.yaw_pitch_roll_deg)};
}

// ∫ ξ_i ξ_j dm over the centred cuboid [-a/2,a/2]x[-b/2,b/2]x[-c/2,c/2] with
// constant density m/(abc), by GiNaC's exact definite integration.
matrix local_second_moment(const BlockSymbols& s) {
  realsymbol xi("xi"), eta("eta"), zeta("zeta");
  const ex rho = s.m / (s.a * s.b * s.c);
  const ex coords[3] = {xi, eta, zeta};
  matrix S(3, 3);
  for (int i = 0; i < 3; ++i)
    for (int j = i; j < 3; ++j) {
      ex integrand = rho * coords[i] * coords[j];
      ex in_z = integral(zeta, -s.c / 2, s.c / 2, integrand).eval_integ();
      ex in_y = integral(eta, -s.b / 2, s.b / 2, in_z).eval_integ();
      ex in_x = integral(xi, -s.a / 2, s.a / 2, in_y).eval_integ();
      S(i, j) = S(j, i) = normal(in_x);
    }
  return S;
}

// Inertia tensor from a second-moment matrix S = ∫ r r^T dm: J = tr(S) I - S.
matrix inertia_from_second_moment(const matrix& S) {
  const ex tr = S(0, 0) + S(1, 1) + S(2, 2);
  matrix J(3, 3);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) J(i, j) = (i == j ? tr : ex(0)) - S(i, j);
  return J;
}

// Projected area of the rotated cuboid seen along each body axis:
// sum over its three face pairs of face area times |cos| between face normal and axis.
matrix projected_areas(const BlockSymbols& s) {
  const ex face[3] = {s.b * s.c, s.a * s.c, s.a * s.b};
  matrix A(3, 1);
  for (int k = 0; k < 3; ++k) {
    ex sum = 0;
    for (int j = 0; j < 3; ++j) {
      const double c = to_double(s.R(k, j));
      if (std::fabs(c) < 1e-15) continue;
      sum += (c < 0 ? -s.R(k, j) : s.R(k, j)) * face[j];
    }
    A(k, 0) = sum;
  }
  return A;
}

}  // namespace

matrix block_rotation(const Vec3& ypr) {
  return rotation_zyx(exact_angle(ypr[0]), exact_angle(ypr[1]), exact_angle(ypr[2]));
}

MassProperties derive_mass_properties(const Vehicle& v) {
  MassProperties mp;
  mp.mass = 0;
  matrix first_moment(3, 1), second_moment(3, 3);
  for (const Block& b : v.blocks) {
    BlockSymbols s = make_symbols(b);
    mp.values.append(s.m == exact(b.mass));
    mp.values.append(s.a == exact(b.size[0]));
    mp.values.append(s.b == exact(b.size[1]));
    mp.values.append(s.c == exact(b.size[2]));
    mp.values.append(s.cx == exact(b.centre[0]));
    mp.values.append(s.cy == exact(b.centre[1]));
    mp.values.append(s.cz == exact(b.centre[2]));

    BlockContribution bc;
    bc.name = b.name;
    bc.local_second_moment = local_second_moment(s);
    // Shift and rotate: ∫ (R ξ + c)(R ξ + c)^T dm = R S R^T + m c c^T (∫ ξ dm = 0).
    const matrix c = matrix(3, 1, lst{s.cx, s.cy, s.cz});
    const matrix S_body =
        s.R.mul(bc.local_second_moment).mul(s.R.transpose()).add(c.mul(c.transpose()).mul_scalar(s.m));
    matrix S_simpl(3, 3);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) S_simpl(i, j) = normal(S_body(i, j));
    bc.inertia_origin = inertia_from_second_moment(S_simpl);
    bc.areas = projected_areas(s);
    mp.mass += s.m;
    first_moment = first_moment.add(c.mul_scalar(s.m));
    second_moment = second_moment.add(S_simpl);
    mp.areas = mp.areas.add(bc.areas);
    mp.symbols.push_back(s);
    mp.blocks.push_back(bc);
  }
  for (int i = 0; i < 3; ++i) mp.cog(i, 0) = first_moment(i, 0) / mp.mass;
  mp.inertia_origin = inertia_from_second_moment(second_moment);
  // Parallel-axis shift to the centre of gravity: J_cg = J_o - m (|c|^2 I - c c^T).
  const ex cc = (mp.cog.transpose().mul(mp.cog))(0, 0);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      mp.inertia_cog(i, j) = mp.inertia_origin(i, j) - mp.mass * ((i == j ? cc : ex(0)) - mp.cog(i, 0) * mp.cog(j, 0));

  mp.mass_value = to_double(mp.mass.subs(mp.values));
  for (int i = 0; i < 3; ++i) {
    mp.cog_value[i] = to_double(mp.cog(i, 0).subs(mp.values));
    mp.areas_value[i] = to_double(mp.areas(i, 0).subs(mp.values));
  }
  mp.inertia_origin_value = to_mat3(ex_to<matrix>(ex(mp.inertia_origin).subs(mp.values)));
  mp.inertia_cog_value = to_mat3(ex_to<matrix>(ex(mp.inertia_cog).subs(mp.values)));
  for (auto& bc : mp.blocks) {
    bc.inertia_origin_value = to_mat3(ex_to<matrix>(ex(bc.inertia_origin).subs(mp.values)));
    for (int i = 0; i < 3; ++i) bc.areas_value[i] = to_double(bc.areas(i, 0).subs(mp.values));
  }
  return mp;
}

}  // namespace quadgen
