// The thesis' motor step tests (Table 2): rotor speed sampled every ~100 ms while the
// throttle steps by 10 %. Model: steady state rpm(u) = a0 + a1 u + a2 u^2 (0 with the
// motor off) reached through a first-order lag of time constant tau. The instant of each
// step is unknown within the sample interval before the first sample that shows the new
// command; each gets its own bounded nuisance parameter rather than an assumed value.
#pragma once
#include <string>
#include <vector>

#include "fit/least_squares.hpp"

namespace quadgen::fit {

struct MotorStep {
  double t_before = 0;   // last sample with the old command [s]
  double t_first = 0;    // first sample with the new command [s]
  double u_old = 0, u_new = 0;
  std::vector<double> t, rpm;  // samples with the new command
};

std::vector<MotorStep> read_motor_steps(const std::string& path);

class MotorStepModel : public ResidualModel {
 public:
  explicit MotorStepModel(std::vector<MotorStep> steps);
  int num_residuals() const override { return n_; }
  void evaluate(const double* p, double* r, double* J) const override;
  int channel_of(int) const override { return 0; }
  std::vector<std::string> channels() const override { return {"rpm"}; }
  // a0, a1, a2 [rpm], tau [s], step_1..step_n [s after t_before]; nominal starting values.
  std::vector<FitParameter> parameters() const;
  static constexpr int kTau = 3;           // index of tau in parameters()
  static constexpr int kFirstStepTime = 4;  // index of step_1; step k is kFirstStepTime + k
  const std::vector<MotorStep>& steps() const { return steps_; }
  // Model rpm at time t within step k, for plots.
  double predict(const double* p, size_t k, double t) const;

 private:
  std::vector<MotorStep> steps_;
  int n_ = 0;
};

}  // namespace quadgen::fit
