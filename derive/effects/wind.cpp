// wind: a steady air velocity in the world frame. It acts only through the terms that
// depend on the air-relative velocity (the drag of the vehicle file, rotor_drag,
// blade_flapping, inflow), which is why it comes before them in the catalogue.
#include <cmath>

#include "derive/effects/definitions.hpp"
#include "derive/dynamics.hpp"
#include "derive/effects/headline_words.hpp"
#include "derive/kinematics.hpp"

namespace quadgen::effects {
using namespace GiNaC;

namespace {

void terms(ModelContext& c) {
  const ex wx = c.add_param("wind.x", "m/s", 0.0, -10.0, 10.0, true, "steady wind x, world");
  const ex wy = c.add_param("wind.y", "m/s", 0.0, -10.0, 10.0, true, "steady wind y, world");
  c.air_velocity_world = c.air_velocity_world.sub(vec3(wx, wy, 0));
}

std::string headline(const std::map<std::string, double>& v, const std::string&) {
  using headline::words;
  const double x = headline::value_of(v, "wind.x"), y = headline::value_of(v, "wind.y");
  return "A steady wind of " + words(std::hypot(x, y)) + " m/s (x " + words(x) + ", y " + words(y) + " m/s, world frame).";
}

}  // namespace

Effect wind() {
  Effect e;
  e.name = "wind";
  e.meaning = "steady air velocity in the world frame, through the drag terms";
  e.apply = terms;
  e.parameter_names = "wind.x/y";  // as --help lists them
  e.per_flight = true;
  e.judged_by_force_model = true;
  e.plausible = {{"", -0.5, 0.5, PlausibleRange::Scale::kSI, Environment::kIndoor,
                  "indoors the air is still but for ventilation drafts of a few dm/s"},
                 {"", -15.0, 15.0, PlausibleRange::Scale::kSI, Environment::kUnknown,
                  "small multirotors are not flown beyond about Beaufort 6-7 (11-15 m/s)"}};
  e.headline = headline;
  return e;
}

}  // namespace quadgen::effects
