// Equation-error residuals: at every logged sample, the model's accelerations evaluated at
// the measured state and commands against the measured ones: specific force from the
// accelerometer (or the derivative of the velocity), and the derivative of the gyro.
// Jacobians come from the model's analytic df/dp. Suits logs with good state estimates
// and IMU data; it needs no integration and so cannot drift. (Multiple shooting, which
// compares integrated windows with the pose, is the other formulation; see README.)
#pragma once
#include <string>
#include <vector>

#include "dynamic_model.hpp"
#include "flight_data.hpp"
#include "least_squares.hpp"

namespace quadgen::fit {

class EquationErrorModel : public ResidualModel {
 public:
  // The model's parameters are the fit parameters; `use_accelerometer` picks specific
  // force (body) over differentiated velocity (world) for the translational channels.
  // `use` selects channels by name (empty: all six).
  EquationErrorModel(runtime::DynamicModel& model, Flight flight, bool use_accelerometer,
                     std::vector<std::string> use = {});
  int num_residuals() const override { return static_cast<int>(flight_.samples.size() * used_.size()); }
  void evaluate(const double* p, double* r, double* J) const override;
  int channel_of(int i) const override { return i % static_cast<int>(used_.size()); }
  std::vector<std::string> channels() const override;
  void set_free(const std::vector<bool>& free) const override;
  // Residuals of all six channels at sample k (for plots), after evaluate-able parameters.
  void all_channels(const double* p, std::vector<double>& r6) const;
  const Flight& flight() const { return flight_; }

 private:
  runtime::DynamicModel& model_;
  Flight flight_;
  bool accel_;
  int g_index_;
  std::vector<int> used_;  // indices into the six channels
  std::vector<std::string> all_names() const;
  void evaluate6(const double* p, double* r, double* J) const;
};


}  // namespace quadgen::fit
