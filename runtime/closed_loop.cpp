#include "runtime/closed_loop.hpp"

#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <sstream>

#include <Eigen/Dense>

#include "output/numbers.hpp"
#include "runtime/allocation_matrix.hpp"
#include "runtime/attitude.hpp"
#include "runtime/integrator.hpp"
#include "runtime/portable_random.hpp"
#include "runtime/rigid_body_state.hpp"

namespace quadgen::runtime {

namespace {

using V3 = Eigen::Vector3d;
using M3 = Eigen::Matrix3d;
using namespace rigid_body;

// The three states from `first` (kPosition, kVelocity, kBodyRate) as a vector.
V3 vec3_at(const std::vector<double>& x, int first) { return V3(x[first], x[first + 1], x[first + 2]); }

// Smooth random reference: a sum of a few sinusoids per axis, with its derivatives.
struct Reference {
  struct Wave {
    double a, w, phase;
  };
  std::vector<Wave> axis[4];  // x, y, z, yaw
  double offset[4] = {0, 0, 0, 0};
  Reference(const ClosedLoopOptions& o, std::mt19937& rng) {
    const UniformReal freq(0.08, 0.35), ph(0, 2 * M_PI);
    const double amp[4] = {o.amplitude, o.amplitude, o.height_amplitude, o.yaw_amplitude};
    offset[2] = o.height;
    for (int a = 0; a < 4; ++a)
      for (int k = 0; k < 3; ++k) axis[a].push_back({amp[a] / 3.0, 2 * M_PI * freq(rng), ph(rng)});
  }
  // value, first and second derivative; faded in over the first seconds from rest.
  void at(double t, int a, double out[3]) const {
    // Quintic smoothstep: the reference's acceleration (and so the commands) stays
    // continuous when the fade ends.
    const double T = 3.0, s = t < T ? t / T : 1.0;
    const double fade = s * s * s * (10 - 15 * s + 6 * s * s),
                 dfade = t < T ? 30 * s * s * (1 - s) * (1 - s) / T : 0.0,
                 ddfade = t < T ? 60 * s * (1 - s) * (1 - 2 * s) / (T * T) : 0.0;
    double v = 0, dv = 0, ddv = 0;
    for (const auto& w : axis[a]) {
      v += w.a * (std::sin(w.w * t + w.phase) - std::sin(w.phase));
      dv += w.a * w.w * std::cos(w.w * t + w.phase);
      ddv -= w.a * w.w * w.w * std::sin(w.w * t + w.phase);
    }
    out[0] = offset[a] + fade * v;
    out[1] = dfade * v + fade * dv;
    out[2] = ddfade * v + 2 * dfade * dv + fade * ddv;
  }
};

V3 vee(const M3& S) { return V3(S(2, 1), S(0, 2), S(1, 0)); }

}  // namespace

std::vector<std::array<double, 4>> allocation_columns(const ControllerModel& b) {
  std::vector<std::array<double, 4>> columns;
  for (size_t i = 0; i < b.rotor_x.size(); ++i)
    columns.push_back({1.0, b.rotor_y[i], -b.rotor_x[i], -b.spin[i] * b.kappa});
  return columns;
}

namespace {

// The least-norm thrusts for the wrench w, the rotors not `free` held at their `least` thrust.
Eigen::VectorXd trim_with(const Eigen::MatrixXd& A, const std::vector<bool>& free, const Eigen::VectorXd& least,
                          const Eigen::Vector4d& w) {
  Eigen::MatrixXd open = A;
  Eigen::Vector4d rest = w;
  for (Eigen::Index i = 0; i < A.cols(); ++i)
    if (!free[static_cast<size_t>(i)]) {
      rest -= A.col(i) * least(i);
      open.col(i).setZero();
    }
  Eigen::VectorXd F = open.completeOrthogonalDecomposition().solve(rest);
  for (Eigen::Index i = 0; i < A.cols(); ++i)
    if (!free[static_cast<size_t>(i)]) F(i) = least(i);
  return F;
}

}  // namespace

std::vector<double> allocate(const ControllerModel& b, double thrust, const std::array<double, 3>& torque) {
  const Eigen::Vector4d w(thrust, torque[0], torque[1], torque[2]);
  const Eigen::VectorXd F = allocation_matrix(b).completeOrthogonalDecomposition().solve(w);
  return std::vector<double>(F.data(), F.data() + F.size());
}

namespace {
// Why the least-norm trim (balancing, but asking some rotor for less than its command 0 gives)
// had no alternative: names the rotor furthest below its least and where the CoG must lie.
// A thrust within rounding of 0 (a rotor the trim does not need: 1e-17 N either side) is 0,
// not a pull.
std::string why_no_trim_above_least(const Eigen::VectorXd& least_norm, const Eigen::VectorXd& least,
                                    const std::vector<std::string>& rotor_names, double weight,
                                    bool idle_lifts_weight) {
  Eigen::Index k = 0;
  (least_norm - least).minCoeff(&k);
  const bool pulls = least_norm(k) < -1e-9 * weight;
  const double asked = pulls ? least_norm(k) : std::max(least_norm(k), 0.0);
  // Six digits, as ThrustLaw::command_for's messages (which keep their own printer: that
  // header is dependency-free): a reader adds the thrusts up against the weight by eye.
  const auto newtons = [](double f) { return output::six_digits(f) + " N"; };
  const std::string what =
      pulls ? " would have to pull down " + newtons(-asked)
            : " would have to give " + newtons(asked) + ", less than its motor map gives at command 0 (" +
                  newtons(least(k)) + ")";
  if (idle_lifts_weight)
    return "rotor " + rotor_names[static_cast<size_t>(k)] + what + " (at command 0 the rotors give " +
           newtons(least.sum()) + " in all, the weight is " + newtons(weight) +
           ": " + kRpmWithoutUnit + "; or c_t too large?)";
  const std::string where =
      least_norm.size() > static_cast<Eigen::Index>(kExactTrimRotors)
          ? " (with more than " + std::to_string(kExactTrimRotors) +
                " rotors: no other trim was found, holding such rotors at command 0 in turn)"
      : least_norm.size() > 4 ? " (nor with any set of rotors held at command 0: no trim keeps every rotor within reach)"
      : pulls               ? " (the centre of gravity lies outside the rotors)"
                            : " (the centre of gravity lies too far towards the other rotors)";
  return "rotor " + rotor_names[static_cast<size_t>(k)] + what + where;
}
}  // namespace

namespace {

// The hover trim's problem: thrusts F (one per rotor) with A F = (weight, 0, 0, 0), each
// between the least a rotor gives (its thrust at command 0: a motor map with a0 > 0 idles
// above 0 N) and the most (at command 1).
struct TrimProblem {
  explicit TrimProblem(const ControllerModel& b) : A(allocation_matrix(b)), least(A.cols()), most(A.cols()) {
    weight = b.mass * b.g;
    w = Eigen::Vector4d(weight, 0, 0, 0);
    for (Eigen::Index i = 0; i < A.cols(); ++i) {
      const ThrustLaw& l = b.thrust_laws[static_cast<size_t>(i)];
      least(i) = l.thrust_at_command(0.0);
      most(i) = l.thrust_at_command(1.0);
    }
  }
  // stableNorm: a weight of 1e300 N squared overflows, and norm() then said no thrusts balance
  // it (a review, helper-88).
  bool balances(const Eigen::VectorXd& F) const { return (A * F - w).stableNorm() <= 1e-6 * weight; }
  bool above_least(const Eigen::VectorXd& F) const { return balances(F) && (F - least).minCoeff() >= -1e-12 * weight; }
  bool within_reach(const Eigen::VectorXd& F) const { return above_least(F) && (most - F).minCoeff() >= -1e-12 * weight; }
  Eigen::VectorXd trim(const std::vector<bool>& free) const { return trim_with(A, free, least, w); }

