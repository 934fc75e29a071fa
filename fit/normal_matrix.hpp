// The Gauss-Newton normal matrix J^T W J of a fit's free parameters: the one place where
// covariances, standard errors and undetermined directions are read off it.
#pragma once
#include <vector>

#include <Eigen/Dense>

namespace quadgen::fit {

// Its pseudo-inverse (the covariance, for standard errors) and which parameters lie along a
// direction the data cannot determine (an eigenvalue of the unit-diagonal form near zero),
// computed on the matrix scaled to unit diagonal so that parameters of very different size
// do not hide one another.
struct NormalMatrixAnalysis {
  Eigen::MatrixXd covariance;
  std::vector<bool> confounded;
};
NormalMatrixAnalysis analyse_normal_matrix(const Eigen::MatrixXd& H);

// Whether the columns of a Jacobian, each scaled to unit length, are linearly dependent
// (column-pivoted QR, relative threshold 1e-10): some combination of the parameters is not
// determined at all, whatever the pseudo-inverse says. Scaled so that the answer does not
// depend on the parameters' units.
bool columns_dependent(const Eigen::MatrixXd& J);

}  // namespace quadgen::fit
