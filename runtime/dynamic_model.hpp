// The runtime's view of a flight model: sizes, names, parameters and a right-hand side
// with optional dense Jacobians. Two implementations: CompiledModel wraps a generated
// header (fast, fixed at compile time); TapeModel interprets the same expression DAG at
// run time, so `quadgen simulate` works for any vehicle file without a compiler.
#pragma once
#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include "runtime/parameter.hpp"

namespace quadgen::runtime {

class DynamicModel {
 public:
  virtual ~DynamicModel() = default;
  virtual int num_states() const = 0;
  virtual int num_inputs() const = 0;
  virtual int num_params() const = 0;
  virtual const std::vector<std::string>& state_names() const = 0;
  virtual const std::vector<std::string>& input_names() const = 0;
  virtual const std::vector<std::string>& param_names() const = 0;
  virtual const std::vector<double>& params() const = 0;
  virtual void set_params(const std::vector<double>& p) = 0;  // reruns the precompute step
  // Every parameter at its current value, with its unit, bounds and default fit flag.
  virtual std::vector<Parameter> parameters() const = 0;
  // f = dx/dt; A = df/dx (n x n), B = df/dp (n x np), Bu = df/du (n x nu), all dense
  // row-major; any of A, B, Bu may be nullptr.
  virtual void rhs(const double* x, const double* u, double* f, double* A, double* B, double* Bu) const = 0;
  // f[i] for the rows i in `rows` only (each in 0..num_states()-1; the other entries of f
  // unwritten), equal to rhs()'s bit for bit. For a caller that needs a few rates at every sample (the rotor speeds'
  // commanded values): a TapeModel then runs only the instructions those rows need.
  virtual void rhs_rows(const double* x, const double* u, const std::vector<int>& rows, double* f) const;
  // df/dp in a block of rows and columns (each list without repeats), packed:
  // block[i * columns.size() + k] is df[rows[i]] / dp[columns[k]]. A caller that needs a few
  // rows of B in a fit's free columns at every sample (the equation error's six
  // accelerations) prepares the block once with param_block() and passes it to rhs_block()
  // at each sample: B is n x 45 and more (a joint model's, n x 100 and more), mostly zero,
  // and clearing and filling it at every call took a tenth of a diagnosis.
  struct ParamBlock {
    std::vector<int> rows, columns;
    // The model's own preparation, opaque to callers. A generated model: where each nonzero
    // of its df/dp goes in the block (-1: outside it). A per-flight model: each flight's
    // block of the inner model and where its columns go in this one.
    std::vector<int> slot;
    std::vector<ParamBlock> inner;
    std::vector<std::vector<int>> place;
    // Who prepared it: a token that a model shares with its clones (a generated model's
    // type; a per-flight model's layout of parameters), held by the block so that no later
    // model is given its address. A model uses the preparation only of a block that carries
    // its own token (and has its shape); any other block takes the default path, which reads
    // nothing but rows and columns and so is right for every model.
    std::shared_ptr<const void> prepared_by;
  };
  virtual ParamBlock param_block(std::vector<int> rows, std::vector<int> columns) const {
    return {std::move(rows), std::move(columns), {}, {}, {}, nullptr};
  }
  // f (all rows) and the block of df/dp, equal to rhs()'s bit for bit. The default takes them
  // from rhs()'s dense df/dp.
  virtual void rhs_block(const double* x, const double* u, double* f, const ParamBlock& block, double* B) const;
  // The rotor-speed states (motor_lag's w_<rotor>), in rotor order; empty without a motor lag.
  // Where the model is derived they are the rotors' speed symbols among the states
  // (SymbolicModel::rotor_speed_states); every runtime user takes them from here, so the
  // rows the equation error filters are the ones the header's rotor_speed_rates() computes.
  virtual const std::vector<int>& rotor_speed_states() const = 0;
  // What a flight log records, h(x, p) (the generated measurement function): position, and
  // the attitude quaternion as the autopilot logs it (q ⊗ q_bias under attitude_bias). H =
  // dh/dx (num_outputs x n) and Hp = dh/dp (num_outputs x np), dense row-major, from the
  // generated analytic Jacobians; either may be nullptr. `t` is the log time: it picks a
  // per-flight parameter's copy (PerFlightModel), other models ignore it.
  virtual int num_outputs() const = 0;
  virtual void measurement(const double* x, double t, double* h, double* H, double* Hp) const = 0;
  // The input_delay parameter (the runtime feeds the commands of t - delay), or -1. Its value
  // for a time t sits at param_column(input_delay_param(), t).
  virtual int input_delay_param() const = 0;
  // A fit with few free parameters needs only their columns of B; a model may then skip
  // the others (left zero). Empty: all columns. Cheap when the columns are those of the
  // last call (residual models pass their free columns at every evaluation).
  virtual void restrict_param_jacobian(const std::vector<int>& /*columns*/) {}
  // An independent copy (parameters, caches and all), for work on another thread: a model
  // holds its parameters and scratch space, so one instance serves one thread. nullptr:
  // this model cannot be copied, and its users stay on one thread.
  virtual std::unique_ptr<DynamicModel> clone() const { return nullptr; }
  // Where parameter `index`'s value for time t (the input "t") sits in the parameter vector:
  // `index` itself, except in a model whose parameters differ by flight (PerFlightModel).
  // Effects applied to the data rather than the dynamics (attitude bias, input delay, motor
  // lag) read their values through it.
  virtual int param_column(int index, double /*t*/) const { return index; }

