// What `quadgen derive` writes for people and programs: derivation.md (each step with
// its equations in LaTeX, the audit, the thesis comparison) and model.json.
#pragma once
#include <string>
#include <vector>

#include "audit/audit.hpp"
#include "derive/geometry.hpp"
#include "derive/symbolic_model.hpp"
#include "audit/thesis_reference.hpp"
#include "model/vehicle.hpp"
#include "runtime/closed_loop.hpp"

namespace quadgen {

struct Derivation {
  const Vehicle& vehicle;
  const MassProperties& mass;
  const SymbolicModel& model;
  const AuditResult& audit;
  const std::vector<ThesisItem>& thesis;  // empty for vehicles other than the FINken 3
  const runtime::HoverTrim& hover_trim;    // at the nominal values (nominal_hover_trim)
  double hover_residual = 0;               // the largest |f| of the model there (hover_miss)
  // Why that trim does not hold this model (fitted effect values move the hover), or empty:
  // then the header declares none, and model.json and derivation.md say so too.
  std::string why_trim_does_not_hold;
  // Where the base model's trim missed and hover_trim is the model's own (model_hover_trim):
  // how the hover moved, and the base trim's commands; empty otherwise.
  std::string trim_moved_by_effects;
  std::vector<double> base_trim_commands;
  double base_trim_residual = 0;  // the largest |f| at base_trim_commands
};

std::string derivation_markdown(const Derivation& d);
std::string model_json(const Derivation& d);

}  // namespace quadgen