  Eigen::MatrixXd A;
  Eigen::VectorXd least, most;
  Eigen::Vector4d w;
  double weight = 0;
};

// Every set of rotors held at their least in turn, the others trimmed with least norm: of
// those trims, the least-norm one with every rotor within reach (commands 0 to 1). That is
// the least-norm trim within reach where only command 0 binds (a KKT point of the least-norm
// problem holds its active rotors at their least); where command 1 binds too, a trim within
// reach is still found if holding rotors at command 0 gives one. (2^n - 1 small solves; a
// greedy choice of the set missed trims.) F and free are left as they are where none is.
void search_held_sets(const TrimProblem& P, Eigen::VectorXd& F, std::vector<bool>& free) {
  const size_t n = free.size();
  double best = std::numeric_limits<double>::infinity();
  for (unsigned held = 1; held < (1u << n); ++held) {
    std::vector<bool> f(n);
    for (size_t i = 0; i < n; ++i) f[i] = !(held >> i & 1u);
    const Eigen::VectorXd candidate = P.trim(f);
    if (P.within_reach(candidate) && candidate.stableNorm() < best) best = candidate.stableNorm(), F = candidate, free = f;
  }
}

// Holds the rotor furthest below its least at its least, and trims the others again, until
// every rotor is above its least (or no free rotor is left below it).
void hold_shortfalls(const TrimProblem& P, Eigen::VectorXd& F, std::vector<bool>& free) {
  Eigen::Index short_most = 0;
  while (P.balances(F) && (F - P.least).minCoeff(&short_most) < -1e-12 * P.weight && free[static_cast<size_t>(short_most)]) {
    free[static_cast<size_t>(short_most)] = false;
    F = P.trim(free);
  }
}

}  // namespace


HoverTrim hover_trim(const ControllerModel& b, const std::vector<std::string>& rotor_names) {
  const TrimProblem P(b);
  if (!std::isfinite(P.weight) || !std::isfinite(P.least.sum()) || !std::isfinite(P.most.sum())) {
    HoverTrim t;  // a mass or motor map beyond a double (a review: 1.7e308 kg said "no thrusts balance")
    t.why_not = !std::isfinite(P.weight) ? "the weight m g is not a finite number (mass " + output::six_digits(b.mass) + " kg)"
                                         : "a motor map's thrust at command 0 or 1 is not a finite number";
    return t;
  }
  const size_t n = static_cast<size_t>(P.A.cols());
  const double even = P.weight / static_cast<double>(n);
  std::vector<bool> free(n, true);
  const Eigen::VectorXd least_norm = P.trim(free);
  Eigen::VectorXd F = least_norm;
  if (!P.within_reach(F) && n <= kExactTrimRotors)
    search_held_sets(P, F, free);
  else if (!P.above_least(F))
    hold_shortfalls(P, F, free);
  HoverTrim t;
  t.idle_lifts_weight = P.least.sum() >= P.weight;
  // Where no trim is within reach but the least-norm one is above every least, the rotor
  // beyond its command 1 is named below (command_for), as before the search.
  const bool reachable_below = P.above_least(F);
  if (!reachable_below) F = least_norm;
  t.thrusts.assign(F.data(), F.data() + F.size());
  if ((F.array() - even).abs().maxCoeff() <= 1e-9 * even) t.thrusts.assign(n, even);  // symmetric: exact
  if (!P.balances(least_norm)) {
    t.why_not = "no thrusts balance the weight without a moment";
  } else if (!reachable_below) {
    t.why_not = why_no_trim_above_least(least_norm, P.least, rotor_names, P.weight, t.idle_lifts_weight);
  }
  for (size_t i = 0; t.found() && i < n; ++i) try {
      t.commands.push_back(free[i] ? b.thrust_laws[i].command_for(t.thrusts[i]) : 0.0);  // held: command 0
    } catch (const std::invalid_argument& e) {
      t.why_not = "rotor " + rotor_names[i] + ": " + e.what() + "; check the masses, c_t and the motor map's a0, a1, a2";
      t.commands.clear();
    }
  return t;
}

std::string GeneratedFlight::csv() const {
  std::ostringstream os;
  os.precision(10);
  for (size_t i = 0; i < columns.size(); ++i) os << (i ? "," : "") << columns[i];
  os << "\n";
  for (const auto& r : rows) {
    for (size_t i = 0; i < r.size(); ++i) os << (i ? "," : "") << r[i];
    os << "\n";
  }
  return os.str();
}

namespace {

// System-identification excitation: per channel (roll, pitch, yaw rate, thrust) five sines
// between 1 and 8 Hz with random phases, unit RMS.
class Multisine {
 public:
  explicit Multisine(std::mt19937& rng) {
    const UniformReal uphase(0, 2 * M_PI);
    for (auto& ch : phase_)
      for (double& p : ch) p = uphase(rng);
  }
  double operator()(double t, int ch) const {
    static constexpr double kFreqs[5] = {1.1, 2.3, 3.7, 5.3, 7.9};
    double s = 0;
    for (int i = 0; i < 5; ++i) s += std::sin(2 * M_PI * kFreqs[i] * t + phase_[ch][i]);
    return s * std::sqrt(2.0 / 5.0);
  }

