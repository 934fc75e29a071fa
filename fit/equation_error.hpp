// Equation-error residuals: at every logged sample, the model's accelerations evaluated at
// the measured state and commands against the measured ones: specific force from the
// accelerometer (or the derivative of the velocity), and the derivative of the gyro.
// Jacobians come from the model's analytic df/dp.
// Effects that act before the dynamics are applied to the data instead: input_delay shifts
// the logged commands, motor_lag filters the commanded rotor speeds into the rotor-speed
// states, attitude_bias turns the logged attitude back into the true one; their Jacobian
// columns are central differences of the residuals. Suits logs with good state estimates
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
  // Parameters applied to the data (-1 when the model lacks the effect).
  int lag_ = -1, delay_ = -1, roll_ = -1, pitch_ = -1;
  std::vector<int> speed_states_;  // w_<rotor> state of each rotor (motor_lag)
  mutable std::vector<bool> free_;
  std::vector<std::string> all_names() const;
  void evaluate6(const double* p, double* r, double* J) const;
  // Full model state and inputs of every sample (states row-major ns x n, inputs ns x nu).
  void prepare(const double* p, std::vector<double>& X, std::vector<double>& U) const;
  void commands_at(double t, double* u) const;  // rotor commands interpolated at t
  void residuals(const double* p, double* r, double* J) const;
};


}  // namespace quadgen::fit
