#include "app/derive_pipeline.hpp"

#include "audit/report.hpp"

namespace quadgen {

DerivedModel run_derive_pipeline(const Vehicle& vehicle, const MassProperties& mass, const DeriveRequest& request) {
  auto progress = [&](const char* step) {
    if (request.progress) request.progress(step);
  };
  DerivedModel out;
  progress("equations of motion and Jacobians");
  out.model = derive_model(vehicle, mass, request.derive);
  if (request.set_nominal) request.set_nominal(out.model);
  progress("audit");
  out.audit = audit(out.model, mass);
  if (request.thesis_comparison) out.thesis = compare_with_thesis(out.model, mass);
  progress("generating C++");
  codegen::EmitOptions emit = request.emit;
  if (request.effects_flag_from_model)
    emit.effects_flag = out.model.effects.empty() ? "" : " --effects " + out.model.effect_list();
  out.header = codegen::generate_header(out.model, emit);
  const Derivation d{vehicle, mass, out.model, out.audit, out.thesis};
  out.model_json = model_json(d);
  out.derivation_md = derivation_markdown(d);
  return out;
}

}  // namespace quadgen
