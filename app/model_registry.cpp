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
#include "output/numbers.hpp"

namespace quadgen::app {

namespace {

std::vector<std::string> names_of(const std::vector<Variable>& vars) {
  std::vector<std::string> out;
  for (const Variable& v : vars) out.push_back(v.name);
  return out;
}

// Equal but for rounding: a compiler that contracts a*b+c may round a derived quantity
// differently from the machine that generated the header. The header's array has the length
// of `vars` (names_equal checks it first).
bool values_equal(const double* header, const std::vector<Variable>& vars) {
  for (size_t i = 0; i < vars.size(); ++i)
    if (!output::equal_but_for_rounding(vars[i].nominal, header[i])) return false;
  return true;
}

bool names_equal(const char* const* header, int count, const std::vector<std::string>& names) {
  if (names.size() != static_cast<size_t>(count)) return false;
  for (int i = 0; i < count; ++i)
    if (names[i] != header[i]) return false;
  return true;
}

// A header runs in place of derivation `m` only where it was generated from the same vehicle
// file (its SHA-256, model/sha256.hpp: no file can pass for another) and effects, and where
// its states, inputs, parameters and nominal values are the derivation's, so that no header
// ever runs with another vehicle's shape (a simulation writes one command per rotor into an
// input vector of the header's size). A forgeable FNV-1a hash once let a six-rotor file run
// on a four-rotor header. The fixed numbers its code holds (rotor places, radii, areas) are
// compared too; the rotors' spins and the parameters' bounds rest on the hash alone.
template <class M>
std::unique_ptr<runtime::DynamicModel> compiled_if(const SymbolicModel& m) {
  if (m.vehicle_hash != M::kVehicleHash || m.effect_list() != M::kEffects) return nullptr;
  if (!names_equal(M::kStateNames, M::kNumStates, names_of(m.states)) ||
      !names_equal(M::kInputNames, M::kNumInputs, names_of(m.inputs)) ||
      !names_equal(M::kParamNames, M::kNumParams, names_of(m.params)) ||
      !names_equal(M::kConstantNames, M::kNumConstants, names_of(m.constants)))
    return nullptr;
  if (!values_equal(M::kNominalParams, m.params) || !values_equal(M::kConstantValues, m.constants)) return nullptr;
  return std::make_unique<runtime::CompiledModel<M>>();
}

// The header generated from this derivation's vehicle file and effects, if any.
std::unique_ptr<runtime::DynamicModel> find_compiled(const SymbolicModel& m) {
  namespace g = quadgen_generated;
  for (auto make : {compiled_if<g::finken3::Model>, compiled_if<g::finken3_all_effects::Model>,
                    compiled_if<g::crazyflie21::Model>, compiled_if<g::crazyflie21_all_effects::Model>,
                    compiled_if<g::crazyflie21_nanobench::Model>, compiled_if<g::crazyflie21_nanobench_all_effects::Model>})
    if (auto model = make(m)) return model;
  return nullptr;
}

}  // namespace

std::unique_ptr<runtime::DynamicModel> make_model(const SymbolicModel& m, bool* compiled) {
  auto model = find_compiled(m);
  if (compiled) *compiled = model != nullptr;
  return model ? std::move(model) : std::make_unique<runtime::TapeModel>(codegen::build_tape(m));
}

std::unique_ptr<runtime::DynamicModel> model_for(const Vehicle& v, const std::vector<std::string>& effects,
                                                 std::string* how) {
  // Derived first, whether or not a header matches (about 0.2 s with every effect): the
  // derivation is what a header must equal to be used.
  DeriveOptions o;
  o.effects = effects;
  bool compiled = false;
  auto model = make_model(derive_model(v, derive_mass_properties(v), o), &compiled);
  if (how)
    *how = compiled ? "compiled header from generated/ (the derivation matches it)"
                    : "interpreted from the vehicle file (no header compiled into quadgen matches it: normal for "
                      "your own vehicle, the same numbers, slower; README, \"the tape\")";
  return model;
}

}  // namespace quadgen::app
