// The generated headers: byte-identical to what the generator produces now, Jacobians
// against central finite differences and against ceres::Jet of the generated f itself,
// float against double, and independence from symbol creation order.
#include <gtest/gtest.h>

#include <ceres/jet.h>

#include <filesystem>
#include <fstream>
#include <random>

#include "dynamics.hpp"
#include "effects.hpp"
#include "generated/crazyflie21/model.hpp"
#include "generated/finken3/model.hpp"
#include "generated/finken3_all_effects/model.hpp"
#include "header_writer.hpp"
#include "test_helpers.hpp"

namespace fs = std::filesystem;
namespace gen = quadgen_generated;

namespace {

std::string read(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), {});
}

// A random but physical evaluation point for model M: unit quaternion, commands in range,
// parameters perturbed by up to ±20 % (effect parameters moved off zero).
template <class M>
struct Point {
  double x[M::kNumStates], u[M::kNumInputs], p[M::kNumParams];
};

template <typename Names, size_t N>
int index_of(const Names (&names)[N], const std::string& want) {
  for (size_t i = 0; i < N; ++i)
    if (want == names[i]) return static_cast<int>(i);
  return -1;
}

}  // namespace

#define QUADGEN_MODEL_TRAITS(NS)                                                            \
  struct NS##_traits {                                                                      \
    static constexpr int kNumStates = gen::NS::kNumStates;                                  \
    static constexpr int kNumInputs = gen::NS::kNumInputs;                                  \
    static constexpr int kNumParams = gen::NS::kNumParams;                                  \
    static constexpr int kDfdxNnz = gen::NS::kDfdxNnz;                                      \
    static constexpr int kDfdpNnz = gen::NS::kDfdpNnz;                                      \
    static constexpr int kDfduNnz = gen::NS::kDfduNnz;                                      \
    static constexpr const int* dfdx_row = gen::NS::kDfdxRow;                               \
    static constexpr const int* dfdx_col = gen::NS::kDfdxCol;                               \
    static constexpr const int* dfdp_row = gen::NS::kDfdpRow;                               \
    static constexpr const int* dfdp_col = gen::NS::kDfdpCol;                               \
    static constexpr const int* dfdu_row = gen::NS::kDfduRow;                               \
    static constexpr const int* dfdu_col = gen::NS::kDfduCol;                               \
    static constexpr const char* const* state_names = gen::NS::kStateNames;                 \
    static constexpr const char* const* input_names = gen::NS::kInputNames;                 \
    static constexpr const char* const* param_names = gen::NS::kParamNames;                 \
    static constexpr const double* nominal = gen::NS::kNominalParams;                       \
    template <typename S>                                                                   \
    static void f(const S* x, const S* u, const S* p, S* out, S* dx, S* du, S* dp) {        \
      gen::NS::Precomputed<S> pre;                                                          \
      gen::NS::precompute(p, &pre);                                                         \
      gen::NS::rhs(x, u, p, pre, out, dx, du, dp);                                          \
    }                                                                                       \
  };

QUADGEN_MODEL_TRAITS(finken3)
QUADGEN_MODEL_TRAITS(finken3_all_effects)
QUADGEN_MODEL_TRAITS(crazyflie21)

template <class M>
int index_of_param(const std::string& name) {
  for (int i = 0; i < M::kNumParams; ++i)
    if (name == M::param_names[i]) return i;
  return -1;
}

