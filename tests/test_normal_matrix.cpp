// The normal matrix J^T W J of a fit (fit::analyse_normal_matrix): standard errors and
// which parameters the data cannot determine, whatever the parameters' scales.
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include "fit/normal_matrix.hpp"

using quadgen::fit::analyse_normal_matrix;

namespace {
// J^T J of a Jacobian whose column j is scaled by 1 / scale[j] (a parameter of that size).
Eigen::MatrixXd normal_matrix(Eigen::MatrixXd J, const std::vector<double>& scale) {
  for (int j = 0; j < J.cols(); ++j) J.col(j) /= scale[static_cast<size_t>(j)];
  return J.transpose() * J;
}
}  // namespace

// Three well-determined parameters, one of them eight orders of magnitude smaller than the
// others (a blade-flapping coefficient beside winds): none is confounded, and the
// covariance is the inverse. On the unscaled matrix the small one's eigenvalue (1e16) made
// the others' look like zero.
TEST(NormalMatrix, ParametersOfVeryDifferentSizeAreAllDetermined) {
  Eigen::MatrixXd J(4, 3);
  J << 1, 0.5, 0, 0, 1, 0.2, 1, 0, 1, 0.3, 0.1, 0.4;
  const Eigen::MatrixXd H = normal_matrix(J, {1e-8, 1.0, 0.5});
  const auto a = analyse_normal_matrix(H);
  ASSERT_EQ(a.confounded.size(), 3u);
  for (bool c : a.confounded) EXPECT_FALSE(c);
  const Eigen::MatrixXd inv = H.inverse();
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(a.covariance(i, i) / inv(i, i), 1.0, 1e-9) << i;
  // The old test (raw eigenvalues against the largest) flags the two ordinary parameters.
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> raw(H);
  EXPECT_LT(raw.eigenvalues().minCoeff(), 1e-10 * raw.eigenvalues().maxCoeff());
}

// Two parameters that act only through their sum (a per-flight wind and a trim the flight
// cannot tell apart): both are confounded, the third is not.
TEST(NormalMatrix, ParametersActingOnlyTogetherAreConfounded) {
  Eigen::MatrixXd J(4, 3);
  J << 1, 1, 0.2, 2, 2, 0.1, 0.5, 0.5, 1, 1, 1, 0.3;
  const auto a = analyse_normal_matrix(normal_matrix(J, {1.0, 1e-3, 1e-8}));
  EXPECT_TRUE(a.confounded[0]);
  EXPECT_TRUE(a.confounded[1]);
  EXPECT_FALSE(a.confounded[2]);
}
