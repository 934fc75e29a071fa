#include "fit/normal_matrix.hpp"

#include <algorithm>
#include <cmath>

namespace quadgen::fit {

Eigen::MatrixXd weighted_free_jacobian(const ResidualModel& model, const std::vector<FitParameter>& params,
                                       const std::vector<double>& channel_weights) {
  const size_t nr = static_cast<size_t>(model.num_residuals());
  std::vector<int> free;
  for (size_t i = 0; i < params.size(); ++i)
    if (params[i].free) free.push_back(static_cast<int>(i));
  const size_t nf = free.size();
  std::vector<double> r(nr), J(nr * nf);
  if (nf > 0) model.evaluate_columns(parameter_values(params), r.data(), J.data(), free);
  Eigen::MatrixXd Jw(static_cast<Eigen::Index>(nr), static_cast<Eigen::Index>(nf));
  for (size_t i = 0; i < nr; ++i)
    for (size_t k = 0; k < nf; ++k)
      Jw(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(k)) =
          J[i * nf + k] * channel_weights[model.channel_of(static_cast<int>(i))];
  return Jw;
}

NormalMatrixAnalysis analyse_normal_matrix(const Eigen::MatrixXd& H) {
  // Scaled to unit diagonal first (the correlation form): the parameters' scales differ by
  // many orders of magnitude (blade_flapping.k ~ 1e-8 N s^2 beside a wind of 1 m/s, a motor
  // map term of 1e3 rad/s), and on the raw matrix every well-determined direction of a
  // small-scale parameter made the eigenvalues of all the others look near zero beside it
  // - a joint diagnosis then found every flight's wind and motor gains "confounded" and
  // named nothing, and a pseudo-inverse with a relative cut-off dropped a weak direction
  // and reported a standard error near zero for it.
  const Eigen::Index n = H.rows();
  NormalMatrixAnalysis out;
  out.covariance = Eigen::MatrixXd::Zero(n, n);
  out.confounded.assign(static_cast<size_t>(n), false);
  if (n == 0) return out;
  Eigen::VectorXd scale(n);
  for (Eigen::Index a = 0; a < n; ++a) scale(a) = H(a, a) > 0 ? 1 / std::sqrt(H(a, a)) : 0.0;
  const Eigen::MatrixXd Hs = scale.asDiagonal() * H * scale.asDiagonal();
  out.covariance = scale.asDiagonal() * Hs.completeOrthogonalDecomposition().pseudoInverse() * scale.asDiagonal();
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(Hs);
  for (Eigen::Index k = 0; k < n; ++k)
    if (eig.eigenvalues()(k) <= 1e-10 * std::max(1.0, eig.eigenvalues().maxCoeff()))
      for (Eigen::Index a = 0; a < n; ++a)
        if (std::abs(eig.eigenvectors()(a, k)) > 0.1) out.confounded[static_cast<size_t>(a)] = true;
  for (Eigen::Index a = 0; a < n; ++a)
    if (scale(a) == 0) out.confounded[static_cast<size_t>(a)] = true;  // a parameter the data do not touch
  return out;
}

bool columns_dependent(const Eigen::MatrixXd& J) {
  Eigen::MatrixXd Js = J;
  for (Eigen::Index k = 0; k < Js.cols(); ++k)
    if (const double norm = Js.col(k).norm(); norm > 0) Js.col(k) /= norm;
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(Js);
  qr.setThreshold(1e-10);
  return qr.rank() < Js.cols();
}

}  // namespace quadgen::fit
