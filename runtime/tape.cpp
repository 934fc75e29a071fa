#include "runtime/tape.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <initializer_list>
#include <numeric>
#include <utility>

namespace quadgen::runtime {

namespace {

// One run: n instructions of the same operation, a loop without a branch per instruction.
template <class Op>
void binary_run(const Instruction* in, uint32_t n, double* r, Op op) {
  for (uint32_t i = 0; i < n; ++i) r[in[i].dst] = op(r[in[i].a], r[in[i].b]);
}
template <class Op>
void unary_run(const Instruction* in, uint32_t n, double* r, Op op) {
  for (uint32_t i = 0; i < n; ++i) r[in[i].dst] = op(r[in[i].a]);
}

void run(const TapeFunction& fn, double* r) {
  assert(fn.code.empty() || !fn.runs.empty());  // unscheduled code would run nothing
  const Instruction* in = fn.code.data();
  for (const OpRun& g : fn.runs) {
    switch (g.op) {
      case TapeOp::add: binary_run(in, g.count, r, [](double a, double b) { return a + b; }); break;
      case TapeOp::sub: binary_run(in, g.count, r, [](double a, double b) { return a - b; }); break;
      case TapeOp::mul: binary_run(in, g.count, r, [](double a, double b) { return a * b; }); break;
      case TapeOp::div: binary_run(in, g.count, r, [](double a, double b) { return a / b; }); break;
      case TapeOp::pow: binary_run(in, g.count, r, [](double a, double b) { return std::pow(a, b); }); break;
      case TapeOp::neg: unary_run(in, g.count, r, [](double a) { return -a; }); break;
      case TapeOp::sin: unary_run(in, g.count, r, [](double a) { return std::sin(a); }); break;
      case TapeOp::cos: unary_run(in, g.count, r, [](double a) { return std::cos(a); }); break;
      case TapeOp::log: unary_run(in, g.count, r, [](double a) { return std::log(a); }); break;
      case TapeOp::abs: unary_run(in, g.count, r, [](double a) { return a < 0 ? -a : a; }); break;
      case TapeOp::sign: unary_run(in, g.count, r, [](double a) { return a > 0 ? 1.0 : (a < 0 ? -1.0 : 0.0); }); break;
    }
    in += g.count;
  }
}

void scatter(double* dense, int rows, int cols, const SparseOutputs& s, const double* r) {
  for (int i = 0; i < rows * cols; ++i) dense[i] = 0;
  for (size_t k = 0; k < s.reg.size(); ++k) dense[s.row[k] * cols + s.col[k]] = r[s.reg[k]];
}

// Group g of a function (g >= 1: a Jacobian) is wanted when bit g-1 of a request mask is set;
// group 0, the value, always is. rhs groups: f, dfdx, dfdu, dfdp; measurement: h, dhdx, dhdp.
constexpr unsigned group_bit(int group) { return 1u << (group - 1); }
constexpr int kDfdxGroup = 1, kDfduGroup = 2, kDfdpGroup = 3, kDhdxGroup = 1, kDhdpGroup = 2;

unsigned request(std::initializer_list<std::pair<const double*, int>> outputs) {
  unsigned mask = 0;
  for (const auto& [out, group] : outputs)
    if (out) mask |= group_bit(group);
  return mask;
}

// The function with only the groups in `mask` (group_bit; group 0 always), group
// `restricted` cut to the columns `want_col` (empty: all), and only the instructions they
// need: walking backwards, an instruction is needed when its result is, and then so are
// its operands (each register is written once).
TapeFunction pruned(const TapeFunction& fn, unsigned mask, int restricted, const std::vector<char>& want_col,
                    int num_registers) {
  TapeFunction out;
  std::vector<char> live(num_registers, 0);
  for (size_t g = 0; g < fn.groups.size(); ++g) {
    SparseOutputs kept;
    if (g == 0 || (mask & group_bit(static_cast<int>(g)))) {
      const SparseOutputs& all = fn.groups[g];
      for (size_t k = 0; k < all.reg.size(); ++k) {
        if (static_cast<int>(g) == restricted && !want_col.empty() && !want_col[all.col[k]]) continue;
        kept.row.push_back(all.row[k]);
        kept.col.push_back(all.col[k]);
        kept.reg.push_back(all.reg[k]);
        live[all.reg[k]] = 1;
      }
    }
    out.groups.push_back(std::move(kept));
  }
  std::vector<Instruction> kept;
  for (auto it = fn.code.rbegin(); it != fn.code.rend(); ++it) {
    if (!live[it->dst]) continue;
    kept.push_back(*it);
    live[it->a] = 1;
    if (is_binary(it->op)) live[it->b] = 1;
  }
  out.code.assign(kept.rbegin(), kept.rend());
  schedule_by_level(out, num_registers);
  return out;
}

}  // namespace

void schedule_by_level(TapeFunction& fn, int num_registers) {
  std::vector<int> level_of_register(num_registers, 0), level(fn.code.size());
  for (size_t k = 0; k < fn.code.size(); ++k) {
    const Instruction& in = fn.code[k];
    int l = level_of_register[in.a];
    if (is_binary(in.op)) l = std::max(l, level_of_register[in.b]);
    level[k] = level_of_register[in.dst] = l + 1;
  }
  std::vector<size_t> order(fn.code.size());
  std::iota(order.begin(), order.end(), size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](size_t i, size_t j) {
    return level[i] != level[j] ? level[i] < level[j] : fn.code[i].op < fn.code[j].op;
  });
  std::vector<Instruction> code;
  code.reserve(order.size());
  fn.runs.clear();
  for (size_t k : order) {  // a run may continue into the next level: it executes in order
    const Instruction& in = fn.code[k];
    if (fn.runs.empty() || fn.runs.back().op != in.op) fn.runs.push_back({in.op, 0});
    ++fn.runs.back().count;
    code.push_back(in);
  }
  fn.code = std::move(code);
}

