// The thesis' published equations and numbers, encoded as a reference, and their
// comparison with the derived model: what agrees, what differs, why, and by how much.
// Only meaningful for the FINken 3 (vehicle name "finken3" with rotors A..D: is_thesis_vehicle).
#pragma once
#include <string>
#include <vector>

#include "derive/geometry.hpp"
#include "derive/symbolic_model.hpp"
#include "model/vehicle.hpp"

namespace quadgen {

struct ThesisItem {
  std::string ref;      // equation numbers, e.g. "(42)-(45), Table 1"
  std::string topic;
  std::string thesis;   // what the thesis says
  std::string derived;  // what quadgen derives
  bool agrees = false;
  std::string cause;    // why they differ (physics or algebra), empty when they agree
  std::string size;     // how large the difference is numerically
  std::string basis;    // how the verdict was reached: kFromModel, kFromArithmetic or kFromReading, and how
};

// The ways a verdict is reached, first words of ThesisItem::basis.
inline constexpr const char* kFromModel = "computed from the model";
inline constexpr const char* kFromArithmetic = "computed by arithmetic";
inline constexpr const char* kFromReading = "reading of the equations";

// The thesis, as a reader cites it (derivation.md's comparison names it; vehicles/finken3.yaml
// says the same in its header).
inline constexpr const char* kThesisCitation =
    "A. Heckert, \"Entwicklung eines dynamischen Modells und Parameterschätzung für den FINken 3 Quadkopter\", "
    "bachelor thesis, Otto-von-Guericke-Universität Magdeburg, 2016";

// Whether a model is of the thesis' vehicle (model/vehicle.hpp decides it by name).
bool is_thesis_vehicle(const SymbolicModel& m);

// The comparison, item by item; empty for any other vehicle.
std::vector<ThesisItem> compare_with_thesis(const Vehicle& v, const SymbolicModel& m, const MassProperties& mp);

// The thesis' transformation matrix (3)/(81), as printed.
GiNaC::matrix thesis_transformation(const GiNaC::ex& phi, const GiNaC::ex& theta, const GiNaC::ex& psi);
// The thesis' rotation about y (78), as printed (not a rotation: det -1).
GiNaC::matrix thesis_rotation_about_y(const GiNaC::ex& theta);

}  // namespace quadgen
