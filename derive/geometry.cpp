#include "derive/geometry.hpp"

#include <array>
#include <cmath>
#include <map>
#include <utility>

#include "derive/exact_number.hpp"
#include "derive/kinematics.hpp"
#include "output/sinks.hpp"

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

BlockSymbols make_symbols(const Block& b, const matrix& R) {
  const std::string n = b.name;
  const std::string t = "{\\mathrm{" + output::latex_math_text(n) + "}}";
  return BlockSymbols{n,
                      symbol("m_" + n, "m_" + t),
                      symbol("a_" + n, "a_" + t),
                      symbol("b_" + n, "b_" + t),
                      symbol("c_" + n, "c_" + t),
                      symbol("cx_" + n, "x_" + t),
                      symbol("cy_" + n, "y_" + t),
                      symbol("cz_" + n, "z_" + t),
                      R};
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
matrix projected_areas(const matrix& R, const ex& a, const ex& b, const ex& c) {
  const ex face[3] = {b * c, a * c, a * b};
  matrix A(3, 1);
  for (int k = 0; k < 3; ++k) {
    ex sum = 0;
    for (int j = 0; j < 3; ++j) {
      const double cosine = to_double(R(k, j));
      if (std::fabs(cosine) < 1e-15) continue;
      sum += (cosine < 0 ? -R(k, j) : R(k, j)) * face[j];
    }
    A(k, 0) = sum;
  }
  return A;
}

// One generic block: mass m, edges a, b, c, centre (x, y, z). The cuboid is integrated
// once per derivation, ∫ ξ_i ξ_j dm over [-a/2,a/2]x[-b/2,b/2]x[-c/2,c/2] with constant
// density m/(abc), by GiNaC's exact definite integration; per orientation the second
// moment is rotated and shifted into the body frame once. A block then costs the
// substitution of its own symbols (for the expressions) and of its own numbers (for the
// values) into these closed forms, the same whatever the size of the vehicle. Integrating
// and normalising every block anew cost about 1 ms per block.
struct GenericBlock {
  symbol m{"m"}, a{"a"}, b{"b"}, c{"c"}, x{"x"}, y{"y"}, z{"z"};
  matrix S{3, 3};  // ∫ ξ ξ^T dm in the block frame

  // The generic block in one orientation, in the body frame.
  struct Placed {
    matrix R;
    matrix S_body{3, 3};   // ∫ r r^T dm about the body origin, normalised
    matrix inertia{3, 3};  // tr(S_body) I - S_body
    matrix areas{3, 1};
    bool symmetric = false;  // S_body(i, j) and S_body(j, i) the same expression

    // subs into a symmetric 3x3 matrix, the lower triangle copied where it is the same.
    matrix substitute(const matrix& M, const exmap& values) const {
      matrix r(3, 3);
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
          r(i, j) = j < i && symmetric ? r(j, i) : M(i, j).subs(values, subs_options::no_pattern | subs_options::pattern_is_not_product);
      return r;
    }
  };

  GenericBlock() {
    realsymbol xi("xi"), eta("eta"), zeta("zeta");
    const ex rho = m / (a * b * c);
    const ex coords[3] = {xi, eta, zeta};
    for (int i = 0; i < 3; ++i)
      for (int j = i; j < 3; ++j) {
        ex integrand = rho * coords[i] * coords[j];
        ex in_z = integral(zeta, -c / 2, c / 2, integrand).eval_integ();
        ex in_y = integral(eta, -b / 2, b / 2, in_z).eval_integ();
        ex in_x = integral(xi, -a / 2, a / 2, in_y).eval_integ();
        S(i, j) = S(j, i) = normal(in_x);
      }
  }

  const Placed& placed(const Vec3& ypr) {
    const std::array<long, 3> key = {std::lround(ypr[0] * 1000.0), std::lround(ypr[1] * 1000.0),
                                     std::lround(ypr[2] * 1000.0)};
    auto it = orientations.find(key);
    if (it != orientations.end()) return it->second;
    Placed p;
    p.R = block_rotation(ypr);
    // Shift and rotate: ∫ (R ξ + c)(R ξ + c)^T dm = R S R^T + m c c^T (∫ ξ dm = 0).
    const matrix centre = matrix(3, 1, lst{x, y, z});
    const matrix S_body = p.R.mul(S).mul(p.R.transpose()).add(centre.mul(centre.transpose()).mul_scalar(m));
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) p.S_body(i, j) = normal(S_body(i, j));
    p.inertia = inertia_from_second_moment(p.S_body);
    p.symmetric = true;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < i; ++j)
        p.symmetric = p.symmetric && p.S_body(i, j).is_equal(p.S_body(j, i)) && p.inertia(i, j).is_equal(p.inertia(j, i));
    p.areas = projected_areas(p.R, a, b, c);
    return orientations.emplace(key, std::move(p)).first->second;
  }

  exmap to_symbols(const BlockSymbols& s) const {
    return {{m, s.m}, {a, s.a}, {b, s.b}, {c, s.c}, {x, s.cx}, {y, s.cy}, {z, s.cz}};
  }
  exmap to_numbers(const Block& bl) const {
    return {{m, exact(bl.mass)},      {a, exact(bl.size[0])},   {b, exact(bl.size[1])}, {c, exact(bl.size[2])},
            {x, exact(bl.centre[0])}, {y, exact(bl.centre[1])}, {z, exact(bl.centre[2])}};
  }

 private:
  std::map<std::array<long, 3>, Placed> orientations;  // by thousandths of a degree, as exact_angle
};

