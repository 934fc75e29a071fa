// A straight-line program over registers that evaluates a model at run time: the
// interpreted twin of a generated header. It is lowered from the same plan as the header
// (codegen/lowered_plan), so it performs the header's operations in the header's order and
// its results are the header's, bit for bit.
#pragma once
#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "runtime/dynamic_model.hpp"

namespace quadgen::runtime {

// abs: v < 0 ? -v : v, and sign: -1, 0 or 1, as the header's abs_value and sign_of.
enum class TapeOp : uint8_t { add, sub, mul, div, neg, pow, sin, cos, log, abs, sign };

struct Instruction {
  TapeOp op;
  int dst, a, b;  // registers; b unused for unary ops
};

inline bool is_binary(TapeOp op) {
  return op == TapeOp::add || op == TapeOp::sub || op == TapeOp::mul || op == TapeOp::div || op == TapeOp::pow;
}

struct SparseOutputs {
  std::vector<int> row, col, reg;
};

// `count` consecutive instructions of one operation.
struct OpRun {
  TapeOp op;
  uint32_t count;
};

// One function of the header (rhs or measurement) as instructions. Group 0 is the value
// (f, or h; col 0), then its Jacobians in the header's sparse layout: rhs: dfdx, dfdu,
// dfdp; measurement: dhdx, dhdp. Every register is written once.
//
// As lowered, the code is in the header's order. The model runs it scheduled
// (schedule_by_level): ordered by dependency level, each level's instructions grouped by
// operation into `runs`, so the interpreter dispatches once per run rather than once per
// instruction. Each instruction still applies the same operation to the same operands, so
// the results are the header's bit for bit; only independent instructions change places.
struct TapeFunction {
  std::vector<Instruction> code;
  std::vector<SparseOutputs> groups;
  std::vector<OpRun> runs;  // empty until scheduled
};

// Reorders `fn.code` by dependency level (an instruction's level is one more than its
// operands' highest; x, u, p and constants are level 0), then by operation within a level,
// keeping the lowered order otherwise, and sets `fn.runs`.
void schedule_by_level(TapeFunction& fn, int num_registers);

struct Tape {
  int nx = 0, nu = 0, np = 0, ny = 0;
  int num_registers = 0;
  std::vector<std::pair<int, double>> constants;  // register, value
  std::vector<Instruction> precompute;  // parameters only: run on set_params
  TapeFunction rhs, measurement;
  std::vector<std::string> state_names, input_names, param_names;
  std::vector<double> nominal;
  std::vector<std::string> param_units;
  std::vector<double> param_lower, param_upper;
  std::vector<char> param_fit;
  int input_delay_param = -1;
  std::vector<int> rotor_speed_states;  // DynamicModel::rotor_speed_states()
  // Registers 0..nx-1 are x, then u, then p, then constants and nodes.
  int x_reg(int i) const { return i; }
  int u_reg(int i) const { return nx + i; }
  int p_reg(int i) const { return nx + nu + i; }
};

class TapeModel : public DynamicModel {
 public:
  explicit TapeModel(Tape t);
  int num_states() const override { return tape_->nx; }
  int num_inputs() const override { return tape_->nu; }
  int num_params() const override { return tape_->np; }
  const std::vector<std::string>& state_names() const override { return tape_->state_names; }
  const std::vector<std::string>& input_names() const override { return tape_->input_names; }
  const std::vector<std::string>& param_names() const override { return tape_->param_names; }
  const std::vector<double>& params() const override { return p_; }
  void set_params(const std::vector<double>& p) override;
  void rhs(const double* x, const double* u, double* f, double* A, double* B, double* Bu) const override;
  void rhs_rows(const double* x, const double* u, const std::vector<int>& rows, double* f) const override;
  void restrict_param_jacobian(const std::vector<int>& columns) override;
  std::unique_ptr<DynamicModel> clone() const override { return std::make_unique<TapeModel>(*this); }
  std::vector<Parameter> parameters() const override;
  int num_outputs() const override { return tape_->ny; }
  void measurement(const double* x, double t, double* h, double* H, double* Hp) const override;
  int input_delay_param() const override { return tape_->input_delay_param; }
  const std::vector<int>& rotor_speed_states() const override { return tape_->rotor_speed_states; }

 private:
  // The functions pruned (backward liveness) to the outputs asked for, one per combination
  // of requested Jacobians (a mask with bit g-1 for group g: rhs dfdx, dfdu, dfdp, the last
  // cut to the restricted columns; measurement dhdx, dhdp).
  struct Programs {
    std::vector<int> dfdp_columns;  // empty: all
    std::array<TapeFunction, 8> rhs_for;
    std::array<TapeFunction, 4> measurement_for;
  };
  // Restricting dfdp re-prunes only the four rhs programs that compute it.
  static std::shared_ptr<const Programs> programs_for(const Tape& t, const std::vector<int>& dfdp_columns,
                                                      const Programs* unrestricted_parts);

  // Immutable, so shared by clones: a clone costs its registers and parameters only.
  std::shared_ptr<const Tape> tape_;
  std::shared_ptr<const TapeFunction> precompute_;  // tape_->precompute, scheduled
  std::shared_ptr<const Programs> programs_;
  std::vector<double> p_;
  mutable std::vector<double> reg_;  // scratch of rhs(), rhs_rows() and measurement()
  // rhs_rows(): the rows of the last call and the value program pruned to them (a cache of
  // one: the one caller asks for the same rows at every sample; callers alternating two sets
  // on one instance would rebuild it at every call).
  mutable std::vector<int> rows_asked_;
  mutable std::shared_ptr<const TapeFunction> rows_program_;
};

}  // namespace quadgen::runtime
