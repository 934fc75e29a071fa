// Thrust-stand measurements (the layout of Bitcraze's Crazyflie 2.1 stand, weight[g], pwm,
// vbat[V], rpm1..rpmN): total thrust of the N rotors on the stand, each rotor's speed, the
// PWM command and the battery voltage.
//  - ThrustVsSpeed: T = b + sum_i k_i w_i^2, a thrust coefficient per motor plus the
//    scale's tare offset; or T = b + k sum_i w_i^2, one coefficient for all, which is all
//    that total thrust determines when the motors run at nearly the same speed.
//  - SpeedVsCommand: mean rotor speed = (a0 + a1 u + a2 u^2) (vbat / vref)^e: the motor
//    map and how it scales with battery voltage (thrust then scales with (vbat/vref)^(2e),
//    the battery_sag effect's exponent).
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "fit/least_squares.hpp"
#include "fit/profile_likelihood.hpp"

namespace quadgen::fit {

struct StandSample {
  double thrust = 0;      // N, all the logged rotors together
  double u = 0;           // PWM / 65535
  double vbat = 0;        // V
  std::vector<double> w;  // rad/s, each logged rotor (rpm1..rpmN)
  double mean_speed() const;
  double sum_of_squared_speeds() const;
};

// Rows with PWM > 0; as many rotors as the file has consecutive columns rpm1, rpm2, ...
std::vector<StandSample> read_thrust_stand(const std::string& path);

// How independently the motors' speeds moved: RMS over motors of the standard deviation,
// over samples, of each motor's speed relative to the motors' mean. Total thrust
// separates per-motor coefficients only through this variation (a constant ratio makes
// the columns w_i^2 proportional).
double motor_speed_ratio_variation(const std::vector<StandSample>& s);

class ThrustVsSpeed : public ResidualModel {
 public:
  enum class Coefficients { kPerMotor, kShared };
  explicit ThrustVsSpeed(std::vector<StandSample> s, Coefficients c = Coefficients::kPerMotor)
      : s_(std::move(s)), c_(c) {}
  int num_residuals() const override { return static_cast<int>(s_.size()); }
  void evaluate(const double* p, double* r, double* J) const override;
  int channel_of(int) const override { return 0; }
  std::vector<std::string> channels() const override { return {"thrust"}; }
  std::unique_ptr<ResidualModel> clone() const override { return std::make_unique<ThrustVsSpeed>(*this); }
  // Per motor: k_1..k_N [N s^2], tare [N]. Shared: k [N s^2], tare [N]. Started at the
  // shared coefficient the data give in closed form, bounded a thousandfold either side of
  // it, so that a stand of any size starts near its answer.
  std::vector<FitParameter> parameters() const;
  size_t motors() const { return s_.front().w.size(); }

 private:
  std::vector<StandSample> s_;
  Coefficients c_;
};

class SpeedVsCommand : public ResidualModel {
 public:
  SpeedVsCommand(std::vector<StandSample> s, double vref) : s_(std::move(s)), vref_(vref) {}
  int num_residuals() const override { return static_cast<int>(s_.size()); }
  void evaluate(const double* p, double* r, double* J) const override;
  int channel_of(int) const override { return 0; }
  std::vector<std::string> channels() const override { return {"rotor_speed"}; }
  std::unique_ptr<ResidualModel> clone() const override { return std::make_unique<SpeedVsCommand>(*this); }
  static std::vector<FitParameter> parameters();  // a0, a1, a2 [rad/s], e [1]

 private:
  std::vector<StandSample> s_;
  double vref_;
};

// What a stand run determines, fitted so that no reported value sits on a bound or rests
// on an open profile:
//  - thrust: per-motor coefficients when every one is identifiable, else one coefficient
//    shared by all (total thrust fixes only the sum when the speeds barely differ);
//  - rotor speed: the motor map with the voltage exponent when it is identifiable, else
//    without it (the voltage then varied only with the load, confounded with the command).
struct StandFit {
  ThrustVsSpeed::Coefficients coefficients = ThrustVsSpeed::Coefficients::kPerMotor;
  FitResult thrust;
  std::vector<Profile> thrust_profiles;
  FitResult per_motor;  // the per-motor attempt (kept for the report when it was rejected)
  std::vector<Profile> per_motor_profiles;
  std::string coefficients_reason;  // why shared, empty when per motor
  FitResult speed;
  std::vector<Profile> speed_profiles;
  bool voltage_exponent_identified = true;
  std::string voltage_reason;  // why the exponent was left out, empty when fitted
  double ratio_variation = 0;  // motor_speed_ratio_variation of the run
};

StandFit fit_stand(const std::vector<StandSample>& samples, double vref, const FitOptions& fo, const ProfileOptions& po);

}  // namespace quadgen::fit
