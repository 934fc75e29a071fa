#include "model_registry.hpp"

#include "generated/crazyflie21/model.hpp"
#include "generated/crazyflie21_all_effects/model.hpp"
#include "generated/finken3/model.hpp"
#include "generated/finken3_all_effects/model.hpp"
#include "tape_builder.hpp"

namespace quadgen::cli {

namespace {
template <class M>
bool matches(const SymbolicModel& m) {
  return m.vehicle_hash == M::kVehicleHash && m.effect_list() == M::kEffects;
}
}  // namespace

std::unique_ptr<runtime::DynamicModel> make_model(const SymbolicModel& m, bool* compiled) {
  namespace g = quadgen_generated;
  if (compiled) *compiled = true;
  if (matches<g::finken3::Model>(m)) return std::make_unique<runtime::CompiledModel<g::finken3::Model>>();
  if (matches<g::finken3_all_effects::Model>(m))
    return std::make_unique<runtime::CompiledModel<g::finken3_all_effects::Model>>();
  if (matches<g::crazyflie21::Model>(m)) return std::make_unique<runtime::CompiledModel<g::crazyflie21::Model>>();
  if (matches<g::crazyflie21_all_effects::Model>(m))
    return std::make_unique<runtime::CompiledModel<g::crazyflie21_all_effects::Model>>();
  if (compiled) *compiled = false;
  return std::make_unique<runtime::TapeModel>(emission::build_tape(m));
}

}  // namespace quadgen::cli