 private:
  double phase_[4][5];
};

// The reference at one time: value, rate and acceleration per axis (x, y, z, yaw).
struct ReferenceAt {
  double axis[4][3];
  ReferenceAt(const Reference& ref, double t) {
    for (int a = 0; a < 4; ++a) ref.at(t, a, axis[a]);
  }
  V3 position() const { return V3(axis[0][0], axis[1][0], axis[2][0]); }
  V3 velocity() const { return V3(axis[0][1], axis[1][1], axis[2][1]); }
  V3 acceleration() const { return V3(axis[0][2], axis[1][2], axis[2][2]); }
};

// The test flights' controller: position PD + I to a desired acceleration, geometric
// attitude P on the estimated attitude to rate set points (plus the excitation), rate P + I
// to body torques, allocated to per-rotor thrusts. It sees the true state except for the
// attitude, which it takes from the estimate the vehicle logs.
class CascadedController {
 public:
  CascadedController(const ControllerModel& b, const ClosedLoopOptions& o, const Multisine& excitation)
      : b_(b), o_(o), excitation_(excitation) {}

  std::vector<double> thrusts(double t, double dt, const ReferenceAt& r, const std::vector<double>& x,
                              const M3& R_estimated) {
    const V3 p = vec3_at(x, kPosition), v = vec3_at(x, kVelocity), w = vec3_at(x, kBodyRate);
    const V3 e_p = r.position() - p, e_v = r.velocity() - v;
    int_pos_ += e_p * dt;
    const V3 a_cmd = r.acceleration() + o_.kp_pos * e_p + o_.kd_pos * e_v + o_.ki_pos * int_pos_ + V3(0, 0, b_.g);
    const double thrust = b_.mass * a_cmd.dot(R_estimated.col(2));
    const V3 b3 = a_cmd.normalized();
    const V3 c1(std::cos(r.axis[3][0]), std::sin(r.axis[3][0]), 0);
    const V3 b2 = b3.cross(c1).normalized();
    M3 Rd;
    Rd.col(0) = b2.cross(b3);
    Rd.col(1) = b2;
    Rd.col(2) = b3;
    desired_ = Rd;
    const V3 e_R = 0.5 * vee(Rd.transpose() * R_estimated - R_estimated.transpose() * Rd);
    V3 w_d = -o_.kp_att * e_R + V3(0, 0, r.axis[3][1]);
    double thrust_scale = 1;
    if (o_.excitation > 0) {
      w_d += o_.excitation * V3(excitation_(t, 0), excitation_(t, 1), excitation_(t, 2));
      thrust_scale += 0.1 * o_.excitation * excitation_(t, 3);
    }
    const V3 e_w = w - w_d;
    int_rate_ += e_w * dt;
    const V3 Jd(b_.J[0], b_.J[1], b_.J[2]);
    const V3 torque = Jd.cwiseProduct(-o_.kp_rate * e_w - o_.ki_rate * int_rate_) + w.cross(Jd.cwiseProduct(w));
    return allocate(b_, thrust * thrust_scale, {torque.x(), torque.y(), torque.z()});
  }
  // The attitude the last step asked for (logged as phi_ref, theta_ref).
  const M3& desired() const { return desired_; }

