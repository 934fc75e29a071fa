#include "runtime/scenarios.hpp"
#include "output/joined.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace quadgen::runtime {

namespace {

// The thesis names its manoeuvres by the FINken 3's rotors (A rear-left at (-x, -y), B at
// (+x, -y), C at (+x, +y), D at (-x, +y); A and C spin ccw). Each is flown here by the rule
// it follows there, a side of the centre of gravity or a spin, so that on any layout it
// turns the vehicle the same way. A rotor within 0.1 % of the largest arm of an axis sits on
// it, on neither side.
enum class Side { kMinusX, kPlusX, kMinusY, kPlusY };
double on_axis_band(const std::vector<RotorPlace>& all) {
  double arm = 0;
  for (const auto& o : all) arm = std::max(arm, std::hypot(o.x, o.y));
  return 1e-3 * arm;
}
bool on(const RotorPlace& r, Side side, double band) {
  switch (side) {
    case Side::kMinusX: return r.x < -band;
    case Side::kPlusX: return r.x > band;
    case Side::kMinusY: return r.y < -band;
    case Side::kPlusY: return r.y > band;
  }
  return false;
}
bool between(double t, double a, double b) { return t >= a && t < b; }

// The thesis flies its manoeuvres in newtons for the FINken 3, whose hover thrust is 0.9491 N
// per rotor (thesis (60)). They are flown here as the same fractions of each vehicle's own
// hover thrust h, so that a 27 g Crazyflie (0.066 N per rotor) flies the same manoeuvre
// rather than being asked for 17 times its weight.
constexpr double kThesisHover = 0.9491;  // N per rotor
constexpr double kThesisClimb = 1.1;     // N per rotor (thesis 2.3.1 b)
constexpr double kThesisDelta = 0.02;    // N: the step of the manoeuvre thrusts, 2.1 % of hover

double step(double h) { return kThesisDelta / kThesisHover * h; }

std::vector<double> hover(double, double h, const std::vector<RotorPlace>& r) { return std::vector<double>(r.size(), h); }

// Thesis 2.3.1 b): 1.1 N on every rotor, 1.16 times hover.
std::vector<double> climb(double, double h, const std::vector<RotorPlace>& r) {
  return std::vector<double>(r.size(), kThesisClimb / kThesisHover * h);
}

// Tilt doublet, hold, reverse doublet: raise the `first` side then the `second`, later the reverse.
std::vector<double> doublet(double t, double h, const std::vector<RotorPlace>& r, Side first, Side second) {
  std::vector<double> F(r.size(), h);
  const double band = on_axis_band(r);
  for (size_t i = 0; i < r.size(); ++i) {
    if ((between(t, 0.5, 0.6) || between(t, 1.6, 1.7)) && on(r[i], first, band)) F[i] += step(h);
    if ((between(t, 0.6, 0.7) || between(t, 1.5, 1.6)) && on(r[i], second, band)) F[i] += step(h);
  }
  return F;
}
// Thesis 2.3.2 a): raise A and D (the -x side) to tilt towards +x.
std::vector<double> right(double t, double h, const std::vector<RotorPlace>& r) {
  return doublet(t, h, r, Side::kMinusX, Side::kPlusX);
}
// Thesis 2.3.2 b): raise C and D (the +y side), as the thesis does for "forward (+y)".
std::vector<double> forward(double t, double h, const std::vector<RotorPlace>& r) {
  return doublet(t, h, r, Side::kPlusY, Side::kMinusY);
}
// Thesis 2.3.2 c): raise A and C (the ccw rotors) for a second.
std::vector<double> yaw(double t, double h, const std::vector<RotorPlace>& r) {
  std::vector<double> F(r.size(), h);
  for (size_t i = 0; i < r.size(); ++i)
    if (between(t, 0.5, 1.5) && r[i].ccw) F[i] += step(h);
  return F;
}
// Thesis 2.3.2 d): all up, coast, all down by the same amount: a new constant height.
std::vector<double> new_height(double t, double h, const std::vector<RotorPlace>& r) {
  double d = 0;
  if (between(t, 0.5, 1.0)) d = 5 * step(h);
  if (between(t, 2.0, 2.5)) d = -5 * step(h);
  return std::vector<double>(r.size(), h + d);
}

}  // namespace

const std::vector<Scenario>& scenario_catalogue() {
  // (thrust, roll, pitch, yaw) each manoeuvre means to change.
  constexpr std::array<bool, 4> kNone{}, kThrust{true}, kThrustRoll{true, true}, kThrustPitch{true, false, true},
      kThrustYaw{true, false, false, true};
  static const std::vector<Scenario> list = {
      {"hover", "every rotor at its hover thrust (m g / n on a symmetric vehicle; thesis (60))", hover, kNone},
      {"climb", "1.16 times hover thrust on every rotor (the thesis' 1.1 N; 2.3.1 b, (63)-(64))", climb, kThrust},
      {"right", "the rotors on the -x side of the centre of gravity (A, D) raised 2.1 % of hover for 0.1 s, then "
                "those on +x; reversed at 1.5 s (thesis 2.3.2 a): tilts towards +x", right, kThrustPitch},
      {"forward", "the rotors on the +y side (C, D) raised 2.1 % of hover for 0.1 s, then those on -y; reversed at "
                  "1.5 s (thesis 2.3.2 b, its inputs for +y): tilts towards -y", forward, kThrustRoll},
      {"yaw", "the ccw rotors (A, C) raised 2.1 % of hover from 0.5 to 1.5 s (thesis 2.3.2 c)", yaw, kThrustYaw},
      {"new_height", "all rotors +10.5 % of hover from 0.5 to 1.0 s, -10.5 % from 2.0 to 2.5 s (thesis 2.3.2 d)",
       new_height, kThrust},
  };
  return list;
}

const Scenario& find_scenario(const std::string& name) {
  for (const auto& s : scenario_catalogue())
    if (s.name == name) return s;
  const std::string known = output::joined(scenario_catalogue(), ", ", [](const Scenario& s) { return s.name; });
  throw std::invalid_argument("unknown scenario '" + name + "' (known: " + known + ")");
}

}  // namespace quadgen::runtime
