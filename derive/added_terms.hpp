// Terms found beyond the catalogue (diagnose/term_discovery: sparse regression of what the
// fitted model still gets wrong), added to the symbolic model so that the code generated
// from it carries them and a simulation can measure what they buy, like any effect's.
#pragma once
#include <string>
#include <utility>
#include <vector>

namespace quadgen {

struct ModelContext;

// One channel's term: channel += sum of coefficient * regressor. Channels: pdot, qdot, rdot
// (body angular acceleration, rad/s^2), ax_world..az_world (world acceleration, m/s^2), ax..az
// (body specific force, m/s^2). Regressors as term_discovery names them: "1", v_bx, v_by,
// v_bz (body velocity, m/s), p, q, r (rad/s), dU (mean rotor command minus its centre), dvbat
// (battery voltage minus its centre, V), and products "a*b" of two of them.
struct AddedTerm {
  std::string channel;
  std::vector<std::pair<std::string, double>> coefficients;  // regressor -> value, SI
  std::vector<std::pair<std::string, double>> centres;       // "dU", "dvbat" -> what they are taken about
};

// Adds each term's coefficients as parameters "term_<channel>_<k>" (nominal = value, fitted,
// unit from the channel's and the regressor's) and its force or moment to the context: a
// moment J a for an angular acceleration a, a body force m R^T a for a world acceleration, m a
// for a specific force, so that the channel changes by exactly the term. Throws
// std::invalid_argument on an unknown channel or regressor.
void add_terms(ModelContext& c, const std::vector<AddedTerm>& terms);

}  // namespace quadgen
