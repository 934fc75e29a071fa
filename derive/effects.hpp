// Model extensions (contracts.md §3). Each effect is a self-contained symbolic change:
// it declares its parameters (and states or inputs) and rewrites the intermediate
// quantities of the model context. At their nominal values the model is unchanged.
#pragma once
#include <functional>
#include <string>
#include <vector>

#include "dynamics.hpp"

namespace quadgen {

struct Effect {
  std::string name;
  std::string meaning;
  std::function<void(ModelContext&)> apply;
};

// All effects in canonical order (the order they are applied in, whatever the user wrote).
const std::vector<Effect>& effect_catalogue();

// Parses "motor_gain,motor_lag" or "all"; rejects unknown or repeated names.
std::vector<std::string> parse_effect_list(const std::string& text);

}  // namespace quadgen
