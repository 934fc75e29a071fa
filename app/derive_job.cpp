#include "app/derive_job.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <map>
#include <sstream>

#include "app/derive_pipeline.hpp"
#include "derive/effects/effect_catalogue.hpp"
#include "output/joined.hpp"
#include "output/numbers.hpp"
#include "output/progress.hpp"

namespace quadgen::app {

namespace {

// The blocks' value of a quantity of kDerivedQuantities the summary prints.
double blocks_value(const MassProperties& mp, const std::string& name) {
  if (name == "mass") return mp.mass_value;
  if (name.rfind("cog_", 0) == 0) return mp.cog_value[static_cast<size_t>(name[4] - 'x')];
  const auto axis = [&](char c) { return static_cast<size_t>(c - 'x'); };
  return mp.inertia_cog_value[axis(name[2])][axis(name[3])];  // J_xy -> [x][y]
}

// Where the values said come from: " (the blocks')", " (the file's `derived:`)" or " (fitted)"
// where all of `names` come from one place, else each place with its names, "(the blocks';
// the file's `derived:`: J_xy)". Fitted values (--params, a `fitted:` section) replace the
// blocks' and the `derived:` ones as the model's nominal ones: a value is the file's only
// where the model holds it (a review found a fitted mass said to be the file's).
std::string source_of(const Vehicle& v, const MassProperties& mp, const SymbolicModel& model,
                      const std::vector<std::string>& names) {
  std::map<std::string, std::vector<std::string>> by_source;
  for (const auto& n : names) {
    const double nominal = model.params[model.param_index(n)].nominal;
    const auto same = [&](double value) { return output::equal_but_for_rounding(nominal, value); };
    const bool given = v.derived_given.count(n) > 0;
    by_source[given && same(v.derived_overrides.at(n).nominal) ? "the file's `derived:`"
              : !given && same(blocks_value(mp, n))            ? "the blocks'"
                                                               : "fitted"]
        .push_back(n);
  }
  if (by_source.size() == 1) return " (" + by_source.begin()->first + ")";
  std::string said;
  for (const char* source : {"the blocks'", "the file's `derived:`", "fitted"})
    if (by_source.count(source))
      said += std::string(said.empty() ? "" : "; ") + source +
              (std::string(source) == "the blocks'" ? "" : ": " + output::joined(by_source[source]));
  return " (" + said + ")";
}

// What a user checks first: the model's size and audit, the generated code's op counts, and
// the mass properties against their scale and CAD (as the model uses them: from the blocks,
// or measured values the vehicle file gives in `derived:`).
std::string summary_of(const Vehicle& vehicle, const MassProperties& mp, const DerivedModel& d, double seconds) {
  const SymbolicModel& model = d.model;
  const codegen::GeneratedHeader& header = d.header;
  const auto nominal = [&](const std::string& name) { return model.params[model.param_index(name)].nominal; };
  std::ostringstream os;
  os << "derived " << vehicle.name << ": " << model.states.size() << " states, " << model.inputs.size() << " inputs, "
     << model.params.size() << " parameters; audit " << (d.audit.all_passed() ? "passed" : "FAILED") << " ("
     << d.audit.checks.size() << " checks"
     << (d.audit.warnings().empty() ? std::string()
                                    : "; " + std::to_string(d.audit.warnings().size()) +
                                          (d.audit.warnings().size() == 1 ? " vehicle warning" : " vehicle warnings") +
                                          " below")
     << "); derived, audited and generated in " << std::setprecision(3) << seconds
     << std::setprecision(6) << " s (writing the files not counted)\n"
     << "generated model.hpp (" << header.name << "): f " << header.ops_f_before << " -> " << header.ops_f_after
     << " ops, f + Jacobians " << header.ops_before << " -> " << header.ops_after << " ops after CSE, "
     << header.pre_count << " precomputed values (" << header.pre_ops << " ops)\n";
  // Values the file gives in `derived:` replace the blocks' (their tensor stays about the blocks'
  // centre as given: the file's values are what the model uses), so the line says which.
  os << "mass " << nominal("mass") << " kg" << source_of(vehicle, mp, model, {"mass"}) << "; centre of gravity (" << nominal("cog_x")
     << ", " << nominal("cog_y") << ", " << nominal("cog_z") << ") m" << source_of(vehicle, mp, model, {"cog_x", "cog_y", "cog_z"});
  // A fitted CoG offset moves the point the thrust's moments act about; the blocks' centre
  // stays what the file describes, so both are said.
  const auto has = [&](const std::string& name) {
    return std::any_of(model.params.begin(), model.params.end(), [&](const auto& p) { return p.name == name; });
  };
  if (has("cog_offset.x") && (nominal("cog_offset.x") != 0 || nominal("cog_offset.y") != 0))
    os << ", moved by the fitted cog_offset (" << nominal("cog_offset.x") << ", " << nominal("cog_offset.y") << ") m";
  os << "; inertia J_xx, J_yy, J_zz " << nominal("J_xx") << ", " << nominal("J_yy") << ", " << nominal("J_zz") << " kg m²";
  // A block off the symmetry planes (a camera under the nose) shows first in the products.
  if (nominal("J_xy") != 0 || nominal("J_xz") != 0 || nominal("J_yz") != 0)
    os << ", products J_xy, J_xz, J_yz " << nominal("J_xy") << ", " << nominal("J_xz") << ", " << nominal("J_yz") << " kg m²";
  os << source_of(vehicle, mp, model, {"J_xx", "J_yy", "J_zz", "J_xy", "J_xz", "J_yz"}) << "\n";
  // The hover commands a changed vehicle moves (a researcher's trial, helper-148: they were in
  // model.json and derivation.md only).
  if (d.why_trim_does_not_hold.empty() && d.hover_trim.found() && !d.hover_trim.commands.empty()) {
    os << "hover command (the header's kHoverCommand):";
    for (size_t i = 0; i < vehicle.rotors.size() && i < d.hover_trim.commands.size(); ++i)
      os << (i ? ", " : " ") << vehicle.rotors[i].name << " " << output::six_digits(d.hover_trim.commands[i]);
    os << "\n";
  }
  for (const AuditCheck* w : d.audit.warnings())
    os << "warning: the vehicle: " << w->name << ": no; " << w->detail << "\n";
  if (!d.why_trim_does_not_hold.empty()) os << "note: the header declares no hover trim: " << d.why_trim_does_not_hold << "\n";
  if (!d.trim_moved_by_effects.empty()) os << "note: the header's hover trim: " << d.trim_moved_by_effects << "\n";
  return os.str();
}

}  // namespace

DeriveJobResult run_derive_job(const DeriveJob& job, const Vehicle& vehicle) {
  const auto t0 = std::chrono::steady_clock::now();
  const auto progress = [&](const std::string& what) {
    if (job.progress) job.progress(what);
  };
  DeriveRequest request;
  request.derive.effects = parse_effect_list(job.effects);
  request.emit.vehicle_file = job.vehicle;
  request.emit.regenerate_flags = job.effects.empty() ? "" : " --effects " + job.effects;
  // The fitted values: --params, or the vehicle file's own `fitted:` section.
  const std::string note = use_fitted_values(request, vehicle, job.vehicle, job.params, !job.effects.empty());
  progress("mass properties of " + std::to_string(vehicle.blocks.size()) + " blocks");
  const MassProperties mass_properties = derive_mass_properties(vehicle);
  request.progress = progress;
  const DerivedModel d = run_derive_pipeline(vehicle, mass_properties, request);
  DeriveJobResult r;
  r.files = {{"model.json", d.model_json}, {"derivation.md", d.derivation_md}, {"model.hpp", d.header.content}};
  r.audit_passed = d.audit.all_passed();
  r.note = note;
  r.summary = summary_of(vehicle, mass_properties, d, output::seconds_since(t0));
  return r;
}

}  // namespace quadgen::app
