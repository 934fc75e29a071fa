// A flat ground for simulations: the derived model has none, so a replayed log that starts
// with the motors off (a vehicle standing on the floor) would fall until they spin up.
//
// The ground is a constraint applied after each integration step (IntegratorOptions::
// constrain), not a force: the body origin cannot go below `height`. Reaching it, the vehicle
// stops at once (a touch-down without bounce, friction holding it in place) and rests, its
// attitude as it was, while the model's forces push it down; it lifts off as soon as they
// push it up, because a step that ends above the ground is left alone. What the contact does
// to the attitude (a tilted landing levelling on its legs) is not modelled.
#pragma once
#include <vector>

#include "runtime/rigid_body_state.hpp"

namespace quadgen::runtime {

struct GroundContact {
  double height = 0;  // m, world z of the body origin when the vehicle stands on the ground

  // x after a step from `before` (IntegratorOptions::constrain). A vehicle that rested at the
  // step's start keeps its place and attitude: zeroing the velocities after each step alone
  // would let both creep by the accelerations' h^2/2 per step.
  void operator()(const std::vector<double>& before, std::vector<double>& x) const {
    using namespace rigid_body;
    if (!(x[kPosition + 2] < height)) return;
    x[kPosition + 2] = height;
    for (int i = 0; i < 3; ++i) x[kVelocity + i] = x[kBodyRate + i] = 0;
    if (before[kPosition + 2] > height) return;  // touched down in this step: where and as it landed
    for (int i = 0; i < 2; ++i) x[kPosition + i] = before[kPosition + i];
    for (int i = 0; i < 4; ++i) x[kAttitude + i] = before[kAttitude + i];
  }
};

}  // namespace quadgen::runtime