 private:
  const ControllerModel& b_;
  const ClosedLoopOptions& o_;
  const Multisine& excitation_;
  V3 int_pos_ = V3::Zero(), int_rate_ = V3::Zero();
  M3 desired_ = M3::Identity();
};

// Per-rotor commands for the thrusts, through the believed thrust laws, saturated to [0, 1]
// and quantised as a PWM register holds them.
void commands_for(const ControllerModel& b, const std::vector<double>& F, int levels, std::vector<double>& u) {
  for (size_t i = 0; i < F.size(); ++i) {
    double ui;
    try {
      ui = b.thrust_laws[i].command_for(std::max(0.0, F[i]));
    } catch (const std::invalid_argument&) {
      ui = F[i] <= 0 ? 0.0 : 1.0;  // saturated
    }
    ui = std::clamp(ui, 0.0, 1.0);
    u[i] = std::round(ui * levels) / levels;
  }
}

// Battery: the open-circuit voltage falling over the flight, and a drop under load (the last
// commands' thrust above hover), so that voltage is not simply a function of time.
double battery_voltage(const ClosedLoopOptions& o, double t, bool first, const std::vector<double>& u, int nr,
                       double hover_u) {
  double load = 0;
  for (int i = 0; i < nr; ++i) load += u[i] * u[i] / (hover_u * hover_u) / nr;
  return o.vbat_start + (o.vbat_end - o.vbat_start) * t / o.duration - o.vbat_load_drop * (first ? 0.0 : load - 1.0);
}

// The start: at the reference's first point, level, at rest; rotor-speed states (motor_lag)
// at the hover command's speed.
std::vector<double> initial_state(const DynamicModel& truth, const ControllerModel& b, const Reference& ref,
                                  const std::vector<std::string>& rotors, double hover_u) {
  std::vector<double> x(truth.num_states(), 0.0);
  const ReferenceAt r0(ref, 0.0);
  for (int a = 0; a < 3; ++a) x[kPosition + a] = r0.axis[a][0];
  x[kAttitude] = 1;
  for (size_t i = 0; i < rotors.size(); ++i) {
    const int w = rotor_speed_state(truth, i);
    if (w >= 0) x[w] = b.thrust_laws[i].speed_at(hover_u);
  }
  return x;
}

std::vector<std::string> flight_columns(const std::vector<std::string>& rotors) {
  std::vector<std::string> columns = {"t"};
  for (const auto& r : rotors) columns.push_back("u_" + r);
  for (const char* c : {"x", "y", "z", "qw", "qx", "qy", "qz", "vx", "vy", "vz", "p", "q", "r", "ax", "ay", "az", "vbat",
                        "x_ref", "y_ref", "z_ref", "psi_ref", "phi_ref", "theta_ref"})
    columns.push_back(c);
  return columns;
}

// What the vehicle logs at one control step: the commands, a mocap-like pose and velocity,
// gyro and accelerometer with their biases and noise, the battery, the reference and the
// attitude the controller asked for (its roll and pitch, as an autopilot logs them). The
// accelerometer feels f, the derivative under the commands acting now. (The noise is drawn
// in this order, so that a flight is the same for the same seed.)
struct Sensors {
  const ClosedLoopOptions& o;
  V3 gyro_bias, acc_bias;
  double g;
  std::vector<double> row(double t, const std::vector<double>& u, int nr, const std::vector<double>& x,
                          const Eigen::Quaterniond& q_estimated, const M3& R_true, const std::vector<double>& f,
                          double vbat, const ReferenceAt& r, const M3& desired, std::mt19937& rng,
                          Normal& gauss) const {
    std::vector<double> row{t};
    for (int i = 0; i < nr; ++i) row.push_back(u[i]);
    const double an = o.pose_noise;
    // One draw per declarator, z first: as a constructor's three arguments their order was the
    // compiler's (GCC drew z first, clang x: the flights differed by compiler).
    const double dz = gauss(rng), dy = gauss(rng), dx = gauss(rng);
    const Eigen::Quaterniond dq(1, 0.5 * an * dx, 0.5 * an * dy, 0.5 * an * dz);
    const Eigen::Quaterniond q = (q_estimated * dq).normalized();
    for (int i = 0; i < 3; ++i) row.push_back(x[kPosition + i] + an * gauss(rng));
    for (double c : {q.w(), q.x(), q.y(), q.z()}) row.push_back(c);
    for (int i = 0; i < 3; ++i) row.push_back(x[kVelocity + i] + an * 10 * gauss(rng));
    for (int i = 0; i < 3; ++i) row.push_back(x[kBodyRate + i] + gyro_bias[i] + o.gyro_noise * gauss(rng));
    const V3 sf = R_true.transpose() * (vec3_at(f, kVelocity) + V3(0, 0, g));
    for (int i = 0; i < 3; ++i) row.push_back(sf[i] + acc_bias[i] + o.accel_noise * gauss(rng));
    row.push_back(vbat);
    for (double c : {r.axis[0][0], r.axis[1][0], r.axis[2][0], r.axis[3][0]}) row.push_back(c);
    const Eigen::Quaterniond qd(desired);
    const auto euler = euler_zyx(qd.w(), qd.x(), qd.y(), qd.z());
    row.push_back(euler[0]), row.push_back(euler[1]);
    return row;
  }
};

// Forces outside the effect catalogue, as impulses over one control period: a tether pulling
// back to the start, a random roll and pitch disturbance, a yaw moment in proportion to the
// forward speed. The disturbance has an engine of its own but draws through the sensors'
// Normal (portable_random.hpp), whose kept second value it may take: a flight without it is the
// same as before it existed, one with it does not share the sensor noise of the same seed
// without it. (Kept so, since the flights generated with it are referred to as they are.)
struct UnmodelledForces {
  const ClosedLoopOptions& o;
  double mass, dt;
  std::mt19937 rng;
  double pole, gain;
  double disturbance[2] = {0, 0};
  UnmodelledForces(const ClosedLoopOptions& options, double m, double period)
      : o(options), mass(m), dt(period), rng(options.seed + 7919), pole(std::exp(-2 * M_PI * 10.0 * period)),
        gain(options.angular_disturbance * std::sqrt(1 - pole * pole)) {}
  void apply(std::vector<double>& x, const Reference& ref, Normal& gauss) {
    if (o.tether_stiffness > 0) {
      const ReferenceAt start(ref, 0.0);
      for (int a = 0; a < 2; ++a)
        x[kVelocity + a] -= o.tether_stiffness * (x[kPosition + a] - start.axis[a][0]) / mass * dt;
    }
    if (o.angular_disturbance > 0)
      for (int a = 0; a < 2; ++a) {
        disturbance[a] = pole * disturbance[a] + gain * gauss(rng);
        x[kBodyRate + a] += disturbance[a] * dt;
      }
    if (o.yaw_per_forward_speed != 0) {
      const double forward = body_velocity(x.data())[0];
      x[kBodyRate + 2] += o.yaw_per_forward_speed * forward * dt;
    }
  }
};

// The commands the motors act on: those sent `delay` seconds ago. The delay is whole control
// periods and a rest within one (below 1 us counts as none: 0.03 / 0.01 is
// 2.9999999999999996 in floating point); with a rest, the command acting switches that far
// into each period.
class DelayedCommands {
 public:
  DelayedCommands(double delay, double dt, double duration) {
    // A negative delay would read commands not yet sent, one beyond the flight none sent.
    if (!(delay >= 0 && delay <= duration))
      throw std::invalid_argument("input_delay.seconds = " + output::six_digits(delay) + ": expected 0 to the flight's " +
                                  output::six_digits(duration) + " s");
    whole_ = static_cast<long>(std::floor(delay / dt + 1e-6));
    rest_ = delay - static_cast<double>(whole_) * dt;
    if (rest_ < 1e-6) rest_ = 0;
  }
  void send(const std::vector<double>& u) { sent_.push_back(u); }
  double rest() const { return rest_; }
  // In control period k: acting before the switch, after it, and at the period's start.
  // (References into the record: valid until the next send.)
  const std::vector<double>& before_switch(long k) const { return sent_at(k - whole_ - 1); }
  const std::vector<double>& after_switch(long k) const { return sent_at(k - whole_); }
  const std::vector<double>& at_start(long k) const { return rest_ > 0 ? before_switch(k) : after_switch(k); }

