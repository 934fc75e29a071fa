#include "app/derive_job.hpp"

#include <algorithm>
#include <chrono>
#include <iomanip>
#include <sstream>

#include "app/derive_pipeline.hpp"
#include "derive/effects/effect_catalogue.hpp"
#include "output/joined.hpp"

namespace quadgen::app {

namespace {

// Where the values said come from: " (the blocks')", " (the file's `derived:`)" where it gives
// all of `names`, or " (the blocks', J_xy from the file's `derived:`)" where it gives some.
std::string given(const Vehicle& v, const std::vector<std::string>& names) {
  std::vector<std::string> from_file;
  for (const auto& n : names)
    if (v.derived_given.count(n)) from_file.push_back(n);
  if (from_file.empty()) return " (the blocks')";
  if (from_file.size() == names.size()) return " (the file's `derived:`)";
  return " (the blocks', " + output::joined(from_file) + " from the file's `derived:`)";
}

// What a user checks first: the model's size and audit, the generated code's op counts, and
// the mass properties against their scale and CAD (as the model uses them: from the blocks,
// or measured values the vehicle file gives in `derived:`).
std::string summary_of(const Vehicle& vehicle, const DerivedModel& d, double seconds) {
  const SymbolicModel& model = d.model;
  const codegen::GeneratedHeader& header = d.header;
  const auto nominal = [&](const std::string& name) { return model.params[model.param_index(name)].nominal; };
  std::ostringstream os;
  os << "derived " << vehicle.name << ": " << model.states.size() << " states, " << model.inputs.size() << " inputs, "
     << model.params.size() << " parameters; audit " << (d.audit.all_passed() ? "passed" : "FAILED") << " ("
     << d.audit.checks.size() << " checks"
     << (d.audit.warnings().empty() ? std::string()
                                    : "; " + std::to_string(d.audit.warnings().size()) + " about the vehicle warn, below")
     << "); derived, audited and generated in " << std::setprecision(3) << seconds
     << std::setprecision(6) << " s (writing the files not counted)\n"
     << "generated model.hpp (" << header.name << "): f " << header.ops_f_before << " -> " << header.ops_f_after
     << " ops, f + Jacobians " << header.ops_before << " -> " << header.ops_after << " ops after CSE, "
     << header.pre_count << " precomputed values (" << header.pre_ops << " ops)\n";
  // Values the file gives in `derived:` replace the blocks' (their tensor stays about the blocks'
  // centre as given: the file's values are what the model uses), so the line says which.
  os << "mass " << nominal("mass") << " kg" << given(vehicle, {"mass"}) << "; centre of gravity (" << nominal("cog_x")
     << ", " << nominal("cog_y") << ", " << nominal("cog_z") << ") m" << given(vehicle, {"cog_x", "cog_y", "cog_z"});
  // A fitted CoG offset moves the point the thrust's moments act about; the blocks' centre
  // stays what the file describes, so both are said.
  const auto has = [&](const std::string& name) {
    return std::any_of(model.params.begin(), model.params.end(), [&](const auto& p) { return p.name == name; });
  };
  if (has("cog_offset.x") && (nominal("cog_offset.x") != 0 || nominal("cog_offset.y") != 0))
    os << ", moved by the fitted cog_offset (" << nominal("cog_offset.x") << ", " << nominal("cog_offset.y") << ") m";
  os << "; inertia J_xx, J_yy, J_zz " << nominal("J_xx") << ", " << nominal("J_yy") << ", " << nominal("J_zz")
     << " kg m^2" << given(vehicle, {"J_xx", "J_yy", "J_zz", "J_xy", "J_xz", "J_yz"}) << "\n";
  for (const AuditCheck* w : d.audit.warnings())
    os << "warning: the vehicle: " << w->name << ": no; " << w->detail << "\n";
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
  r.summary = summary_of(vehicle, d, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  return r;
}

}  // namespace quadgen::app
