// Flight logs as CSV: reading with line-exact errors, the canonical layout of
// contracts.md §2 (validation against a model's rotor names), and writing trajectories.
#pragma once
#include <stdexcept>
#include <string>
#include <vector>

#include "dynamic_model.hpp"
#include "integrator.hpp"

namespace quadgen::runtime {

struct LogError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct CsvTable {
  std::string path;
  std::vector<std::string> columns;
  std::vector<std::vector<double>> rows;
  int column(const std::string& name) const;  // -1 if absent
  std::vector<double> values(const std::string& name) const;
};

// Numbers only (an empty cell is an error); throws LogError "path:line: ...".
CsvTable read_csv(const std::string& path);
CsvTable parse_csv(const std::string& text, const std::string& path);

// Checks the canonical layout for these rotors: t strictly increasing, u_<rotor> present
// for every rotor and no u_ column for an unknown rotor, finite values, at least 2 rows.
void validate_canonical(const CsvTable& log, const std::vector<std::string>& rotor_names);

// Canonical-layout CSV of a trajectory: t, u_*, x, y, z, qw..qz, phi, theta, psi, vx, vy,
// vz, p, q, r, then any further states (w_* rotor speeds).
std::string trajectory_csv(const DynamicModel& m, const Trajectory& tr, const InputFunction& u,
                           const std::vector<std::string>& rotor_names);

}  // namespace quadgen::runtime
