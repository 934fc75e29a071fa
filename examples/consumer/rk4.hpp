// One classical Runge-Kutta step, shared by the consumer examples. The model is passed as a
// callable f(x, dxdt) so that any generated namespace (with or without effects) fits.
#pragma once

template <int N, typename S, typename Rhs>
void rk4_step(S* x, S h, const Rhs& f) {
  S k1[N], k2[N], k3[N], k4[N], xt[N];
  f(x, k1);
  for (int i = 0; i < N; ++i) xt[i] = x[i] + h / 2 * k1[i];
  f(xt, k2);
  for (int i = 0; i < N; ++i) xt[i] = x[i] + h / 2 * k2[i];
  f(xt, k3);
  for (int i = 0; i < N; ++i) xt[i] = x[i] + h * k3[i];
  f(xt, k4);
  for (int i = 0; i < N; ++i) x[i] += h / 6 * (k1[i] + 2 * k2[i] + 2 * k3[i] + k4[i]);
}
