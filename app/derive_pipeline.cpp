#include "app/derive_pipeline.hpp"

#include <set>
#include <stdexcept>

#include "audit/mass_quadrature.hpp"
#include "audit/report.hpp"
#include "audit/vehicle_checks.hpp"
#include "derive/fitted_parameters.hpp"
#include "output/numbers.hpp"
#include "output/sinks.hpp"

namespace quadgen {

std::string use_fitted_values(DeriveRequest& request, const Vehicle& vehicle, const std::string& vehicle_path,
                       const std::string& params_path, bool effects_given) {
  if (vehicle.fitted_line > 0 && !params_path.empty())
    throw std::invalid_argument(vehicle_path + " carries fitted values already (its 'fitted:' section); leave --params out");
  const std::string params = vehicle.fitted_line > 0 ? vehicle_path : params_path;
  if (params.empty()) return "";
  const FittedParameters fitted = load_fitted_parameters(params);
  const auto& wanted = request.derive.effects;
  if (!effects_given) request.derive.effects = fitted.effects;
  else if (std::set<std::string>(wanted.begin(), wanted.end()) != std::set<std::string>(fitted.effects.begin(), fitted.effects.end()))
    throw EffectsNotTheFittedOnes("--effects differs from the effects " + params + " was fitted with; leave it out", fitted.effects);
  request.set_nominal = [fitted](SymbolicModel& m) { apply_fitted_parameters(m, fitted); };
  request.emit.regenerate_flags = params == vehicle_path ? "" : " --params " + output::shell_path(params);
  request.emit.parameter_source = "fitted values from " + params;
  if (fitted.vehicle.empty() || fitted.vehicle == vehicle.name) return "";
  return output::printable(params) + " was fitted for the vehicle '" + output::printable(fitted.vehicle) + "', not '" +
         vehicle.name + "'; its values are applied by parameter name";
}

// The trim is the base model's; a model whose effect values were fitted away from neutral does
// not hover at it (hover_miss says how far it misses). Above kHoverHolds the model's own
// trim is sought from it (model_hover_trim) and, where found, declared with a note of how it
// moved; where none holds, why, which the header, model.json and derivation.md then say
// instead of declaring one.
static void judge_hover_trim(const Vehicle& vehicle, DerivedModel& out) {
  if (!out.hover_trim.found()) return;
  // Judged at the commands the header declares (and model.json gives), the rotor speeds found
  // there: a motor lag's speed rows then hold at what a user reads (declared_trim_value).
  const auto declared = [](std::vector<double> commands) {
    for (double& c : commands) c = codegen::declared_trim_value(c);
    return commands;
  };
  out.hover_trim.commands = declared(out.hover_trim.commands);
  const HoverMiss base_miss = hover_miss(out.model, out.hover_trim.commands);
  out.hover_residual = base_miss.largest;
  if (out.hover_residual <= DerivedModel::kHoverHolds) {
    out.hover_trim.rotor_speeds = base_miss.rotor_speeds;
    return;
  }
  const std::string moved = "the model's effect values (fitted away from neutral) move the hover: the base model's trim (" +
                            output::short_number(out.hover_trim.commands.front()) + "...) leaves |f| = " +
                            output::short_number(out.hover_residual) + " there (in " + base_miss.row + ")";
  runtime::HoverTrim own = model_hover_trim(vehicle, out.model, out.hover_trim.commands);
  own.commands = declared(own.commands);
  const HoverMiss own_miss = own.found() ? hover_miss(out.model, own.commands) : HoverMiss{};
  const double own_residual = own_miss.largest;
  if (own.found() && own_residual <= DerivedModel::kHoverHolds) {
    out.base_trim_commands = out.hover_trim.commands;
    out.base_trim_residual = out.hover_residual;
    out.hover_trim = own;
    out.hover_trim.rotor_speeds = own_miss.rotor_speeds;
    out.hover_residual = own_residual;
    out.trim_moved_by_effects = moved + "; this trim is the model's own, with them";
    return;
  }
  out.why_trim_does_not_hold = moved + ", and the model has no trim of its own: " +
                               (own.found() ? "|f| = " + output::short_number(own_residual) + " at the one found" : own.why_not);
}

SymbolicModel requested_model(const Vehicle& vehicle, const MassProperties& mass, const DeriveRequest& request) {
  SymbolicModel model = derive_model(vehicle, mass, request.derive);
  if (request.set_nominal) request.set_nominal(model);
  return model;
}

DerivedModel run_derive_pipeline(const Vehicle& vehicle, const MassProperties& mass, const DeriveRequest& request) {
  auto progress = [&](const char* step) {
    if (request.progress) request.progress(step);
  };
  DerivedModel out;
  progress("equations of motion and Jacobians");
  out.model = requested_model(vehicle, mass, request);
  progress("audit");
  out.audit = audit(out.model, mass);
  for (AuditCheck& c : check_mass_properties_by_quadrature(vehicle, mass)) out.audit.checks.push_back(std::move(c));
  out.hover_trim = nominal_hover_trim(vehicle, out.model);
  for (AuditCheck& c : check_vehicle_can_fly(vehicle, out.model, out.hover_trim)) out.audit.checks.push_back(std::move(c));
  if (request.thesis_comparison) out.thesis = compare_with_thesis(vehicle, out.model, mass);
  progress("generating C++");
  codegen::EmitOptions emit = request.emit;
  if (request.regenerate_flags_from_model)
    emit.regenerate_flags = out.model.effects.empty() ? "" : " --effects " + out.model.effect_list();
  for (const Rotor& r : vehicle.rotors) emit.rotor_spin.push_back(spin_sign(r));
  judge_hover_trim(vehicle, out);
  emit.hover_command = out.why_trim_does_not_hold.empty() ? out.hover_trim.commands : std::vector<double>{};
  emit.hover_thrust = out.hover_trim.thrusts;
  emit.hover_rotor_speed = out.hover_trim.rotor_speeds;
  emit.why_no_hover = out.why_trim_does_not_hold.empty() ? out.hover_trim.why_not : out.why_trim_does_not_hold;
  emit.hover_note = out.trim_moved_by_effects;
  out.header = codegen::generate_header(out.model, emit);
  const Derivation d{vehicle,          mass, out.model, out.audit, out.thesis, out.hover_trim, out.hover_residual,
                     out.why_trim_does_not_hold, out.trim_moved_by_effects, out.base_trim_commands, out.base_trim_residual};
  out.model_json = model_json(d);
  out.derivation_md = derivation_markdown(d);
  return out;
}

}  // namespace quadgen