// The terms the vehicle's totals are sums of, block by block: as expressions in the blocks'
// symbols, and as the blocks' exact values. `second` holds second moments (expressions) or
// inertias about the origin (values): whichever the block's closed forms give cheaply.
struct TotalTerms {
  exvector mass;
  std::array<exvector, 3> first, areas;
  std::array<std::array<exvector, 3>, 3> second;
  void add(const ex& m, const ex c[3], const matrix& areas_col, const matrix& second_3x3) {
    mass.push_back(m);
    for (int i = 0; i < 3; ++i) {
      first[i].push_back(m * c[i]);
      areas[i].push_back(areas_col(i, 0));
      for (int j = 0; j < 3; ++j) second[i][j].push_back(second_3x3(i, j));
    }
  }
};

struct Totals {
  ex mass;
  matrix cog{3, 1}, inertia_origin{3, 3}, inertia_cog{3, 3}, areas{3, 1};
};

// The same steps for the expressions and for the exact values: the sums built in one go
// (adding term by term copies the growing sum each time), then the parallel-axis shift.
Totals totals(const TotalTerms& t, bool is_second_moment) {
  Totals r;
  r.mass = add(t.mass);
  matrix sum(3, 3);
  for (int i = 0; i < 3; ++i) {
    r.cog(i, 0) = add(t.first[i]) / r.mass;
    r.areas(i, 0) = add(t.areas[i]);
    for (int j = 0; j < 3; ++j) sum(i, j) = add(t.second[i][j]);
  }
  r.inertia_origin = is_second_moment ? inertia_from_second_moment(sum) : sum;
  // Parallel-axis shift to the centre of gravity: J_cg = J_o - m (|c|^2 I - c c^T).
  const ex cc = (r.cog.transpose().mul(r.cog))(0, 0);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      r.inertia_cog(i, j) = r.inertia_origin(i, j) - r.mass * ((i == j ? cc : ex(0)) - r.cog(i, 0) * r.cog(j, 0));
  return r;
}

