#include "runtime/tape.hpp"

#include <cmath>

namespace quadgen::runtime {

namespace {
void run(const std::vector<Instruction>& code, double* r) {
  for (const Instruction& in : code) {
    const double a = r[in.a];
    double v = 0;
    switch (in.op) {
      case TapeOp::add: v = a + r[in.b]; break;
      case TapeOp::mul: v = a * r[in.b]; break;
      case TapeOp::div: v = a / r[in.b]; break;
      case TapeOp::ipow: {
        v = 1;
        for (long i = 0; i < in.k; ++i) v *= a;
        break;
      }
      case TapeOp::pow: v = std::pow(a, r[in.b]); break;
      case TapeOp::sin: v = std::sin(a); break;
      case TapeOp::cos: v = std::cos(a); break;
      case TapeOp::log: v = std::log(a); break;
      case TapeOp::abs: v = std::fabs(a); break;
      case TapeOp::sign: v = a > 0 ? 1.0 : (a < 0 ? -1.0 : 0.0); break;
    }
    r[in.dst] = v;
  }
}
void scatter(double* dense, int rows, int cols, const SparseOutputs& s, const double* r) {
  for (int i = 0; i < rows * cols; ++i) dense[i] = 0;
  for (size_t k = 0; k < s.reg.size(); ++k) dense[s.row[k] * cols + s.col[k]] = r[s.reg[k]];
}
}  // namespace

TapeModel::TapeModel(Tape t) : tape_(std::move(t)), reg_(tape_.num_registers, 0.0) {
  for (const auto& [r, v] : tape_.constants) reg_[r] = v;
  dfdp_code_ = tape_.dfdp_code;
  dfdp_ = tape_.dfdp;
  set_params(tape_.nominal);
}

void TapeModel::restrict_param_jacobian(const std::vector<int>& columns) {
  if (columns == restricted_to_) return;  // a cache: the same columns as the last call
  restricted_to_ = columns;
  if (columns.empty()) {
    dfdp_code_ = tape_.dfdp_code;
    dfdp_ = tape_.dfdp;
    return;
  }
  std::vector<char> want_col(tape_.np, 0), live(tape_.num_registers, 0);
  for (int c : columns) want_col[c] = 1;
  dfdp_ = SparseOutputs{};
  for (size_t k = 0; k < tape_.dfdp.reg.size(); ++k)
    if (want_col[tape_.dfdp.col[k]]) {
      dfdp_.row.push_back(tape_.dfdp.row[k]);
      dfdp_.col.push_back(tape_.dfdp.col[k]);
      dfdp_.reg.push_back(tape_.dfdp.reg[k]);
      live[tape_.dfdp.reg[k]] = 1;
    }
  // Each register is written once in this straight-line code: walking backwards, an
  // instruction is needed when its result is, and then so are its operands.
  std::vector<Instruction> kept;
  for (auto it = tape_.dfdp_code.rbegin(); it != tape_.dfdp_code.rend(); ++it) {
    if (!live[it->dst]) continue;
    kept.push_back(*it);
    live[it->a] = 1;
    if (it->op == TapeOp::add || it->op == TapeOp::mul || it->op == TapeOp::div || it->op == TapeOp::pow) live[it->b] = 1;
  }
  dfdp_code_.assign(kept.rbegin(), kept.rend());
}

void TapeModel::set_params(const std::vector<double>& p) {
  p_ = p;
  for (int i = 0; i < tape_.np; ++i) reg_[tape_.p_reg(i)] = p[i];
  run(tape_.precompute, reg_.data());
}

std::vector<Parameter> TapeModel::parameters() const {
  std::vector<Parameter> out;
  for (int i = 0; i < tape_.np; ++i)
    out.push_back({tape_.param_names[i], tape_.param_units[i], p_[i], tape_.param_lower[i], tape_.param_upper[i],
                   tape_.param_fit[i] != 0});
  return out;
}

void TapeModel::measurement(const double* x, double /*t*/, double* h, double* H, double* Hp) const {
  double* r = reg_.data();
  for (int i = 0; i < tape_.nx; ++i) r[i] = x[i];
  run(tape_.h_code, r);
  for (int i = 0; i < tape_.ny; ++i) h[i] = r[tape_.h_out[i]];
  if (H) scatter(H, tape_.ny, tape_.nx, tape_.dhdx, r);
  if (Hp) scatter(Hp, tape_.ny, tape_.np, tape_.dhdp, r);
}

void TapeModel::rhs(const double* x, const double* u, double* f, double* A, double* B, double* Bu) const {
  double* r = reg_.data();
  for (int i = 0; i < tape_.nx; ++i) r[i] = x[i];
  for (int i = 0; i < tape_.nu; ++i) r[tape_.nx + i] = u[i];
  run(tape_.f_code, r);
  for (int i = 0; i < tape_.nx; ++i) f[i] = r[tape_.f_out[i]];
  // Each Jacobian's code computes only what it needs beyond f; nodes shared between
  // Jacobians are recomputed, which is cheaper than computing Jacobians nobody asked for.
  if (A) {
    run(tape_.dfdx_code, r);
    scatter(A, tape_.nx, tape_.nx, tape_.dfdx, r);
  }
  if (B) {
    run(dfdp_code_, r);
    scatter(B, tape_.nx, tape_.np, dfdp_, r);
  }
  if (Bu) {
    run(tape_.dfdu_code, r);
    scatter(Bu, tape_.nx, tape_.nu, tape_.dfdu, r);
  }
}

}  // namespace quadgen::runtime
