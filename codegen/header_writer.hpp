// Fills the file skeleton in templates/model.hpp.mustache with the emitted code.
#pragma once
#include <string>
#include <vector>

#include <kainjow/mustache.hpp>

#include "derive/symbolic_model.hpp"

namespace quadgen::codegen {

struct EmitOptions {
  std::string vehicle_file;  // as named on the command line, for the regenerate comment
  std::string regenerate_flags;  // what follows "--out DIR" in the regenerate command: " --effects ...", " --params FILE" or ""
  // Where kNominalParams come from when not the vehicle file (e.g. "fitted by quadgen
  // diagnose to LOG"): said in the header's comment, since regenerating with derive gives
  // the vehicle file's values. Empty: the vehicle file's.
  std::string parameter_source;
  // The rotors in input order (u_<rotor>): each one's spin seen from above (+1 counter-
  // clockwise, -1 clockwise), and the hover trim at the nominal values (each rotor's command
  // and thrust [N]; empty where the vehicle has none, `why_no_hover` then says why). A firmware
  // mixer and a simulator's start need them, and the header is all such a user has.
  std::vector<int> rotor_spin;
  std::vector<double> hover_command, hover_thrust;
  // rad/s: the rotor-speed states (motor_lag) at that trim's declared commands, in the
  // model's order of them; declared to 15 digits (declared_trim_value).
  std::vector<double> hover_rotor_speed;
  std::string why_no_hover;
  // Where the trim is the model's own because fitted effect values moved the base model's:
  // how, said on the line above the trim.
  std::string hover_note;
};

struct GeneratedHeader {
  std::string name;     // namespace and folder name, e.g. "finken3_with_motor_lag"
  std::string content;
  double ops_before = 0, ops_after = 0, ops_f_before = 0, ops_f_after = 0, ops_speeds_after = 0, pre_ops = 0;
  int pre_count = 0;
};

GeneratedHeader generate_header(const SymbolicModel& m, const EmitOptions& opt);

// A trim value (command, thrust) as the header declares it: 12 significant digits, which hold
// hover to about 1e-10 m/s² and leave no last bits that another machine's solver could round
// otherwise (CI compares generated/ byte for byte). The rotor speeds a motor lag has at the
// trim are found at these commands and declared to 15 digits: to 12 a speed leaves its row
// omega 1e-12 / tau off (5e-7 rad/s² at tau = 1 ms; the consumer check's example found it),
// to 15 about 1e-9, and no last bit that the order of GiNaC's terms could set (a review).
double declared_trim_value(double v);

// Where a header came from, as its comments and string constants tell it: text from a vehicle
// file and a command line.
struct Provenance {
  std::string vehicle_name, vehicle_hash, effects_text, effects_list, vehicle_file, regenerate_flags;
};

// Sets the template fields that carry provenance, each escaped for the C++ comment or string
// literal it lands in (exposed for fuzz/fuzz_template.cpp).
void set_provenance_fields(kainjow::mustache::data& d, const Provenance& p);

// The model's name: vehicle, plus effects.
std::string model_name(const SymbolicModel& m);

}  // namespace quadgen::codegen
