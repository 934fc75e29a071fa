// The generated model as firmware would use it, compiled for a Cortex-M4F by
// scripts/firmware_check.sh: float only, f alone and f with all Jacobians, parameters set
// once. MODEL_HEADER and MODEL_NAMESPACE name the generated header and its namespace.
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
}
