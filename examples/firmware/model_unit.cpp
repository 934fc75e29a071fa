// The generated model as firmware would use it, compiled for a Cortex-M4F by
// scripts/firmware_check.sh: float only, f alone and f with all Jacobians, the rotor speeds'
// rates alone and the measurement, parameters set once. MODEL_HEADER and MODEL_NAMESPACE name the generated header and its namespace.
#include MODEL_HEADER

namespace m = MODEL_NAMESPACE;

extern "C" {
float quadgen_params[m::kNumParams];
m::Precomputed<float> quadgen_pre;

// After the parameters change (rarely: once at start-up on a flight controller).
void quadgen_precompute(void) { m::precompute(quadgen_params, &quadgen_pre); }

// Every control or estimator step.
void quadgen_f(const float* x, const float* u, float* f) { m::rhs(x, u, quadgen_params, quadgen_pre, f); }

// An EKF or MPC step that needs the Jacobians (sparse, coordinate format).
void quadgen_f_jacobians(const float* x, const float* u, float* f, float* dfdx, float* dfdu, float* dfdp) {
  m::rhs(x, u, quadgen_params, quadgen_pre, f, dfdx, dfdu, dfdp);
}

// A filter of the commands through the motor lag (its rows of f only; none without it).
void quadgen_rotor_speed_rates(const float* x, const float* u, float* f) {
  m::rotor_speed_rates(x, u, quadgen_params, quadgen_pre, f);
}

// An estimator's measurement update: the pose h(x) and its Jacobian.
void quadgen_measurement(const float* x, float* h, float* dhdx) {
  m::measurement(x, quadgen_params, quadgen_pre, h, dhdx, static_cast<float*>(nullptr));
}
}
