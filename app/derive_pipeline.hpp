// The derive pipeline, written once: a vehicle and its mass properties -> the symbolic model
// -> the audit (and, for the thesis' vehicle, the comparison with the thesis) -> the
// generated header, model.json and derivation.md. `quadgen derive` and diagnose's extended
// model both run it; what differs between them is in DeriveRequest.
#pragma once
#include <functional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "audit/audit.hpp"
#include "derive/dynamics.hpp"
#include "codegen/header_writer.hpp"
#include "derive/geometry.hpp"
#include "derive/symbolic_model.hpp"
#include "audit/thesis_reference.hpp"
#include "model/vehicle.hpp"
#include "runtime/closed_loop.hpp"

namespace quadgen {

struct DeriveRequest {
  DeriveOptions derive;       // effects and added terms
  codegen::EmitOptions emit;  // the header's provenance
  // The header's regenerate command names the model's effects in canonical order
  // ("--effects motor_gain,wind") rather than emit.regenerate_flags.
  bool regenerate_flags_from_model = false;
  // Sets nominal values other than the vehicle file's (fitted ones) before the audit and the
  // emission; none when empty.
  std::function<void(SymbolicModel&)> set_nominal;
  bool thesis_comparison = true;  // for the thesis' vehicle only (thesis_reference.hpp)
  // Called before each step with its description ("audit", "generating C++").
  std::function<void(const std::string&)> progress;
};

struct DerivedModel {
  SymbolicModel model;
  AuditResult audit;
  std::vector<ThesisItem> thesis;
  runtime::HoverTrim hover_trim;  // at the nominal values: the vehicle checks, the header and model.json read it
  // The largest |f| of the model at that trim (hover_miss; 0 where there is none), and the
  // most that still counts as holding: the trim's 12 digits leave about 1e-10.
  double hover_residual = 0;
  static constexpr double kHoverHolds = 1e-6;
  std::string why_trim_does_not_hold;  // empty where it holds (or there is none)
  // Where the base model's trim missed and hover_trim is the model's own (model_hover_trim):
  // how the hover moved, and the base trim's commands; empty otherwise.
  std::string trim_moved_by_effects;
  std::vector<double> base_trim_commands;
  double base_trim_residual = 0;  // the largest |f| at base_trim_commands
  codegen::GeneratedHeader header;
  std::string model_json, derivation_md;
};

// --effects given beside fitted values of other effects: its own type, so that a command whose
// --effects means something else (compare's, for both files) can say it in its own words.
struct EffectsNotTheFittedOnes : std::invalid_argument {
  EffectsNotTheFittedOnes(const std::string& what, std::vector<std::string> fitted_effects)
      : std::invalid_argument(what), fitted(std::move(fitted_effects)) {}
  std::vector<std::string> fitted;
};

// Gives `request` fitted values as nominal ones: from `params_path` (a fitted_parameters.yaml),
// or from the vehicle file's own `fitted:` section; both at once is an error. Without
// `effects_given` the effects are the fitted ones; given, they must be the same set
// (EffectsNotTheFittedOnes otherwise).
// Returns a note for the user where the values were fitted for another vehicle (by name): they
// may still be wanted (the same airframe under another name), but never silently.
std::string use_fitted_values(DeriveRequest& request, const Vehicle& vehicle, const std::string& vehicle_path,
                       const std::string& params_path, bool effects_given);

DerivedModel run_derive_pipeline(const Vehicle& vehicle, const MassProperties& mass, const DeriveRequest& request);

// The pipeline's first step alone: the symbolic model with the request's effects and nominal
// values, neither audited nor generated (quadgen compare needs its equations only).
SymbolicModel requested_model(const Vehicle& vehicle, const MassProperties& mass, const DeriveRequest& request);

}  // namespace quadgen