// One block's contribution: the generic block's closed forms with its symbols and with its
// numbers substituted (two substitutions, by lookup), its terms added to both totals.
BlockContribution contribution(const Block& b, const GenericBlock& generic, const GenericBlock::Placed& placed,
                               const BlockSymbols& s, MassProperties& mp, TotalTerms& sym, TotalTerms& num) {
  const unsigned by_lookup = subs_options::no_pattern | subs_options::pattern_is_not_product;
  const exmap to_symbols = generic.to_symbols(s), to_numbers = generic.to_numbers(b);
  for (const symbol* g : {&generic.m, &generic.a, &generic.b, &generic.c, &generic.x, &generic.y, &generic.z})
    mp.values.append(to_symbols.at(*g) == to_numbers.at(*g));

  BlockContribution bc;
  bc.name = b.name;
  bc.local_second_moment = ex_to<matrix>(ex(generic.S).subs(to_symbols, by_lookup));
  const matrix S_body = placed.substitute(placed.S_body, to_symbols);
  bc.inertia_origin = inertia_from_second_moment(S_body);
  bc.areas = ex_to<matrix>(ex(placed.areas).subs(to_symbols, by_lookup));
  const matrix inertia_exact = placed.substitute(placed.inertia, to_numbers);
  const matrix areas_exact = ex_to<matrix>(ex(placed.areas).subs(to_numbers, by_lookup));
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      bc.inertia_origin_value[i][j] = j < i && placed.symmetric ? bc.inertia_origin_value[j][i] : to_double(inertia_exact(i, j));
  for (int i = 0; i < 3; ++i) bc.areas_value[i] = to_double(areas_exact(i, 0));

  const ex centre_symbols[3] = {s.cx, s.cy, s.cz};
  const ex centre[3] = {to_numbers.at(generic.x), to_numbers.at(generic.y), to_numbers.at(generic.z)};
  sym.add(s.m, centre_symbols, bc.areas, S_body);
  num.add(to_numbers.at(generic.m), centre, areas_exact, inertia_exact);
  return bc;
}

}  // namespace

matrix block_rotation(const Vec3& ypr) {
  return rotation_zyx(exact_angle(ypr[0]), exact_angle(ypr[1]), exact_angle(ypr[2]));
}

// Linear in the number of blocks. Each block costs two substitutions into the generic
// block's closed forms (its symbols, its numbers); the symbolic sums are built in one go
// from the collected terms; the totals' values are the same formulas applied to the sums of
// the blocks' exact values (exact arithmetic, so the same numbers as substituting all values
// into the symbolic totals, which costs a walk over expressions of the vehicle's size per
// entry). Before, every block was evaluated with a list of all 7N values (subs with a list
// matches every symbol against every relation in turn): 1,000 blocks took about a minute.
MassProperties derive_mass_properties(const Vehicle& v) {
  GenericBlock generic;
  MassProperties mp;
  mp.symbols.reserve(v.blocks.size());
  mp.blocks.reserve(v.blocks.size());
  TotalTerms sym, num;
  for (const Block& b : v.blocks) {
    const GenericBlock::Placed& placed = generic.placed(b.yaw_pitch_roll_deg);
    BlockSymbols s = make_symbols(b, placed.R);
    mp.blocks.push_back(contribution(b, generic, placed, s, mp, sym, num));
    mp.symbols.push_back(std::move(s));
  }
  const Totals t = totals(sym, true);
  mp.mass = t.mass;
  mp.cog = t.cog;
  mp.inertia_origin = t.inertia_origin;
  mp.inertia_cog = t.inertia_cog;
  mp.areas = t.areas;

  const Totals n = totals(num, false);
  mp.mass_value = to_double(n.mass);
  for (int i = 0; i < 3; ++i) {
    mp.cog_value[i] = to_double(n.cog(i, 0));
    mp.areas_value[i] = to_double(n.areas(i, 0));
  }
  mp.inertia_origin_value = to_mat3(n.inertia_origin);
  mp.inertia_cog_value = to_mat3(n.inertia_cog);
  return mp;
}

}  // namespace quadgen
