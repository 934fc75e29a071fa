#include "app/predict_job.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "app/model_registry.hpp"
#include "derive/effects/effect_catalogue.hpp"
#include "fit/flight_data.hpp"
#include "output/json_document.hpp"
#include "output/numbers.hpp"
#include "runtime/log_file.hpp"
#include "runtime/plot.hpp"

namespace quadgen::app {

std::string prediction_summary(const predict::Prediction& pooled) {
  std::ostringstream os;
  for (const auto& h : pooled.open_loop) {
    os << "open loop, " << h.horizon << " s: ";
    if (h.position.count == 0) {
      os << "no rollout reached this horizon" << (h.diverged ? " (" + std::to_string(h.diverged) + " diverged)" : "") << "\n";
      continue;
    }
    os << "position " << output::short_number(h.position.mean()) << " m (mean), tilt "
       << output::short_number(h.tilt.mean()) << " rad, heading " << output::short_number(h.heading.mean()) << " rad\n";
  }
  // A tilt error that falls at a longer horizon is no recovery: an angle between two attitudes
  // is at most pi, and a tumbling model comes back towards the measured one by chance (a
  // newcomer's trial, helper-118: 1.34 rad at 0.5 s, 0.896 at 1 s, said without a word).
  for (size_t k = 1; k < pooled.open_loop.size(); ++k) {
    const auto &shorter = pooled.open_loop[k - 1].tilt, &longer = pooled.open_loop[k].tilt;
    if (shorter.count > 0 && longer.count > 0 && shorter.mean() > 1.0 && longer.mean() < shorter.mean()) {
      os << "  (the tilt error falls after " << output::short_number(shorter.mean())
         << " rad: an angle between two attitudes is at most pi, and past about 1 rad the model has lost its attitude;"
            " a smaller error later is no recovery)\n";
      break;
    }
  }
  // The predictors without the moment model and with no model, a line each.
  const auto positions = [&os](const char* what, const std::vector<predict::HorizonErrors>& rows) {
    if (rows.empty()) return;
    os << what << ", mean position error:";
    for (const auto& h : rows)
      os << (&h == &rows.front() ? " " : ", ") << h.horizon << " s "
         << (h.position.count > 0 ? output::short_number(h.position.mean()) + " m" : "-");
    os << "\n";
  };
  positions("body rates held (no moment model)", pooled.body_rates_held);
  positions("attitude held (no moment model)", pooled.attitude_held);
  positions("constant velocity (no model)", pooled.constant_velocity);
  if (const std::string limits = predict::what_limits_prediction(pooled); !limits.empty()) os << limits << "\n";
  // The one-step errors, and with --linear-correction the corrected ones beside them (a review,
  // helper-111: they reached prediction.json only).
  const auto one_step = [&os](const char* what, const predict::OneStepErrors& e) {
    if (e.vertical_acceleration_world.count > 0) os << what << ", RMS: " << predict::one_step_text(e) << "\n";
  };
  one_step("one step", pooled.one_step);
  if (pooled.one_step_corrected) one_step("one step with the linear correction", *pooled.one_step_corrected);
  for (const auto& h : pooled.set_points_flown)  // --controller: not the open loop, said so
    if (h.position.count > 0)
      os << "set points flown by the attitude loop's replica (not the open loop), " << h.horizon << " s: position "
         << output::short_number(h.position.mean()) << " m (mean), tilt " << output::short_number(h.tilt.mean()) << " rad\n";
  return os.str();
}

namespace {

// What went wrong with the model, for exit code 4 (the output is kept for inspection): at
// some horizon of a view every rollout left the model's range, or the errors are not finite.
// The set points flown are checked too, though no input found so far fails there alone: their
// commands are held within [0, 1], and at the largest accepted --controller-gain (20) the
// loop rings on a generated Crazyflie flight but stays finite (1.7 m off at 1 s).
std::string failure_of(const predict::Prediction& pooled) {
  const auto failed = [](const std::vector<predict::HorizonErrors>& rows) -> const predict::HorizonErrors* {
    for (const auto& h : rows)
      if ((h.position.count == 0 && h.diverged > 0) || (h.position.count > 0 && !std::isfinite(h.position.mean()))) return &h;
    return nullptr;
  };
  std::ostringstream os;
  if (const auto* h = failed(pooled.open_loop))
    os << "the open-loop position error " << h->horizon
       << " s ahead is not finite: the model left its range on this log (check the commands' scale, the units and "
          "--params); the output is kept for inspection";
  else if (const auto* s = failed(pooled.set_points_flown))
    os << "with the set points flown, the position error " << s->horizon
       << " s ahead is not finite: the model left its range under the attitude loop's replica (check "
          "--controller-gain and the set points' units and signs); the output is kept for inspection";
  return os.str();
}

// A log too short for one rollout is the input's problem, not the model's: said before
// anything is written. Logs without a pose have no rollouts at all (one-step errors only).
void check_something_measured(const predict::Prediction& pooled, const PredictJob& job) {
  if (pooled.start_points > 0 || pooled.open_loop.empty()) return;
  double longest = 0;
  for (const auto& h : pooled.open_loop) longest = std::max(longest, h.horizon);
  std::ostringstream os;
  os << "no rollout could start: the evaluated part of the log";
  if (job.logs.size() > 1) os << "s";
  os << " (" << pooled.seconds_of_data << " s; --validation " << job.options.validation
     << " of each flight, at its end) holds no airborne start with " << longest
     << " s of samples ahead (the longest horizon); give a longer flight or a larger --validation";
  throw std::invalid_argument(os.str());
}

}  // namespace

PredictJobResult run_predict_job(const PredictJob& job_in, const Vehicle& v) {
  if (std::string error; !job_in.options.IsValid(&error)) throw std::invalid_argument("predict: " + error);  // before any work
  runtime::refuse_repeated_files(job_in.logs, "flight log");
  PredictJobResult r;
  PredictJob job = job_in;
  if (!job.mapping.empty()) job.options.mapping = fit::load_mapping(job.mapping);  // read once, for every log
  const std::string mapping_environment = job.options.mapping ? job.options.mapping->environment : "";
  job.options.environment = parse_environment(job.environment.empty() ? mapping_environment : job.environment);
  // Every effect, at its neutral value unless --params sets it.
  std::string how;
  const std::unique_ptr<runtime::DynamicModel> model = model_for(v, parse_effect_list("all"), &how);
  job.options.progress.say("model: " + how);
  if (const std::string note = fitted_section_note(v, "predict"); !note.empty()) job.options.progress.say(note);
  const predict::PredictedFlights p = predict::predict_flights(v, *model, model->parameters(), job.logs, job.options);
  check_something_measured(p.pooled, job);
  r.files = {{"prediction.json", output::json_document(p.json)}, {"prediction.csv", predict::prediction_csv(p.pooled)}};
  std::string svg, err;
  if (runtime::render_svg(v.name + ": prediction error against horizon", predict::horizon_panels({{"this model", &p.pooled}}),
                          &svg, &err))
    r.files.emplace_back("prediction.svg", svg);
  else
    r.notes.push_back("no plot: " + err);
  r.summary = prediction_summary(p.pooled);
  r.failure = failure_of(p.pooled);
  return r;
}

}  // namespace quadgen::app
