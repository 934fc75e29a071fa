#include "app/fit_job.hpp"

#include <memory>
#include <stdexcept>

#include "app/model_registry.hpp"
#include "derive/effects/effect_catalogue.hpp"
#include "output/json_document.hpp"

namespace quadgen::app {

FitJobResult run_fit_job(const FitJob& job, const Vehicle& v, fit::LogKind kind) {
  if (std::string error; !job.options.IsValidFor(kind, &error)) throw std::invalid_argument("fit: " + error);
  if (!job.effects.empty())
    if (const std::string why = fit::why_unused("effects", kind, job.options.formulation); !why.empty())
      throw std::invalid_argument("fit: effects: " + why);
  FitJobResult r;
  // Said as the work goes, before the fit's own steps (job.options.progress).
  if (const std::string note = fitted_section_note(v, "fit"); !note.empty()) job.options.progress(note);
  fit::FitOutputs fitted;
  if (kind == fit::LogKind::kMotorSteps) {
    fitted = fit::fit_motor_steps_log(job.log, v, job.options);
  } else if (kind == fit::LogKind::kThrustStand) {
    fitted = fit::fit_thrust_stand_log(job.log, v, job.options);
  } else {
    std::string how;
    const std::unique_ptr<runtime::DynamicModel> model = model_for(v, parse_effect_list(job.effects), &how);
    job.options.progress("model: " + how);
    fitted = fit::fit_flight_log(job.log, v, *model, job.options);
  }
  r.files.emplace_back("fit.json", output::json_document(fitted.json));
  for (const auto& plot : fitted.plots) r.files.push_back(plot);
  for (const auto& err : fitted.plot_errors) r.notes.push_back("no plot " + err);
  r.summary = fitted.summary;
  r.warnings = fitted.warnings;
  return r;
}

}  // namespace quadgen::app
