// The Gauss-Newton normal matrix J^T W J of a fit's free parameters: the one place where
// covariances, standard errors and undetermined directions are read off it.
#pragma once
#include <vector>

#include <Eigen/Dense>

#include "fit/least_squares.hpp"

namespace quadgen::fit {

// The Jacobian of the weighted residuals (each row times its channel's weight) in the free
// parameters' columns only, in their order: J_w, with J_w^T J_w the normal matrix below (the
// fit's covariance and the diagnosis' standard errors both start here).
Eigen::MatrixXd weighted_free_jacobian(const ResidualModel& model, const std::vector<FitParameter>& params,
                                       const std::vector<double>& channel_weights);

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
