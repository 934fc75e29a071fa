// Thrust-stand measurements (Bitcraze's Crazyflie 2.1 stand): total thrust of the four
// rotors, each rotor's speed, the PWM command and the battery voltage.
//  - ThrustVsSpeed: T = b + sum_i k_i w_i^2, a thrust coefficient per motor plus the
//    scale's tare offset.
//  - SpeedVsCommand: mean rotor speed = (a0 + a1 u + a2 u^2) (vbat / vref)^e: the motor
//    map and how it scales with battery voltage (thrust then scales with (vbat/vref)^(2e),
//    the battery_sag effect's exponent).
#pragma once
#include <string>
#include <vector>

#include "least_squares.hpp"

namespace quadgen::fit {

struct StandSample {
  double thrust = 0;  // N, all four rotors
  double u = 0;       // PWM / 65535
  double vbat = 0;    // V
  double w[4] = {0, 0, 0, 0};  // rad/s
};

std::vector<StandSample> read_thrust_stand(const std::string& path);  // rows with PWM > 0

class ThrustVsSpeed : public ResidualModel {
 public:
  explicit ThrustVsSpeed(std::vector<StandSample> s) : s_(std::move(s)) {}
  int num_residuals() const override { return static_cast<int>(s_.size()); }
  void evaluate(const double* p, double* r, double* J) const override;
  int channel_of(int) const override { return 0; }
  std::vector<std::string> channels() const override { return {"thrust"}; }
  static std::vector<FitParameter> parameters();  // k_1..k_4 [N s^2], tare [N]

 private:
  std::vector<StandSample> s_;
};

class SpeedVsCommand : public ResidualModel {
 public:
  SpeedVsCommand(std::vector<StandSample> s, double vref) : s_(std::move(s)), vref_(vref) {}
  int num_residuals() const override { return static_cast<int>(s_.size()); }
  void evaluate(const double* p, double* r, double* J) const override;
  int channel_of(int) const override { return 0; }
  std::vector<std::string> channels() const override { return {"rotor_speed"}; }
  static std::vector<FitParameter> parameters();  // a0, a1, a2 [rad/s], e [1]

 private:
  std::vector<StandSample> s_;
  double vref_;
};

}  // namespace quadgen::fit
