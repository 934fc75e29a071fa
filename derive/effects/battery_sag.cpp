// battery_sag: thrust scaled by (vbat / vbat_ref)^exponent, when the log holds the battery
// voltage.
#include "derive/effects/definitions.hpp"
#include "derive/dynamics.hpp"
#include "derive/effects/headline_words.hpp"

namespace quadgen::effects {
using namespace GiNaC;

namespace {

void terms(ModelContext& c) {
  const ex e = c.add_param("battery_sag.exponent", "1", 0.0, -1.0, 4.0, true, "thrust ~ (vbat/vbat_ref)^exponent");
  ParameterSpec ref = param(c.vehicle, "vbat_ref");  // a constant of this effect: held
  ref.lower = ref.upper = ref.nominal;
  ref.fit = false;
  const ex vref = c.add_param(ref);
  const ex vbat = c.add_input("vbat", "V", "battery voltage");
  for (ex& s : c.thrust_scale) s = s * pow(vbat / vref, e);
}

}  // namespace

Effect battery_sag() {
  Effect e;
  e.name = "battery_sag";
  e.meaning = "thrust scaled by (vbat / vbat_ref)^exponent";
  e.apply = terms;
  e.parameter_names = "battery_sag.exponent";  // as --help lists them
  e.needs = EffectNeeds::kBatteryVoltage;
  e.plausible = {{"battery_sag.exponent", 0.0, 3.0, PlausibleRange::Scale::kSI, Environment::kUnknown,
                  "at a fixed duty cycle rotor speed grows about with voltage and thrust with its square: ~2"}};
  e.headline = [](const std::map<std::string, double>& v, const std::string&) {
    return "Thrust follows the battery voltage to the power " +
           headline::words(headline::value_of(v, "battery_sag.exponent")) + ".";
  };
  return e;
}

}  // namespace quadgen::effects
