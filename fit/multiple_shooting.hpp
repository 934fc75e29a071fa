// Multiple-shooting residuals: the flight cut into short windows; each window starts from
// the measured state, the model is integrated over it with the logged commands (RK4 at
// the sample rate) and its predicted pose compared with the measured pose at every
// sample. Jacobians come from the forward sensitivities dx/dp integrated with the
// model's analytic Jacobians. Short windows keep the drift of open-loop replay bounded;
// the pose alone suffices (no IMU needed), but the state at each window start must be
// known (velocities and rates from the log or differentiated).
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "runtime/dynamic_model.hpp"
#include "fit/flight_data.hpp"
#include "fit/least_squares.hpp"

namespace quadgen::fit {

class MultipleShootingModel : public ResidualModel {
 public:
  MultipleShootingModel(runtime::DynamicModel& model, Flight flight, double window_seconds);
  int num_residuals() const override { return num_residuals_; }
  void evaluate(const double* p, double* r, double* J) const override { evaluate_free(p, r, J, {}); }
  void evaluate_free(const double* p, double* r, double* J, const std::vector<bool>& free) const override;
  int channel_of(int i) const override { return i % 6; }
  std::vector<std::string> channels() const override { return {"x", "y", "z", "roll_err", "pitch_err", "yaw_err"}; }
  size_t num_windows() const { return windows_.size(); }
  std::unique_ptr<ResidualModel> clone() const override;  // with its own copy of the dynamic model

 private:
  runtime::DynamicModel* model_;  // the caller's, or owned_model_ in a clone
  std::shared_ptr<runtime::DynamicModel> owned_model_;
  Flight flight_;
  std::vector<std::pair<size_t, size_t>> windows_;  // [first, last] sample indices
  int num_residuals_ = 0;
};

}  // namespace quadgen::fit
