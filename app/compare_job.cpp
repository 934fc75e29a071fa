#include "app/compare_job.hpp"

#include "app/derive_pipeline.hpp"
#include "audit/derivation_comparison.hpp"
#include "derive/effects/effect_catalogue.hpp"
#include "output/joined.hpp"
#include "output/sinks.hpp"

namespace quadgen::app {

namespace {

struct Derived {
  Vehicle vehicle;
  SymbolicModel model;
  std::string note;
};

// The symbolic model derive would emit for the file: its effects, its fitted values as the
// nominal ones. Not audited or generated: the comparison needs the equations only.
Derived derive_for_comparison(const std::string& path, const std::string& effects) {
  Derived d{load_vehicle(path), {}, ""};
  DeriveRequest request;
  request.derive.effects = parse_effect_list(effects);
  try {
    d.note = use_fitted_values(request, d.vehicle, path, "", !effects.empty());
  } catch (const EffectsNotTheFittedOnes& e) {
    // derive's words for this ("leave it out") would not say that --effects is both files'.
    throw std::invalid_argument(output::printable(path) + ": its fitted: section's effects (" + output::joined(e.fitted) +
                                ") are not --effects; compare derives both files with --effects: leave it out to "
                                "derive each file with its own fitted effects (none without a fitted: section)");
  }
  d.model = requested_model(d.vehicle, derive_mass_properties(d.vehicle), request);
  return d;
}

}  // namespace

CompareJobResult run_compare_job(const CompareJob& job) {
  const auto progress = [&](const std::string& what) {
    if (job.progress) job.progress(what);
  };
  progress("deriving A");
  const Derived a = derive_for_comparison(job.vehicle_a, job.effects);
  progress("deriving B");
  const Derived b = derive_for_comparison(job.vehicle_b, job.effects);
  progress("comparing");
  const DerivationComparison c = compare_derivations({a.vehicle, a.model}, {b.vehicle, b.model});
  CompareJobResult r;
  r.text = comparison_text(c, job.vehicle_a, job.vehicle_b);
  for (const auto& [side, note] : {std::pair{"A", a.note}, std::pair{"B", b.note}})
    if (!note.empty()) r.notes.push_back(std::string(side) + ": " + note);
  r.same = c.same();
  return r;
}

}  // namespace quadgen::app
