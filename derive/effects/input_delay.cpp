// input_delay: a pure time shift between the logged commands and their effect.
#include "derive/effects/definitions.hpp"
#include "derive/dynamics.hpp"
#include "derive/effects/headline_words.hpp"

namespace quadgen::effects {

namespace {

// Not an ODE term: the runtime evaluates u(t - d) and the model only carries the parameter
// (SymbolicModel::input_delay_param, DynamicModel::input_delay_param()).
void terms(ModelContext& c) {
  c.add_param("input_delay.seconds", "s", 0.0, 0.0, 0.2, true, "time shift between logged commands and their effect");
  c.model.input_delay_param = c.model.params.size() - 1;
}

}  // namespace

Effect input_delay() {
  Effect e;
  e.name = "input_delay";
  e.meaning = "pure time shift between logged commands and their effect";
  e.apply = terms;
  e.parameter_names = "input_delay.seconds";  // as --help lists them
  e.acts_on = Effect::ActsOn::kCommands;
  e.typical_start = {{"input_delay.seconds", 0.015}};
  e.domain = {{"input_delay.seconds", 0.0, true, "a delay below zero would act on commands not yet sent"}};
  e.plausible = {{"input_delay.seconds", 0.0, 0.1, PlausibleRange::Scale::kSI, Environment::kUnknown,
                  "logging and radio latencies are one to a few control periods (10-50 ms)"}};
  e.headline = [](const std::map<std::string, double>& v, const std::string&) {
    return "Commands act " + headline::words(1e3 * headline::value_of(v, "input_delay.seconds")) +
           " ms after they are logged.";
  };
  return e;
}

}  // namespace quadgen::effects