TapeModel::TapeModel(Tape t)
    : tape_(std::make_shared<const Tape>(std::move(t))), reg_(tape_->num_registers, 0.0) {
  for (const auto& [r, v] : tape_->constants) reg_[r] = v;
  auto precompute = std::make_shared<TapeFunction>();
  precompute->code = tape_->precompute;
  schedule_by_level(*precompute, tape_->num_registers);
  precompute_ = precompute;
  programs_ = programs_for(*tape_, {}, nullptr);
  set_params(tape_->nominal);
}

std::shared_ptr<const TapeModel::Programs> TapeModel::programs_for(const Tape& t, const std::vector<int>& dfdp_columns,
                                                                    const Programs* unrestricted_parts) {
  auto p = std::make_shared<Programs>();
  p->dfdp_columns = dfdp_columns;
  std::vector<char> want_col;
  if (!dfdp_columns.empty()) {
    want_col.assign(t.np, 0);
    for (int c : dfdp_columns) want_col[c] = 1;
  }
  for (unsigned mask = 0; mask < p->rhs_for.size(); ++mask)
    p->rhs_for[mask] = unrestricted_parts && !(mask & group_bit(kDfdpGroup))
                           ? unrestricted_parts->rhs_for[mask]
                           : pruned(t.rhs, mask, kDfdpGroup, want_col, t.num_registers);
  for (unsigned mask = 0; mask < p->measurement_for.size(); ++mask)
    p->measurement_for[mask] = unrestricted_parts ? unrestricted_parts->measurement_for[mask]
                                                  : pruned(t.measurement, mask, -1, {}, t.num_registers);
  return p;
}

void TapeModel::restrict_param_jacobian(const std::vector<int>& columns) {
  if (columns == programs_->dfdp_columns) return;  // a cache: the same columns as the last call
  programs_ = programs_for(*tape_, columns, programs_.get());
}

void TapeModel::set_params(const std::vector<double>& p) {
  p_ = p;
  for (int i = 0; i < tape_->np; ++i) reg_[tape_->p_reg(i)] = p[i];
  run(*precompute_, reg_.data());
}

std::vector<Parameter> TapeModel::parameters() const {
  std::vector<Parameter> out;
  for (int i = 0; i < tape_->np; ++i)
    out.push_back({tape_->param_names[i], tape_->param_units[i], p_[i], tape_->param_lower[i], tape_->param_upper[i],
                   tape_->param_fit[i] != 0});
  return out;
}

void TapeModel::measurement(const double* x, double /*t*/, double* h, double* H, double* Hp) const {
  double* r = reg_.data();
  for (int i = 0; i < tape_->nx; ++i) r[tape_->x_reg(i)] = x[i];
  const TapeFunction& fn = programs_->measurement_for[request({{H, kDhdxGroup}, {Hp, kDhdpGroup}})];
  run(fn, r);
  for (int i = 0; i < tape_->ny; ++i) h[i] = r[fn.groups[0].reg[i]];
  if (H) scatter(H, tape_->ny, tape_->nx, fn.groups[kDhdxGroup], r);
  if (Hp) scatter(Hp, tape_->ny, tape_->np, fn.groups[kDhdpGroup], r);
}

void TapeModel::rhs(const double* x, const double* u, double* f, double* A, double* B, double* Bu) const {
  double* r = reg_.data();
  for (int i = 0; i < tape_->nx; ++i) r[tape_->x_reg(i)] = x[i];
  for (int i = 0; i < tape_->nu; ++i) r[tape_->u_reg(i)] = u[i];
  const TapeFunction& fn = programs_->rhs_for[request({{A, kDfdxGroup}, {Bu, kDfduGroup}, {B, kDfdpGroup}})];
  run(fn, r);
  for (int i = 0; i < tape_->nx; ++i) f[i] = r[fn.groups[0].reg[i]];
  if (A) scatter(A, tape_->nx, tape_->nx, fn.groups[kDfdxGroup], r);
  if (Bu) scatter(Bu, tape_->nx, tape_->nu, fn.groups[kDfduGroup], r);
  if (B) scatter(B, tape_->nx, tape_->np, fn.groups[kDfdpGroup], r);
}

void TapeModel::rhs_rows(const double* x, const double* u, const std::vector<int>& rows, double* f) const {
  if (!rows_program_ || rows != rows_asked_) {
    const TapeFunction& value = programs_->rhs_for[0];  // f alone
    TapeFunction wanted{value.code, {SparseOutputs{}}, {}};
    const SparseOutputs& all = value.groups[0];
    SparseOutputs& kept = wanted.groups[0];
    for (size_t k = 0; k < all.reg.size(); ++k) {
      if (std::find(rows.begin(), rows.end(), all.row[k]) == rows.end()) continue;
      kept.row.push_back(all.row[k]);
      kept.col.push_back(all.col[k]);
      kept.reg.push_back(all.reg[k]);
    }
    rows_program_ = std::make_shared<const TapeFunction>(pruned(wanted, 0, -1, {}, tape_->num_registers));
    rows_asked_ = rows;
  }
  double* r = reg_.data();
  for (int i = 0; i < tape_->nx; ++i) r[tape_->x_reg(i)] = x[i];
  for (int i = 0; i < tape_->nu; ++i) r[tape_->u_reg(i)] = u[i];
  run(*rows_program_, r);
  const SparseOutputs& out = rows_program_->groups[0];
  for (size_t k = 0; k < out.reg.size(); ++k) f[out.row[k]] = r[out.reg[k]];
}

}  // namespace quadgen::runtime
