#include "app/model_registry.hpp"

#include "generated/crazyflie21/model.hpp"
#include "generated/crazyflie21_all_effects/model.hpp"
#include "generated/crazyflie21_nanobench/model.hpp"
#include "generated/crazyflie21_nanobench_all_effects/model.hpp"
#include "generated/finken3/model.hpp"
#include "generated/finken3_all_effects/model.hpp"
#include "derive/dynamics.hpp"
#include "derive/effects/effect_catalogue.hpp"
#include "derive/geometry.hpp"
#include "codegen/tape_builder.hpp"

namespace quadgen::app {

namespace {
template <class M>
std::unique_ptr<runtime::DynamicModel> compiled_if(const std::string& vehicle_hash, const std::string& effects) {
  if (vehicle_hash != M::kVehicleHash || effects != M::kEffects) return nullptr;
  return std::make_unique<runtime::CompiledModel<M>>();
}

// The header generated from this vehicle file hash and canonical effect list, if any.
std::unique_ptr<runtime::DynamicModel> find_compiled(const std::string& hash, const std::string& effects) {
  namespace g = quadgen_generated;
  for (auto make : {compiled_if<g::finken3::Model>, compiled_if<g::finken3_all_effects::Model>,
                    compiled_if<g::crazyflie21::Model>, compiled_if<g::crazyflie21_all_effects::Model>,
                    compiled_if<g::crazyflie21_nanobench::Model>, compiled_if<g::crazyflie21_nanobench_all_effects::Model>})
    if (auto m = make(hash, effects)) return m;
  return nullptr;
}
}  // namespace

std::unique_ptr<runtime::DynamicModel> make_model(const SymbolicModel& m, bool* compiled) {
  auto model = find_compiled(m.vehicle_hash, m.effect_list());
  if (compiled) *compiled = model != nullptr;
  return model ? std::move(model) : std::make_unique<runtime::TapeModel>(codegen::build_tape(m));
}

std::unique_ptr<runtime::DynamicModel> compiled_model_for(const Vehicle& v, const std::vector<std::string>& effects) {
  return find_compiled(v.content_hash, canonical_effect_list(effects));
}

std::unique_ptr<runtime::DynamicModel> model_for(const Vehicle& v, const std::vector<std::string>& effects,
                                                 std::string* how) {
  if (auto compiled = compiled_model_for(v, effects)) {
    if (how) *how = "compiled header from generated/ (no derivation needed)";
    return compiled;
  }
  DeriveOptions o;
  o.effects = effects;
  if (how) *how = "interpreted tape (no matching generated header)";
  return make_model(derive_model(v, derive_mass_properties(v), o));
}

}  // namespace quadgen::app
