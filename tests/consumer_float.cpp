// A consumer that sees only a generated header: built with -O2 -Wall -Wextra -Werror
// -Wdouble-promotion -Wconversion (see tests/CMakeLists.txt), instantiated for float and
// double; exits non-zero if float disagrees with double beyond float precision, at 1.2 m, at
// the old pole of the ground-effect law (z = R / 4) and on the ground, where float must stay
// finite, with the effect on (R = 6 cm) and off (R = 0: its derivatives' largest power there
// is set by the law's floor).
#include <cmath>
#include <cstdio>
#include <initializer_list>

#include "generated/finken3_all_effects/model.hpp"
#include "same_model_elsewhere/model.hpp"  // a copy at another path: one model (its include guard)

namespace m = quadgen_generated::finken3_all_effects;

template <typename S>
void evaluate(const double* xd, const double* ud, double radius, S* f, S* dfdx, S* dfdp) {
  S x[m::kNumStates], u[m::kNumInputs], p[m::kNumParams];
  for (int i = 0; i < m::kNumStates; ++i) x[i] = static_cast<S>(xd[i]);
  for (int i = 0; i < m::kNumInputs; ++i) u[i] = static_cast<S>(ud[i]);
  for (int i = 0; i < m::kNumParams; ++i) p[i] = static_cast<S>(m::kNominalParams[i]);
  p[m::Param::motor_lag_tau] = static_cast<S>(0.03);
  p[m::Param::ground_effect_radius] = static_cast<S>(radius);
  m::Precomputed<S> pre;
  m::precompute(p, &pre);
  m::rhs(x, u, p, pre, f, dfdx, static_cast<S*>(nullptr), dfdp);
  S h[m::kNumOutputs];
  m::measurement(x, p, pre, h, static_cast<S*>(nullptr), static_cast<S*>(nullptr));
}

int main() {
  double x[m::kNumStates] = {0.1, -0.2, 1.2, 0.5, -0.3, 0.1, 0.98, 0.1, -0.1, 0.1, 0.4, -0.2, 0.3};
  const double qn = std::sqrt(0.98 * 0.98 + 0.03);
  for (int i = 6; i < 10; ++i) x[i] /= qn;
  for (int i = 13; i < m::kNumStates; ++i) x[i] = 900.0 + 10.0 * i;
  double u[m::kNumInputs] = {0.4, 0.45, 0.5, 0.42, 3.0, 3.9};
  double fd[m::kNumStates], Jd[m::kDfdxStorage], Pd[m::kDfdpStorage];
  float ff[m::kNumStates], Jf[m::kDfdxStorage], Pf[m::kDfdpStorage];
  int bad = 0;
  double z = 0, radius = 0;
  auto check = [&](const double* d, const float* f, int n, const char* what) {
    double scale = 0;
    for (int i = 0; i < n; ++i) scale = std::fmax(scale, std::fabs(d[i]));
    for (int i = 0; i < n; ++i)
      if (!std::isfinite(f[i]) || std::fabs(static_cast<double>(f[i]) - d[i]) > 1e-4 * (std::fabs(d[i]) + 1e-3 * scale)) {
        std::printf("R = %g m, z = %g m, %s[%d]: float %g vs double %g\n", radius, z, what, i, static_cast<double>(f[i]), d[i]);
        ++bad;
      }
  };
  for (const double r : {0.06, 0.0})
    for (const double height : {1.2, 0.06 / 4, 1e-4, 0.0}) {
      radius = r;
      x[2] = z = height;
      evaluate<double>(x, u, radius, fd, Jd, Pd);
      evaluate<float>(x, u, radius, ff, Jf, Pf);
      check(fd, ff, m::kNumStates, "f");
      check(Jd, Jf, m::kDfdxNnz, "dfdx");
      check(Pd, Pf, m::kDfdpNnz, "dfdp");
    }
  std::printf("float vs double: %d mismatches\n", bad);
  return bad == 0 ? 0 : 1;
}