template <class M>
Point<M> random_point(std::mt19937& rng) {
  Point<M> pt;
  std::uniform_real_distribution<double> d(-1, 1);
  double n = 0;
  for (int i = 0; i < M::kNumStates; ++i) pt.x[i] = d(rng);
  pt.x[2] = 0.5 + std::fabs(pt.x[2]);  // above the ground (ground effect)
  for (int i = 6; i < 10; ++i) n += pt.x[i] * pt.x[i];
  for (int i = 6; i < 10; ++i) pt.x[i] /= std::sqrt(n);
  for (int i = 10; i < 13; ++i) pt.x[i] *= 3;
  for (int i = 13; i < M::kNumStates; ++i) pt.x[i] = 800 + 200 * d(rng);  // rotor speeds
  for (int i = 0; i < M::kNumInputs; ++i) {
    const std::string name = M::input_names[i];
    pt.u[i] = name == "t" ? 5 + 5 * d(rng) : name == "vbat" ? 3.9 + 0.2 * d(rng) : 0.5 + 0.3 * d(rng);
  }
  for (int i = 0; i < M::kNumParams; ++i) {
    const std::string name = M::param_names[i];
    double v = M::nominal[i] * (1 + 0.2 * d(rng));
    if (name.find('.') != std::string::npos) v = 0.01 + 0.01 * d(rng);  // effects off their neutral value
    if (name == "motor_lag.tau") v = 0.02 + 0.01 * d(rng);
    if (name == "ground_effect.radius") v = 0.06 + 0.01 * d(rng);
    if (name == "J_xy" || name == "J_xz" || name == "J_yz")  // products of inertia: 5 % of J_xx
      v = 0.05 * M::nominal[index_of_param<M>("J_xx")] * d(rng);
    if (name == "cog_x" || name == "cog_y") v = 2e-3 * d(rng);
    pt.p[i] = v;
  }
  return pt;
}

template <class M>
void check_jacobians_against_finite_differences(int trials) {
  std::mt19937 rng(42);
  for (int t = 0; t < trials; ++t) {
    Point<M> pt = random_point<M>(rng);
    double f[M::kNumStates], dfdx[M::kDfdxNnz + 1], dfdu[M::kDfduNnz + 1], dfdp[M::kDfdpNnz + 1];
    M::f(pt.x, pt.u, pt.p, f, dfdx, dfdu, dfdp);
    auto column = [&](double* v, int j, double h, double* out) {
      const double keep = v[j];
      double fp[M::kNumStates], fm[M::kNumStates];
      v[j] = keep + h;
      M::f(pt.x, pt.u, pt.p, fp, (double*)nullptr, (double*)nullptr, (double*)nullptr);
      v[j] = keep - h;
      M::f(pt.x, pt.u, pt.p, fm, (double*)nullptr, (double*)nullptr, (double*)nullptr);
      v[j] = keep;
      for (int i = 0; i < M::kNumStates; ++i) out[i] = (fp[i] - fm[i]) / (2 * h);
    };
    auto compare = [&](double* v, int n, const double* J, int nnz, const int* row, const int* col, const char* what) {
      for (int j = 0; j < n; ++j) {
        double fd[M::kNumStates];
        const double h = 1e-6 * std::fmax(std::fabs(v[j]), 1e-3);  // relative step; floor for values near 0
        column(v, j, h, fd);
        for (int i = 0; i < M::kNumStates; ++i) {
          double an = 0;
          for (int k = 0; k < nnz; ++k)
            if (row[k] == i && col[k] == j) an = J[k];
          // Central differences: truncation ~ h^2 f''' and rounding ~ eps |f| / h.
          const double scale = 1 + std::fabs(an) + std::fabs(f[i]);
          EXPECT_NEAR(an, fd[i], 2e-5 * scale) << what << " d f[" << i << "] / d " << j;
        }
      }
    };
    compare(pt.x, M::kNumStates, dfdx, M::kDfdxNnz, M::dfdx_row, M::dfdx_col, "dfdx");
    compare(pt.u, M::kNumInputs, dfdu, M::kDfduNnz, M::dfdu_row, M::dfdu_col, "dfdu");
    compare(pt.p, M::kNumParams, dfdp, M::kDfdpNnz, M::dfdp_row, M::dfdp_col, "dfdp");
  }
}

