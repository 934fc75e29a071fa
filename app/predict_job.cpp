#include "app/predict_job.hpp"

#include <cmath>
#include <sstream>

#include "app/model_registry.hpp"
#include "derive/effects/effect_catalogue.hpp"
#include "output/json_document.hpp"
#include "runtime/plot.hpp"

namespace quadgen::app {

namespace {

std::string summary_of(const predict::Prediction& pooled) {
  std::ostringstream os;
  for (const auto& h : pooled.open_loop)
    os << "open loop, " << h.horizon << " s: position " << h.position.mean() << " m (mean), tilt " << h.tilt.mean()
       << " rad, heading " << h.heading.mean() << " rad\n";
  if (const std::string limits = predict::what_limits_prediction(pooled); !limits.empty()) os << limits << "\n";
  return os.str();
}

std::string failure_of(const predict::Prediction& pooled) {
  for (const auto& h : pooled.open_loop)
    if (!std::isfinite(h.position.mean())) {
      std::ostringstream os;
      os << "the open-loop position error " << h.horizon
         << " s ahead is not finite: the model left its range on this log (check the commands' scale, the units and "
            "--params); the output is kept for inspection";
      return os.str();
    }
  return "";
}

}  // namespace

PredictJobResult run_predict_job(const PredictJob& job, const Vehicle& v) {
  PredictJobResult r;
  // Every effect, at its neutral value unless --params sets it.
  std::string how;
  const std::unique_ptr<runtime::DynamicModel> model = model_for(v, parse_effect_list("all"), &how);
  if (job.options.progress) job.options.progress("model: " + how);
  const predict::PredictedFlights p = predict::predict_flights(v, *model, model->parameters(), job.logs, job.options);
  r.files = {{"prediction.json", output::json_document(p.json)}, {"prediction.csv", predict::prediction_csv(p.pooled)}};
  std::string svg, err;
  if (runtime::render_svg(v.name + ": prediction error against horizon", predict::horizon_panels({{"this model", &p.pooled}}),
                          &svg, &err))
    r.files.emplace_back("prediction.svg", svg);
  else
    r.notes.push_back("no plot: " + err);
  r.summary = summary_of(p.pooled);
  r.failure = failure_of(p.pooled);
  return r;
}

}  // namespace quadgen::app
