// Subcommands of the quadgen executable (docs/formats.md, "What each command writes"): each
// one's flags and run in its own header, so that a command's file compiles only its pipeline.
#pragma once
#include "cli/compare_command.hpp"
#include "cli/derive_command.hpp"
#include "cli/diagnose_command.hpp"
#include "cli/fit_command.hpp"
#include "cli/predict_command.hpp"
#include "cli/simulate_command.hpp"