// Forward-mode automatic differentiation of the generated f: exact to rounding, so the
// analytic Jacobians must agree to 1e-8 relative.
template <class M>
void check_jacobians_against_jets(int trials) {
  constexpr int N = M::kNumStates + M::kNumInputs + M::kNumParams;
  using Jet = ceres::Jet<double, N>;
  std::mt19937 rng(7);
  for (int t = 0; t < trials; ++t) {
    Point<M> pt = random_point<M>(rng);
    Jet x[M::kNumStates], u[M::kNumInputs], p[M::kNumParams], f[M::kNumStates];
    for (int i = 0; i < M::kNumStates; ++i) x[i] = Jet(pt.x[i], i);
    for (int i = 0; i < M::kNumInputs; ++i) u[i] = Jet(pt.u[i], M::kNumStates + i);
    for (int i = 0; i < M::kNumParams; ++i) p[i] = Jet(pt.p[i], M::kNumStates + M::kNumInputs + i);
    M::f(x, u, p, f, (Jet*)nullptr, (Jet*)nullptr, (Jet*)nullptr);
    double fv[M::kNumStates], dfdx[M::kDfdxNnz + 1], dfdu[M::kDfduNnz + 1], dfdp[M::kDfdpNnz + 1];
    M::f(pt.x, pt.u, pt.p, fv, dfdx, dfdu, dfdp);
    // Dense analytic Jacobian; every structural zero must be an exact zero of the jet too.
    std::vector<double> dense(M::kNumStates * N, 0.0);
    for (int k = 0; k < M::kDfdxNnz; ++k) dense[M::dfdx_row[k] * N + M::dfdx_col[k]] = dfdx[k];
    for (int k = 0; k < M::kDfduNnz; ++k) dense[M::dfdu_row[k] * N + M::kNumStates + M::dfdu_col[k]] = dfdu[k];
    for (int k = 0; k < M::kDfdpNnz; ++k)
      dense[M::dfdp_row[k] * N + M::kNumStates + M::kNumInputs + M::dfdp_col[k]] = dfdp[k];
    for (int i = 0; i < M::kNumStates; ++i) {
      EXPECT_NEAR(f[i].a, fv[i], 1e-12 * (1 + std::fabs(fv[i])));
      for (int j = 0; j < N; ++j) {
        const double want = f[i].v[j], got = dense[i * N + j];
        EXPECT_NEAR(got, want, 1e-8 * (1 + std::fabs(want))) << "f[" << i << "] / var " << j;
      }
    }
  }
}

TEST(Generated, Finken3JacobiansMatchFiniteDifferences) { check_jacobians_against_finite_differences<finken3_traits>(20); }
TEST(Generated, AllEffectsJacobiansMatchFiniteDifferences) {
  check_jacobians_against_finite_differences<finken3_all_effects_traits>(20);
}
TEST(Generated, CrazyflieJacobiansMatchFiniteDifferences) {
  check_jacobians_against_finite_differences<crazyflie21_traits>(20);
}
TEST(Generated, Finken3JacobiansMatchJets) { check_jacobians_against_jets<finken3_traits>(50); }
TEST(Generated, AllEffectsJacobiansMatchJets) { check_jacobians_against_jets<finken3_all_effects_traits>(50); }
TEST(Generated, CrazyflieJacobiansMatchJets) { check_jacobians_against_jets<crazyflie21_traits>(50); }

TEST(Generated, MatchesSymbolicModel) {
  // The emitted f equals the GiNaC f it came from, at random points with nominal parameters.
  const quadgen::Vehicle v = quadgen::test::finken3();
  const quadgen::SymbolicModel m = quadgen::derive_model(v, quadgen::derive_mass_properties(v), {});
  std::mt19937 rng(5);
  for (int t = 0; t < 5; ++t) {
    std::vector<double> x = quadgen::test::random_state(rng);
    std::vector<double> u{0.3, 0.45, 0.5, 0.62};
    const auto want = quadgen::test::eval_f(m, x, u);
    double f[13];
    finken3_traits::f(x.data(), u.data(), gen::finken3::kNominalParams, f, (double*)nullptr, (double*)nullptr,
                      (double*)nullptr);
    for (int i = 0; i < 13; ++i) EXPECT_NEAR(f[i], want[i], 1e-12 * (1 + std::fabs(want[i]))) << i;
  }
}

