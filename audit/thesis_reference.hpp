// The thesis' published equations and numbers, encoded as a reference, and their
// comparison with the derived model: what agrees, what differs, why, and by how much.
// Only meaningful for the FINken 3 (vehicle name "finken3").
#pragma once
#include <string>
#include <vector>

#include "derive/geometry.hpp"
#include "derive/symbolic_model.hpp"

namespace quadgen {

struct ThesisItem {
  std::string ref;      // equation numbers, e.g. "(42)-(45), Table 1"
  std::string topic;
  std::string thesis;   // what the thesis says
  std::string derived;  // what quadgen derives
  bool agrees = false;
  std::string cause;    // why they differ (physics or algebra), empty when they agree
  std::string size;     // how large the difference is numerically
};

// Whether a model is of the thesis' vehicle, the FINken 3 (vehicles/finken3.yaml, name
// "finken3"): the one place that decides it.
bool is_thesis_vehicle(const SymbolicModel& m);

// The comparison, item by item; empty for any other vehicle.
std::vector<ThesisItem> compare_with_thesis(const SymbolicModel& m, const MassProperties& mp);

// The thesis' transformation matrix (3)/(81), as printed.
GiNaC::matrix thesis_transformation(const GiNaC::ex& phi, const GiNaC::ex& theta, const GiNaC::ex& psi);

}  // namespace quadgen