  int state_index(const std::string& name) const;
  int input_index(const std::string& name) const;
  int param_index(const std::string& name) const;
};

inline int index_in(const std::vector<std::string>& names, const std::string& n) {
  for (size_t i = 0; i < names.size(); ++i)
    if (names[i] == n) return static_cast<int>(i);
  return -1;
}
inline void DynamicModel::rhs_rows(const double* x, const double* u, const std::vector<int>& rows,
                                   double* f) const {
  std::vector<double> all(num_states());
  rhs(x, u, all.data(), nullptr, nullptr, nullptr);
  for (int i : rows) f[i] = all[i];
}
inline void DynamicModel::rhs_block(const double* x, const double* u, double* f, const ParamBlock& block,
                                    double* B) const {
  const size_t np = static_cast<size_t>(num_params()), nc = block.columns.size();
  thread_local std::vector<double> dense;  // one per thread: rhs() is called from several
  dense.resize(static_cast<size_t>(num_states()) * np);
  rhs(x, u, f, nullptr, dense.data(), nullptr);
  for (size_t i = 0; i < block.rows.size(); ++i)
    for (size_t k = 0; k < nc; ++k)
      B[i * nc + k] = dense[static_cast<size_t>(block.rows[i]) * np + static_cast<size_t>(block.columns[k])];
}
inline int DynamicModel::state_index(const std::string& n) const { return index_in(state_names(), n); }
inline int DynamicModel::input_index(const std::string& n) const { return index_in(input_names(), n); }
inline int DynamicModel::param_index(const std::string& n) const { return index_in(param_names(), n); }
// Rotor i's speed state (rotors in the vehicle's order), or -1 without a motor lag.
inline int rotor_speed_state(const DynamicModel& m, size_t i) {
  const std::vector<int>& s = m.rotor_speed_states();
  return i < s.size() ? s[i] : -1;
}

// The inputs effects add after the rotor commands, in one place: the time since the log's
// start (thrust_decay) and the battery voltage (battery_sag); -1 where the model has none.
struct ExtraInputs {
  explicit ExtraInputs(const DynamicModel& m) : t(m.input_index("t")), vbat(m.input_index("vbat")) {}
  void fill(double time, double voltage, double* u) const {
    if (t >= 0) u[t] = time;
    if (vbat >= 0) u[vbat] = voltage;
  }
  int t = -1, vbat = -1;
};

// Adapts a generated header's Model struct.
template <class M>
class CompiledModel : public DynamicModel {
 public:
  CompiledModel() : p_(M::kNominalParams, M::kNominalParams + M::kNumParams) {
    for (int i = 0; i < M::kNumStates; ++i) states_.push_back(M::kStateNames[i]);
    speed_states_.assign(M::kRotorSpeedStates, M::kRotorSpeedStates + M::kNumRotorSpeedStates);
    for (int i = 0; i < M::kNumInputs; ++i) inputs_.push_back(M::kInputNames[i]);
    for (int i = 0; i < M::kNumParams; ++i) param_names_.push_back(M::kParamNames[i]);
    M::precompute(p_.data(), &pre_);
  }
  int num_states() const override { return M::kNumStates; }
  int num_inputs() const override { return M::kNumInputs; }
  int num_params() const override { return M::kNumParams; }
  const std::vector<std::string>& state_names() const override { return states_; }
  const std::vector<int>& rotor_speed_states() const override { return speed_states_; }
  const std::vector<std::string>& input_names() const override { return inputs_; }
  const std::vector<std::string>& param_names() const override { return param_names_; }
  const std::vector<double>& params() const override { return p_; }
  void set_params(const std::vector<double>& p) override {
    p_ = p;
    M::precompute(p_.data(), &pre_);
  }
  void rhs(const double* x, const double* u, double* f, double* A, double* B, double* Bu) const override {
    double sx[M::kDfdxNnz + 1], sp[M::kDfdpNnz + 1], su[M::kDfduNnz + 1];
    M::rhs(x, u, p_.data(), pre_, f, A ? sx : nullptr, Bu ? su : nullptr, B ? sp : nullptr);
    constexpr int n = M::kNumStates;
    if (A) scatter(A, n, sx, M::kDfdxNnz, M::kDfdxRow, M::kDfdxCol);
    if (B) scatter(B, M::kNumParams, sp, M::kDfdpNnz, M::kDfdpRow, M::kDfdpCol);
    if (Bu) scatter(Bu, M::kNumInputs, su, M::kDfduNnz, M::kDfduRow, M::kDfduCol);
  }
  ParamBlock param_block(std::vector<int> rows, std::vector<int> columns) const override {
    ParamBlock b{std::move(rows), std::move(columns), std::vector<int>(M::kDfdpNnz, -1), {}, {}, block_token()};
    std::vector<int> row_at(M::kNumStates, -1), column_at(M::kNumParams, -1);
    for (size_t i = 0; i < b.rows.size(); ++i) row_at.at(static_cast<size_t>(b.rows[i])) = static_cast<int>(i);
    for (size_t q = 0; q < b.columns.size(); ++q) column_at.at(static_cast<size_t>(b.columns[q])) = static_cast<int>(q);
    for (int k = 0; k < M::kDfdpNnz; ++k) {
      const int i = row_at[M::kDfdpRow[k]], q = column_at[M::kDfdpCol[k]];
      if (i >= 0 && q >= 0) b.slot[k] = i * static_cast<int>(b.columns.size()) + q;
    }
    return b;
  }
  // The nonzeros go straight to their places in the block (a later duplicate wins, as in scatter()).
  void rhs_block(const double* x, const double* u, double* f, const ParamBlock& block, double* B) const override {
    if (block.prepared_by != block_token() || block.slot.size() != static_cast<size_t>(M::kDfdpNnz))
      return DynamicModel::rhs_block(x, u, f, block, B);
    double sp[M::kDfdpNnz + 1];
    double* none = nullptr;
    M::rhs(x, u, p_.data(), pre_, f, none, none, sp);
    std::fill(B, B + block.rows.size() * block.columns.size(), 0.0);
    for (int k = 0; k < M::kDfdpNnz; ++k)
      if (block.slot[k] >= 0) B[block.slot[k]] = sp[k];
  }
  // The rotor speeds' rows have a generated function of their own; other rows take rhs().
  void rhs_rows(const double* x, const double* u, const std::vector<int>& rows, double* f) const override {
    if (!speed_states_.empty() && rows == speed_states_)
      return M::rotor_speed_rates(x, u, p_.data(), pre_, f);
    DynamicModel::rhs_rows(x, u, rows, f);
  }
  std::vector<Parameter> parameters() const override {
    std::vector<Parameter> out;
    for (int i = 0; i < M::kNumParams; ++i)
      out.push_back({M::kParamNames[i], M::kParamUnits[i], p_[i], M::kParamLower[i], M::kParamUpper[i], M::kParamFit[i]});
    return out;
  }
  int num_outputs() const override { return M::kNumOutputs; }
  void measurement(const double* x, double /*t*/, double* h, double* H, double* Hp) const override {
    double sx[M::kDhdxNnz + 1], sp[M::kDhdpNnz + 1];
    M::measurement(x, p_.data(), pre_, h, H ? sx : nullptr, Hp ? sp : nullptr);
    if (H) scatter(H, M::kNumStates, sx, M::kDhdxNnz, M::kDhdxRow, M::kDhdxCol, M::kNumOutputs);
    if (Hp) scatter(Hp, M::kNumParams, sp, M::kDhdpNnz, M::kDhdpRow, M::kDhdpCol, M::kNumOutputs);
  }
  int input_delay_param() const override { return M::kInputDelayParam; }
  std::unique_ptr<DynamicModel> clone() const override { return std::make_unique<CompiledModel>(*this); }

