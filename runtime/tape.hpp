// A straight-line program over registers that evaluates a model's expression DAG at run
// time: the interpreted twin of a generated header (same DAG, same operations).
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "runtime/dynamic_model.hpp"

namespace quadgen::runtime {

enum class TapeOp : uint8_t { add, mul, div, ipow, pow, sin, cos, log, abs, sign };

struct Instruction {
  TapeOp op;
  int dst, a, b;  // registers; b unused for unary ops
  long k = 0;     // ipow exponent
};

struct SparseOutputs {
  std::vector<int> row, col, reg;
};

struct Tape {
  int nx = 0, nu = 0, np = 0;
  int num_registers = 0;
  std::vector<std::pair<int, double>> constants;  // register, value
  std::vector<Instruction> precompute;  // parameters only: run on set_params
  std::vector<Instruction> f_code;      // enough for f
  std::vector<Instruction> dfdx_code, dfdp_code, dfdu_code;  // the rest, per Jacobian
  std::vector<int> f_out;
  SparseOutputs dfdx, dfdp, dfdu;
  // The measurement h(x, p) and its Jacobians, in one piece of code after f's.
  int ny = 0;
  std::vector<Instruction> h_code;
  std::vector<int> h_out;
  SparseOutputs dhdx, dhdp;
  std::vector<std::string> state_names, input_names, param_names;
  std::vector<double> nominal;
  std::vector<std::string> param_units;
  std::vector<double> param_lower, param_upper;
  std::vector<char> param_fit;
  int input_delay_param = -1;
  // Registers 0..nx-1 are x, then u, then p, then constants and nodes.
  int x_reg(int i) const { return i; }
  int u_reg(int i) const { return nx + i; }
  int p_reg(int i) const { return nx + nu + i; }
};

class TapeModel : public DynamicModel {
 public:
  explicit TapeModel(Tape t);
  int num_states() const override { return tape_.nx; }
  int num_inputs() const override { return tape_.nu; }
  int num_params() const override { return tape_.np; }
  const std::vector<std::string>& state_names() const override { return tape_.state_names; }
  const std::vector<std::string>& input_names() const override { return tape_.input_names; }
  const std::vector<std::string>& param_names() const override { return tape_.param_names; }
  const std::vector<double>& params() const override { return p_; }
  void set_params(const std::vector<double>& p) override;
  void rhs(const double* x, const double* u, double* f, double* A, double* B, double* Bu) const override;
  void restrict_param_jacobian(const std::vector<int>& columns) override;
  std::unique_ptr<DynamicModel> clone() const override { return std::make_unique<TapeModel>(*this); }
  std::vector<Parameter> parameters() const override;
  int num_outputs() const override { return tape_.ny; }
  void measurement(const double* x, double t, double* h, double* H, double* Hp) const override;
  int input_delay_param() const override { return tape_.input_delay_param; }

 private:
  Tape tape_;
  std::vector<double> p_;
  // dfdp code and outputs pruned to the requested columns (backward liveness).
  std::vector<Instruction> dfdp_code_;
  SparseOutputs dfdp_;
  std::vector<int> restricted_to_;  // the columns dfdp_code_ computes (empty: all)
  mutable std::vector<double> reg_;
};

}  // namespace quadgen::runtime
