// Shared helpers for the derive tests: load bundled vehicles, evaluate the symbolic
// model numerically.
#pragma once
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "derive/dynamics.hpp"
#include "derive/geometry.hpp"
#include "model/vehicle.hpp"
#include "runtime/portable_random.hpp"

namespace quadgen::test {

inline std::string source_path(const std::string& rel) { return std::string(QUADGEN_SOURCE_DIR) + "/" + rel; }

inline Vehicle finken3() { return load_vehicle(source_path("vehicles/finken3.yaml")); }

// f at a numeric point: x, u given, parameters at their nominal values.
inline std::vector<double> eval_f(const SymbolicModel& m, const std::vector<double>& x, const std::vector<double>& u) {
  if (x.size() != m.states.size() || u.size() != m.inputs.size())
    throw std::invalid_argument("eval_f: wrong number of states or inputs");
  GiNaC::lst s = m.nominal_substitution();
  for (const auto& c : m.constant_substitution()) s.append(c);
  for (size_t i = 0; i < x.size(); ++i) s.append(m.states[i].sym == x[i]);
  for (size_t i = 0; i < u.size(); ++i) s.append(m.inputs[i].sym == u[i]);
  std::vector<double> out;
  for (unsigned i = 0; i < m.f.rows(); ++i) out.push_back(to_double(m.f(i, 0).subs(s)));
  return out;
}

// A random flight state: position, velocity, unit quaternion, body rates.
inline std::vector<double> random_state(std::mt19937& rng) {
  quadgen::runtime::UniformReal d(-1, 1);
  std::vector<double> x(13);
  for (int i = 0; i < 6; ++i) x[i] = 2 * d(rng);
  x[2] = 1.0 + std::fabs(x[2]);  // above the ground
  double n = 0;
  for (int i = 6; i < 10; ++i) n += (x[i] = d(rng)) * x[i];
  for (int i = 6; i < 10; ++i) x[i] /= std::sqrt(n);
  for (int i = 10; i < 13; ++i) x[i] = 3 * d(rng);
  return x;
}

}  // namespace quadgen::test
