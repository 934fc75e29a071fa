// Each effect's descriptor, built in its own file of this folder. catalogue.cpp calls them
// in canonical order; a new effect adds its file, a line here and a line there.
#pragma once
#include "model/effect.hpp"

namespace quadgen::effects {

Effect motor_gain();
Effect motor_lag_spread();
Effect motor_lag();
Effect input_delay();
Effect cog_offset();
Effect wind();
Effect rotor_drag();
Effect blade_flapping();
Effect attitude_bias();
Effect thrust_decay();
Effect battery_sag();
Effect ground_effect();
Effect inflow();

}  // namespace quadgen::effects