 private:
  // One per generated model type (a function's static in a class template: one per M), so a
  // block prepared by another generated model is not read as this one's. Writable, so that no
  // linker folds the tokens of two types into one address; not owned (it lives as long as
  // the program).
  static const std::shared_ptr<const void>& block_token() {
    static char token = 0;
    static const std::shared_ptr<const void> shared(std::shared_ptr<const void>(), &token);
    return shared;
  }
  static void scatter(double* dense, int cols, const double* v, int nnz, const int* row, const int* col,
                      int rows = M::kNumStates) {
    for (int i = 0; i < rows * cols; ++i) dense[i] = 0;
    for (int k = 0; k < nnz; ++k) dense[row[k] * cols + col[k]] = v[k];
  }
  std::vector<double> p_;
  typename M::template Precomputed<double> pre_;
  std::vector<std::string> states_, inputs_, param_names_;
  std::vector<int> speed_states_;
};

// The indices of the true entries of a free-parameter mask (empty mask: none, which
// restrict_param_jacobian reads as all).
inline std::vector<int> free_columns(const std::vector<bool>& free) {
  std::vector<int> cols;
  for (size_t j = 0; j < free.size(); ++j)
    if (free[j]) cols.push_back(static_cast<int>(j));
  return cols;
}

// The Jacobian columns a mask asks for: its free parameters, or all num_params of them for an
// empty mask (as restrict_param_jacobian reads an empty list); none for a mask of only fixed ones.
inline std::vector<int> jacobian_columns(const std::vector<bool>& free, int num_params) {
  std::vector<int> cols = free_columns(free);
  if (free.empty())
    for (int c = 0; c < num_params; ++c) cols.push_back(c);
  return cols;
}

}  // namespace quadgen::runtime
