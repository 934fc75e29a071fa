#include "equation_error.hpp"

#include <cmath>

namespace quadgen::fit {

EquationErrorModel::EquationErrorModel(runtime::DynamicModel& model, Flight flight, bool use_accelerometer,
                                       std::vector<std::string> use)
    : model_(model), flight_(std::move(flight)), accel_(use_accelerometer), g_index_(model.param_index("g")) {
  const auto names = all_names();
  if (use.empty()) use = names;
  for (const auto& u : use) {
    const int c = runtime::index_in(names, u);
    if (c < 0) throw FitError("unknown residual channel '" + u + "'");
    used_.push_back(c);
  }
  if (model.num_states() != 13)
    throw FitError("equation error needs every state measured; this model has states a log does not record (" +
                   model.state_names()[13] + ")");
  if (accel_ && !flight_.has_accelerometer) throw FitError(flight_.source + ": no accelerometer columns ax, ay, az");
  if (!accel_ && !flight_.has_pose) throw FitError(flight_.source + ": no pose to differentiate");
}

std::vector<std::string> EquationErrorModel::all_names() const {
  if (accel_) return {"ax", "ay", "az", "pdot", "qdot", "rdot"};
  return {"ax", "ay", "az", "pdot", "qdot", "rdot"};  // world-frame accelerations when no accelerometer
}

void EquationErrorModel::set_free(const std::vector<bool>& free) const {
  std::vector<int> cols;
  for (size_t j = 0; j < free.size(); ++j)
    if (free[j]) cols.push_back(static_cast<int>(j));
  model_.restrict_param_jacobian(cols);
}

std::vector<std::string> EquationErrorModel::channels() const {
  const auto names = all_names();
  std::vector<std::string> out;
  for (int c : used_) out.push_back(names[c]);
  return out;
}

void EquationErrorModel::evaluate(const double* p, double* r, double* J) const {
  if (used_.size() == 6) return evaluate6(p, r, J);
  const int np = model_.num_params();
  const size_t ns = flight_.samples.size();
  std::vector<double> r6(ns * 6), J6(J ? ns * 6 * np : 0);
  evaluate6(p, r6.data(), J ? J6.data() : nullptr);
  const size_t nu = used_.size();
  for (size_t k = 0; k < ns; ++k)
    for (size_t c = 0; c < nu; ++c) {
      r[k * nu + c] = r6[k * 6 + used_[c]];
      if (J)
        for (int j = 0; j < np; ++j) J[(k * nu + c) * np + j] = J6[(k * 6 + used_[c]) * np + j];
    }
}

void EquationErrorModel::all_channels(const double* p, std::vector<double>& r6) const {
  r6.resize(flight_.samples.size() * 6);
  evaluate6(p, r6.data(), nullptr);
}

void EquationErrorModel::evaluate6(const double* p, double* r, double* J) const {
  const int n = model_.num_states(), np = model_.num_params(), nu = model_.num_inputs();
  model_.set_params(std::vector<double>(p, p + np));
  std::vector<double> u(nu), f(n), B(J ? n * np : 0);
  const int t_in = model_.input_index("t"), v_in = model_.input_index("vbat");
  for (size_t k = 0; k < flight_.samples.size(); ++k) {
    const FlightSample& s = flight_.samples[k];
    for (size_t i = 0; i < s.u.size(); ++i) u[i] = s.u[i];
    if (t_in >= 0) u[t_in] = s.t;
    if (v_in >= 0) u[v_in] = s.vbat;
    model_.rhs(s.x.data(), u.data(), f.data(), nullptr, J ? B.data() : nullptr, nullptr);
    double* rk = r + 6 * k;
    // Body -> world rotation of the measured attitude.
    const double w = s.x[6], x = s.x[7], y = s.x[8], z = s.x[9];
    const double R[3][3] = {{1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)},
                            {2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)},
                            {2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)}};
    const double g = p[g_index_];
    for (int i = 0; i < 3; ++i) {
      if (accel_) {  // specific force in body axes: R^T (a + g e_z)
        double sf = 0;
        for (int j = 0; j < 3; ++j) sf += R[j][i] * (f[3 + j] + (j == 2 ? g : 0.0));
        rk[i] = sf - s.specific_force[i];
      } else {
        rk[i] = f[3 + i] - s.acc_world[i];
      }
      rk[3 + i] = f[10 + i] - s.rate_dot[i];
    }
    if (!J) continue;
    double* Jk = J + static_cast<size_t>(6 * k) * np;
    for (int c = 0; c < np; ++c) {
      for (int i = 0; i < 3; ++i) {
        double d;
        if (accel_) {
          d = 0;
          for (int j = 0; j < 3; ++j) d += R[j][i] * (B[(3 + j) * np + c] + (j == 2 && c == g_index_ ? 1.0 : 0.0));
        } else {
          d = B[(3 + i) * np + c];
        }
        Jk[i * np + c] = d;
        Jk[(3 + i) * np + c] = B[(10 + i) * np + c];
      }
    }
  }
}

}  // namespace quadgen::fit