 private:
  const std::vector<double>& sent_at(long i) const { return sent_[static_cast<size_t>(std::max(0L, i))]; }
  long whole_ = 0;
  double rest_ = 0;
  std::vector<std::vector<double>> sent_;  // commands of every control step
};

// One control period: its number, start [s], length [s] and the battery voltage in it [V].
struct ControlPeriod {
  long k;
  double t0, dt, vbat;
};

// The true model over one control period, the rotor commands (the first `nr` inputs) held as
// the delay has them; the extra inputs (battery voltage, wind...) follow the clock.
void fly_one_period(const DynamicModel& truth, std::vector<double>& x, const DelayedCommands& commands,
                    const ExtraInputs& extra, int nr, const ControlPeriod& period, const IntegratorOptions& io) {
  bool before_switch = false;
  auto inputs = [&](double tt, double* uu) {
    const std::vector<double>& held =
        before_switch ? commands.before_switch(period.k) : commands.after_switch(period.k);
    for (int i = 0; i < nr; ++i) uu[i] = held[i];
    extra.fill(period.t0 + tt, period.vbat, uu);
  };
  // Integrate up to the switch and on from it, so that no RK4 step straddles it.
  if (commands.rest() > 0) {
    before_switch = true;
    x = integrate_rk4(truth, x, inputs, 0.0, commands.rest(), io).x.back();
    before_switch = false;
  }
  x = integrate_rk4(truth, x, inputs, commands.rest(), period.dt, io).x.back();
}

}  // namespace

GeneratedFlight fly_closed_loop(const DynamicModel& truth, const ControllerModel& b,
                                const std::vector<std::string>& rotors, const ClosedLoopOptions& o) {
  std::mt19937 rng(o.seed);
  const Reference ref(o, rng);
  Normal gauss(0, 1);
  const Multisine excitation(rng);
  const int nr = static_cast<int>(rotors.size());
  const ExtraInputs extra(truth);
  const double hover_u = b.thrust_laws[0].command_for(b.mass * b.g / nr);
  std::vector<double> x = initial_state(truth, b, ref, rotors, hover_u);
  GeneratedFlight out;
  out.columns = flight_columns(rotors);
  const double dt = 1.0 / o.log_rate;
  const long steps = std::lround(o.duration * o.log_rate);
  CascadedController controller(b, o, excitation);
  const Sensors sensors{o, V3(o.gyro_bias, -o.gyro_bias, 0.5 * o.gyro_bias), V3(o.accel_bias, -o.accel_bias, 0), b.g};
  UnmodelledForces unmodelled(o, b.mass, dt);
  // Effects outside the ODE, from the true model: the attitude the autopilot estimates and
  // logs is the model's measurement h(x) (q ⊗ q_bias under attitude_bias; it flies on that
  // estimate), and the motors act on the commands of `delay` seconds ago.
  const int delay_param = truth.input_delay_param();
  DelayedCommands commands(delay_param >= 0 ? truth.params()[delay_param] : 0.0, dt, o.duration);
  std::vector<double> logged(truth.num_outputs());
  const int logged_q = truth.num_outputs() - 4;  // h = (position, quaternion)
  std::vector<double> u(truth.num_inputs(), 0.0), f(truth.num_states());
  IntegratorOptions io;
  io.step = o.sim_step;
  io.divergence_bound = 1e4;
  for (long k = 0; k <= steps; ++k) {
    const double t = static_cast<double>(k) * dt;
    const double vbat = battery_voltage(o, t, k == 0, u, nr, hover_u);
    const ReferenceAt r(ref, t);
    const V3 p_at_t = vec3_at(x, kPosition);
    // --- controller, on the attitude the vehicle estimates ---
    const double* q = &x[kAttitude];
    const Eigen::Quaterniond q_true = Eigen::Quaterniond(q[0], q[1], q[2], q[3]).normalized();
    truth.measurement(x.data(), t, logged.data(), nullptr, nullptr);
    const Eigen::Quaterniond q_est =
        Eigen::Quaterniond(logged[logged_q], logged[logged_q + 1], logged[logged_q + 2], logged[logged_q + 3]).normalized();
    commands_for(b, controller.thrusts(t, dt, r, x, q_est.toRotationMatrix()), o.command_levels, u);
    extra.fill(t, vbat, u.data());
    commands.send(u);
    // --- log: noisy sensors (the accelerometer feels the commands in effect now) ---
    std::vector<double> acting = u;
    const std::vector<double>& in_effect = commands.at_start(k);
    for (int i = 0; i < nr; ++i) acting[i] = in_effect[i];
    truth.rhs(x.data(), acting.data(), f.data(), nullptr, nullptr, nullptr);
    out.rows.push_back(sensors.row(t, u, nr, x, q_est, q_true.toRotationMatrix(), f, vbat, r, controller.desired(), rng, gauss));
    if (k == steps) break;
    // --- plant: the true model over one control period ---
    fly_one_period(truth, x, commands, extra, nr, {k, t, dt, vbat}, io);
    unmodelled.apply(x, ref, gauss);
    if (x[kPosition + 2] < -5 || (p_at_t - r.position()).norm() > 20)
      throw DivergenceError("closed-loop flight lost at t = " + output::six_digits(t) + " s: " +
                            (x[kPosition + 2] < -5 ? "fell below z = -5 m"
                                                   : "more than 20 m from the reference (" +
                                                         output::short_number((p_at_t - r.position()).norm()) + " m)") +
                            "; does the vehicle file hold what flies (the audit's warnings), or the --set values?");
  }
  return out;
}

}  // namespace quadgen::runtime