TEST(Generated, NullJacobianPointersGiveTheSameF) {
  std::mt19937 rng(9);
  auto pt = random_point<finken3_all_effects_traits>(rng);
  double f1[finken3_all_effects_traits::kNumStates], f2[finken3_all_effects_traits::kNumStates];
  double dx[finken3_all_effects_traits::kDfdxNnz];
  finken3_all_effects_traits::f(pt.x, pt.u, pt.p, f1, dx, (double*)nullptr, (double*)nullptr);
  finken3_all_effects_traits::f(pt.x, pt.u, pt.p, f2, (double*)nullptr, (double*)nullptr, (double*)nullptr);
  for (int i = 0; i < finken3_all_effects_traits::kNumStates; ++i) EXPECT_EQ(f1[i], f2[i]);
}

// The checked-in generated/ is what the generator produces now (update: scripts/regenerate.sh).
TEST(Generated, CheckedInHeadersAreUpToDate) {
  const fs::path tmp = fs::temp_directory_path() / "quadgen_golden";
  fs::remove_all(tmp);
  const std::string src = QUADGEN_SOURCE_DIR;
  const struct {
    const char* vehicle;
    const char* name;
    const char* effects;
  } cases[] = {{"vehicles/finken3.yaml", "finken3", ""},
               {"vehicles/finken3.yaml", "finken3_all_effects", "all"},
               {"vehicles/crazyflie21.yaml", "crazyflie21", ""},
               {"vehicles/crazyflie21.yaml", "crazyflie21_all_effects", "all"}};
  for (const auto& c : cases) {
    std::string cmd = "cd " + src + " && " + QUADGEN_BINARY + " derive " + c.vehicle + " --out " +
                      (tmp / c.name).string() + (std::string(c.effects).empty() ? "" : std::string(" --effects ") + c.effects) +
                      " > /dev/null 2>&1";
    ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
    const std::string now = read(tmp / c.name / "model.hpp");
    const std::string checked_in = read(fs::path(src) / "generated" / c.name / "model.hpp");
    ASSERT_FALSE(now.empty());
    EXPECT_TRUE(now == checked_in) << "generated/" << c.name
                                   << "/model.hpp is stale or was edited; run scripts/regenerate.sh";
  }
}

// Symbols created in a different order (which changes GiNaC's internal term order) and
// a different process must not change a byte.
TEST(Generated, IndependentOfSymbolCreationOrder) {
  std::vector<GiNaC::symbol> noise;
  for (const char* n : {"r", "q", "p", "qz", "qy", "qx", "qw", "vz", "vy", "vx", "z", "y", "x", "u_D", "u_C", "mass"})
    noise.emplace_back(n);
  GiNaC::ex junk = 0;
  for (auto& s : noise) junk += s * s;  // touch them so they are really allocated first
  const quadgen::Vehicle v = quadgen::test::finken3();
  quadgen::DeriveOptions o;
  o.effects = quadgen::parse_effect_list("all");
  const quadgen::SymbolicModel m = quadgen::derive_model(v, quadgen::derive_mass_properties(v), o);
  quadgen::emission::EmitOptions eo;
  eo.vehicle_file = "vehicles/finken3.yaml";
  eo.effects_flag = " --effects all";
  const std::string text = quadgen::emission::generate_header(m, eo).content;
  EXPECT_TRUE(text == read(fs::path(QUADGEN_SOURCE_DIR) / "generated/finken3_all_effects/model.hpp"));
}

// The hand-written reference (bench/reference_model.hpp) is an independent writing of the
// same physics; it must agree with the generated f everywhere, products of inertia and
// CoG offsets included.
#include "reference_model.hpp"
TEST(Generated, AgreesWithHandWrittenReferenceModel) {
  std::mt19937 rng(21);
  const auto layout = quadgen::reference::finken3_layout();
  for (int t = 0; t < 100; ++t) {
    auto pt = random_point<finken3_traits>(rng);
    double fg[13], fr[13];
    finken3_traits::f(pt.x, pt.u, pt.p, fg, (double*)nullptr, (double*)nullptr, (double*)nullptr);
    quadgen::reference::reference_rhs(pt.x, pt.u, pt.p, layout, fr);
    for (int i = 0; i < 13; ++i) EXPECT_NEAR(fg[i], fr[i], 1e-10 * (1 + std::fabs(fr[i]))) << i;
  }
}
