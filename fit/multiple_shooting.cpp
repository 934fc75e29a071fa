#include "fit/multiple_shooting.hpp"

#include <cmath>

#include "runtime/integrator.hpp"
#include "runtime/rigid_body_state.hpp"

namespace quadgen::fit {

using namespace runtime::rigid_body;

MultipleShootingModel::MultipleShootingModel(runtime::DynamicModel& model, Flight flight, double window)
    : model_(&model), flight_(std::move(flight)) {
  if (!flight_.has_pose) throw FitError(flight_.source + ": multiple shooting needs the pose (x, y, z and qw..qz or phi, theta, psi)");
  if (model.num_states() != kNumStates)
    throw FitError("multiple shooting needs every state at the window starts; this model has unlogged states (" +
                   model.state_names()[kNumStates] + ")");
  const auto& s = flight_.samples;
  size_t start = 0;
  for (size_t k = 1; k <= s.size(); ++k) {
    const bool gap = k < s.size() && s[k].t - s[k - 1].t > 0.1;  // trimmed (on the ground) part
    if (k == s.size() || gap || s[k].t - s[start].t > window) {
      if (k - 1 > start) {
        windows_.push_back({start, k - 1});
        num_residuals_ += 6 * static_cast<int>(k - 1 - start);
      }
      start = k;
    }
  }
  if (windows_.empty()) throw FitError(flight_.source + ": flight shorter than one window");
}

void MultipleShootingModel::evaluate_free(const double* p, double* r, double* J, const std::vector<bool>& free) const {
  const int n = kNumStates, np = model_->num_params(), nu = model_->num_inputs();
  // The parameter columns to propagate through the sensitivities: the free ones, or all.
  std::vector<int> free_;
  if (J) {
    model_->restrict_param_jacobian(runtime::free_columns(free));
    free_ = runtime::jacobian_columns(free, np);
  }
  const int nf = static_cast<int>(free_.size()), cols = n + nf;
  model_->set_params(std::vector<double>(p, p + np));
  const runtime::ExtraInputs extra(*model_);
  int row = 0;
  for (const auto& [first, last] : windows_) {
    const auto& s = flight_.samples;
    // Inputs held from each sample to the next, as the flight controller applied them.
    runtime::InputFunction u = [&, first = first, last = last](double t, double* out) {
      size_t k = first;
      while (k < last && s[k + 1].t - s[first].t <= t + 1e-9) ++k;
      for (size_t i = 0; i < s[k].u.size(); ++i) out[i] = s[k].u[i];
      extra.fill(s[k].t, s[k].vbat, out);
      (void)nu;
    };
    runtime::IntegratorOptions o;
    o.quaternion_offset = -1;
    const double dt = (s[last].t - s[first].t) / static_cast<double>(last - first);
    o.step = dt;
    const auto tr = runtime::integrate_rk4_sensitivities(*model_, s[first].x, u, 0.0, s[last].t - s[first].t, o, &free_);
    for (size_t k = first + 1; k <= last; ++k, row += 6) {
      const auto& xp = tr.states.x[k - first];
      const auto& S = tr.S[k - first];
      const auto& xm = s[k].x;
      for (int i = 0; i < 3; ++i) r[row + i] = xp[kPosition + i] - xm[kPosition + i];
      // Attitude error: 2 vec(q_meas^-1 ⊗ q_pred), small angles about body axes.
      const double mw = xm[kAttitude], mx = -xm[kAttitude + 1], my = -xm[kAttitude + 2], mz = -xm[kAttitude + 3];
      // Rows of the linear map q_pred -> vec(q_meas^-1 ⊗ q_pred).
      const double L[3][4] = {{mx, mw, -mz, my}, {my, mz, mw, -mx}, {mz, -my, mx, mw}};
      for (int i = 0; i < 3; ++i) {
        double e = 0;
        for (int c = 0; c < 4; ++c) e += L[i][c] * xp[kAttitude + c];
        r[row + 3 + i] = 2 * e;
      }
      if (!J) continue;
      for (int i = 0; i < 6; ++i)
        for (int j = 0; j < np; ++j) J[static_cast<size_t>(row + i) * np + j] = 0;
      for (int f = 0; f < nf; ++f) {
        const int j = free_[f];
        for (int i = 0; i < 3; ++i) J[static_cast<size_t>(row + i) * np + j] = S[(kPosition + i) * cols + n + f];
        for (int i = 0; i < 3; ++i) {
          double d = 0;
          for (int c = 0; c < 4; ++c) d += L[i][c] * S[(kAttitude + c) * cols + n + f];
          J[static_cast<size_t>(row + 3 + i) * np + j] = 2 * d;
        }
      }
    }
  }
}

}  // namespace quadgen::fit

namespace quadgen::fit {

std::unique_ptr<ResidualModel> MultipleShootingModel::clone() const {
  std::shared_ptr<runtime::DynamicModel> own = model_->clone();
  if (!own) return nullptr;
  auto copy = std::make_unique<MultipleShootingModel>(*this);
  copy->owned_model_ = own;
  copy->model_ = own.get();
  return copy;
}

}  // namespace quadgen::fit
