#include "codegen/lowered_plan.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>
#include <tuple>
#include <utility>

namespace quadgen::codegen {

namespace {

double power_of(double c, int k) {
  double r = 1;
  for (int i = 0; i < std::abs(k); ++i) r *= c;
  return k < 0 ? 1 / r : r;
}

}  // namespace

// ---------------------------------------------------------------------------------------
// Emission-form nodes, hash-consed.

int LoweredPlan::intern(Node n) {
  if (n.kind != Kind::leaf) {
    n.dynamic = false;
    for (int a : n.args) n.dynamic = n.dynamic || ir_[a].dynamic;
  }
  auto key = std::make_tuple(static_cast<int>(n.kind), n.args, n.sign, n.text);
  auto it = unique_.find(key);
  if (it != unique_.end()) return it->second;
  ir_.push_back(std::move(n));
  unique_[key] = static_cast<int>(ir_.size() - 1);
  return static_cast<int>(ir_.size() - 1);
}

int LoweredPlan::leaf(Leaf kind, int index, const std::string& text, bool dynamic) {
  Node n{Kind::leaf, {}, {}, text, dynamic};
  n.leaf = kind;
  n.index = index;
  if (kind == Leaf::constant) n.value = std::strtod(text.c_str() + 7, nullptr);  // "Scalar(" ...
  return intern(n);
}

int LoweredPlan::constant(double v) { return leaf(Leaf::constant, -1, "Scalar(" + double_literal(v) + ")", false); }

int LoweredPlan::prod(std::vector<int> factors) {
  if (factors.empty()) return constant(1);
  if (factors.size() == 1) return factors[0];
  std::sort(factors.begin(), factors.end());
  return intern(Node{Kind::prod, factors, {}, "", false});
}

int LoweredPlan::sum(std::vector<std::pair<int, int>> terms) {
  std::sort(terms.begin(), terms.end());
  if (terms.size() == 1 && terms[0].second > 0) return terms[0].first;
  if (terms.size() == 1) return negate(terms[0].first);
  Node n{Kind::sum, {}, {}, "", false};
  for (const auto& [id, s] : terms) {
    n.args.push_back(id);
    n.sign.push_back(static_cast<signed char>(s));
  }
  return intern(n);
}

int LoweredPlan::negate(int id) {
  const Node& n = ir_[id];
  if (n.kind == Kind::sum && n.args.size() == 1 && n.sign[0] < 0) return n.args[0];
  return intern(Node{Kind::sum, {id}, {-1}, "", false});
}

int LoweredPlan::recip(int id) { return intern(Node{Kind::recip, {id}, {}, "", false}); }

int LoweredPlan::call(const std::string& name, std::vector<int> args) {
  return intern(Node{Kind::call, std::move(args), {}, name, false});
}

// ---------------------------------------------------------------------------------------
// From the canonical graph to monomials over emission nodes.

namespace {
using Factors = std::vector<std::pair<int, int>>;
Factors merge(const Factors& a, const Factors& b, int scale_b = 1) {
  Factors out;
  size_t i = 0, j = 0;
  while (i < a.size() || j < b.size()) {
    if (j == b.size() || (i < a.size() && a[i].first < b[j].first)) out.push_back(a[i++]);
    else if (i == a.size() || b[j].first < a[i].first) out.push_back({b[j].first, b[j].second * scale_b}), ++j;
    else {
      const int e = a[i].second + b[j].second * scale_b;
      if (e != 0) out.push_back({a[i].first, e});
      ++i, ++j;
    }
  }
  return out;
}
}  // namespace

LoweredPlan::Mono LoweredPlan::convert(int gid) {
  auto it = memo_.find(gid);
  if (it != memo_.end()) return it->second;
  const codegen::Node& n = g_.node(gid);  // the graph's node
  Mono m;
  auto single = [&](int id) {
    Mono r;
    r.f.push_back({id, 1});
    return r;
  };
  auto times = [](const Mono& a, const Mono& b, int k = 1) {
    Mono r;
    r.coeff = a.coeff * power_of(b.coeff, k);
    r.f = merge(a.f, b.f, k);
    return r;
  };
  switch (n.op) {
    case Op::constant: m.coeff = std::strtod(n.literal.c_str(), nullptr); break;
    case Op::state: m = single(leaf(Leaf::state, n.index, "x[" + std::to_string(n.index) + "]", true)); break;
    case Op::input: m = single(leaf(Leaf::input, n.index, "u[" + std::to_string(n.index) + "]", true)); break;
    case Op::param: m = single(leaf(Leaf::param, n.index, "p[" + std::to_string(n.index) + "]", false)); break;
    case Op::mul:
      for (int a : n.args) m = times(m, convert(a));
      break;
    case Op::div: {
      // The denominator first, written out: the order in which nodes are numbered decides
      // signs and operand order in the emitted code (make_sum), and C++ leaves the order of a
      // call's arguments to the compiler (GCC converted the second first, Clang the first:
      // the headers differed by compiler). The checked-in headers were generated in GCC's order.
      const Mono den = convert(n.args[1]);
      const Mono num = convert(n.args[0]);
      m = times(num, den, -1);
      break;
    }
    case Op::ipow: m = times(m, convert(n.args[0]), static_cast<int>(n.exponent)); break;
    case Op::add: {
      std::vector<Mono> terms;
      for (int a : n.args) terms.push_back(convert(a));
      m = make_sum(terms);
      break;
    }
    case Op::pow:
      m = single(call("pow", {materialize_positive(convert(n.args[0])), materialize_positive(convert(n.args[1]))}));
      break;
    case Op::sin: m = single(call("sin", {materialize_positive(convert(n.args[0]))})); break;
    case Op::cos: m = single(call("cos", {materialize_positive(convert(n.args[0]))})); break;
    case Op::log: m = single(call("log", {materialize_positive(convert(n.args[0]))})); break;
    case Op::abs: m = single(call("abs_value", {materialize_positive(convert(n.args[0]))})); break;
    case Op::sign: m = single(call("sign_of", {materialize_positive(convert(n.args[0]))})); break;
  }
  memo_[gid] = m;
  return m;
}

namespace {

// Like terms (equal factors) added, in first-seen order; those that cancel dropped. (Term:
// LoweredPlan's private monomial, {coeff, factors}.)
template <class Term>
std::vector<Term> combine_like_terms(const std::vector<Term>& in) {
  std::map<Factors, double> like;
  std::vector<Factors> order;
  for (const auto& t : in) {
    auto [it, fresh] = like.emplace(t.f, 0.0);
    if (fresh) order.push_back(t.f);
    it->second += t.coeff;
  }
  std::vector<Term> terms;
  for (const auto& f : order)
    if (like[f] != 0) terms.push_back(Term{like[f], f});
  return terms;
}

// The factors every term has (a base with exponents of one sign in all, at its smallest
// power) and the coefficient magnitude they share (1 unless all are equal), divided out of
// the terms.
template <class Term>
void take_out_common(std::vector<Term>& terms, Factors* common, double* ccoeff) {
  *common = terms[0].f;
  for (size_t k = 1; k < terms.size() && !common->empty(); ++k) {
    Factors next;
    for (const auto& [b, e] : *common) {
      for (const auto& [b2, e2] : terms[k].f)
        if (b2 == b && (e > 0) == (e2 > 0)) next.push_back({b, e > 0 ? std::min(e, e2) : std::max(e, e2)});
    }
    *common = next;
  }
  *ccoeff = std::fabs(terms[0].coeff);
  for (const auto& t : terms)
    if (std::fabs(t.coeff) != *ccoeff) *ccoeff = 1;
  for (auto& t : terms) {
    t.f = merge(t.f, *common, -1);
    t.coeff /= *ccoeff;
  }
}

}  // namespace

bool LoweredPlan::is_static(const Mono& t) const {
  for (const auto& [b, e] : t.f)
    if (ir_[b].dynamic) return false;
  return true;
}

// Greedy factoring: the factor shared by the most terms (a dynamic base, or a whole
// parameter-only part, which is one precomputed value) is taken out of those terms,
// c*a + c*b -> c*(a + b), until no factor is shared by two terms.
void LoweredPlan::factor_greedily(std::vector<Mono>& terms) {
  for (;;) {
    // Candidates: (dynamic base, exponent direction) or the parameter-only part.
    using Cand = std::tuple<int, int, double, Factors>;  // (kind 0 base / 1 static part, base or 0, coeff, statics)
    std::map<Cand, int> count;
    auto static_part = [&](const Mono& t) {
      Factors st;
      for (const auto& fe : t.f)
        if (!ir_[fe.first].dynamic) st.push_back(fe);
      return Cand{1, 0, std::fabs(t.coeff), st};
    };
    for (const auto& t : terms) {
      if (is_static(t)) continue;
      const Cand sp = static_part(t);
      if (std::get<2>(sp) != 1 || !std::get<3>(sp).empty()) count[sp]++;
      for (const auto& [b, e] : t.f)
        if (ir_[b].dynamic) count[Cand{0, b, e > 0 ? 1.0 : -1.0, {}}]++;
    }
    const Cand* best = nullptr;
    int best_n = 1;
    for (const auto& [c, n] : count)
      if (n > best_n) best = &c, best_n = n;
    if (!best) return;
    const Cand cand = *best;
    std::vector<Mono> group, rest;
    for (const auto& t : terms) {
      bool has = false;
      if (!is_static(t)) {
        if (std::get<0>(cand) == 1) has = static_part(t) == cand;
        else
          for (const auto& [b, e] : t.f)
            if (b == std::get<1>(cand) && (e > 0 ? 1.0 : -1.0) == std::get<2>(cand)) has = true;
      }
      (has ? group : rest).push_back(t);
    }
    Mono taken;
    if (std::get<0>(cand) == 1) {
      taken = Mono{std::get<2>(cand), std::get<3>(cand)};
    } else {
      taken = Mono{1, {{std::get<1>(cand), static_cast<int>(std::get<2>(cand))}}};
    }
    for (auto& t : group) {
      t.f = merge(t.f, taken.f, -1);
      t.coeff /= taken.coeff;
    }
    const Mono inner = make_sum(group);
    rest.push_back(Mono{inner.coeff * taken.coeff, merge(inner.f, taken.f)});
    terms = rest;
    if (terms.size() == 1) return;
  }
}

// A sum of monomials: like terms combined, factors common to every term (and a common
// coefficient magnitude) taken out, parameter-only terms combined into one (precomputed)
// term, the sign normalised so that the term with the lowest id is added.
LoweredPlan::Mono LoweredPlan::make_sum(std::vector<Mono> in) {
  std::vector<Mono> terms = combine_like_terms(in);
  if (terms.empty()) return Mono{0, {}};
  if (terms.size() == 1) return terms[0];
  Factors common;
  double ccoeff = 1;
  take_out_common(terms, &common, &ccoeff);
  if (terms.size() > 2) factor_greedily(terms);
  // Everything factored into one term, (c*a + c*b) -> c*(a + b): the factors and the
  // coefficient common to all terms, divided out above, go back on it.
  if (terms.size() == 1) return Mono{terms[0].coeff * ccoeff, merge(terms[0].f, common)};

  // Parameter-only terms: one term.
  std::vector<Mono> kept, statics;
  for (const auto& t : terms) (is_static(t) ? statics : kept).push_back(t);
  std::vector<Signed> mat;
  if (statics.size() >= 2 && !kept.empty()) {
    const Mono s = make_sum(statics);  // all static: no further split happens inside
    mat.push_back(materialize(s));
  } else {
    for (const auto& t : statics) kept.push_back(t);
  }
  for (const auto& t : kept) mat.push_back(materialize(t));
  // Stable: should two terms ever materialise as one node, the outer sign is the first one's,
  // not whichever std::sort happened to put first.
  std::stable_sort(mat.begin(), mat.end(), [](const Signed& a, const Signed& b) { return a.id < b.id; });
  const int outer = mat.front().sign;
  std::vector<std::pair<int, int>> st;
  for (const auto& s : mat) st.push_back({s.id, s.sign * outer});
  const int id = sum(st);
  return Mono{outer * ccoeff, merge(common, Factors{{id, 1}})};
}

// A monomial as sign * node: constants and parameter-only factors are one factor (a
// precompute candidate), dynamic denominators one reciprocal.
LoweredPlan::Signed LoweredPlan::materialize(const Mono& m) {
  if (m.coeff == 0) return {1, constant(0)};
  const int sign = m.coeff < 0 ? -1 : 1;
  const double a = std::fabs(m.coeff);
  std::vector<int> snum, sden, dnum, dden;
  for (const auto& [b, e] : m.f) {
    auto& num = ir_[b].dynamic ? dnum : snum;
    auto& den = ir_[b].dynamic ? dden : sden;
    for (int i = 0; i < std::abs(e); ++i) (e > 0 ? num : den).push_back(b);
  }
  int stat = -1;
  if (snum.empty() && sden.empty()) {
    if (a != 1 || (dnum.empty() && dden.empty())) stat = constant(a);
  } else if (a == 1 && snum.size() == 1 && sden.empty()) {
    stat = snum[0];
  } else {
    if (a != 1) snum.push_back(constant(a));
    if (!sden.empty()) snum.push_back(recip(prod(sden)));
    stat = prod(snum);
  }
  if (dnum.empty() && dden.empty()) return {sign, stat};
  if (stat >= 0) dnum.push_back(stat);
  if (!dden.empty()) dnum.push_back(recip(prod(dden)));
  return {sign, prod(dnum)};
}

int LoweredPlan::materialize_positive(const Mono& m) {
  const Signed s = materialize(m);
  return s.sign < 0 ? negate(s.id) : s.id;
}

// ---------------------------------------------------------------------------------------
// Greedy pair extraction.

std::vector<int> LoweredPlan::reachable(Kind kind) const {
  std::vector<char> seen(ir_.size(), 0);
  std::vector<int> out;
  std::function<void(int)> visit = [&](int id) {
    if (seen[id]) return;
    seen[id] = 1;
    const Node& n = ir_[id];
    if (!n.dynamic) return;
    for (int a : n.args) visit(a);
    if (n.kind == kind && n.args.size() >= 2) out.push_back(id);
  };
  for (const auto& r : roots_) visit(r.id);
  std::sort(out.begin(), out.end());
  return out;
}

namespace {

// The operand lists of the sums (or products) being rewritten, and for every pair of operands
// (with its relative sign in a sum) the nodes that hold it, most shared first.
class PairIndex {
 public:
  using Key = std::tuple<int, int, int>;  // a <= b, relative sign (sums) or 0

  PairIndex(bool is_sum, std::vector<std::vector<int>> args, std::vector<std::vector<signed char>> sign)
      : is_sum_(is_sum), args_(std::move(args)), sign_(std::move(sign)), modified_(args_.size(), 0) {}

  void add_node(int id) {
    for (const auto& k : pairs_of(id)) update(k, id, true);
  }
  // The most shared pair while one is held by two nodes or more.
  std::optional<Key> most_shared() const {
    if (queue_.empty() || -std::get<0>(*queue_.begin()) < 2) return std::nullopt;
    const auto& [negcount, a, b, rel] = *queue_.begin();
    return Key{a, b, rel};
  }
  void drop_most_shared() { queue_.erase(queue_.begin()); }
  std::set<int> holders(const Key& k) { return where_[k]; }
  void grow(size_t size) {
    if (size <= args_.size()) return;
    args_.resize(size);
    sign_.resize(size);
    modified_.resize(size, 0);
  }
  // Node `id` takes the new node `p` in place of one occurrence of the pair `k`.
  void replace(int id, const Key& k, int p) {
    const auto [a, b, rel] = k;
    for (const auto& old : pairs_of(id)) update(old, id, false);
    auto& l = args_[id];
    auto& s = sign_[id];
    // Find one occurrence of a and one of b (with the right relative sign).
    int ia = -1, ib = -1;
    for (size_t i = 0; i < l.size() && ia < 0; ++i)
      if (l[i] == a) ia = static_cast<int>(i);
    for (size_t j = 0; j < l.size() && ib < 0; ++j)
      if (static_cast<int>(j) != ia && l[j] == b && (!is_sum_ || s[ia] * s[j] == rel)) ib = static_cast<int>(j);
    const int sa = is_sum_ ? s[ia] : 1;
    std::vector<int> nl;
    std::vector<signed char> ns;
    for (size_t i = 0; i < l.size(); ++i)
      if (static_cast<int>(i) != ia && static_cast<int>(i) != ib) {
        nl.push_back(l[i]);
        if (is_sum_) ns.push_back(s[i]);
      }
    nl.push_back(p);
    if (is_sum_) ns.push_back(static_cast<signed char>(sa));
    l = nl;
    s = ns;
    modified_[id] = 1;
    add_node(id);
  }
  // The rewritten operand lists (empty for nodes left as they were), `size` entries.
  std::pair<std::vector<std::vector<int>>, std::vector<std::vector<signed char>>> rewritten(size_t size) const {
    std::vector<std::vector<int>> args(size);
    std::vector<std::vector<signed char>> sign(size);
    for (size_t id = 0; id < modified_.size(); ++id)
      if (modified_[id]) args[id] = args_[id], sign[id] = sign_[id];
    return {args, sign};
  }

 private:
  std::set<Key> pairs_of(int id) const {
    std::set<Key> ks;
    const auto& l = args_[id];
    for (size_t i = 0; i < l.size(); ++i)
      for (size_t j = i + 1; j < l.size(); ++j) {
        int a = l[i], b = l[j];
        int sa = is_sum_ ? sign_[id][i] : 1, sb = is_sum_ ? sign_[id][j] : 1;
        if (a > b) std::swap(a, b), std::swap(sa, sb);
        if (is_sum_ && a == b) continue;
        ks.insert({a, b, is_sum_ ? sa * sb : 0});
      }
    return ks;
  }
  void update(const Key& k, int id, bool add) {
    auto& s = where_[k];
    if (!s.empty()) queue_.erase({-static_cast<int>(s.size()), std::get<0>(k), std::get<1>(k), std::get<2>(k)});
    if (add) s.insert(id);
    else s.erase(id);
    if (!s.empty()) queue_.insert({-static_cast<int>(s.size()), std::get<0>(k), std::get<1>(k), std::get<2>(k)});
  }

  bool is_sum_;
  std::vector<std::vector<int>> args_;
  std::vector<std::vector<signed char>> sign_;
  std::vector<char> modified_;
  std::map<Key, std::set<int>> where_;
  std::set<std::tuple<int, int, int, int>> queue_;  // (-count, a, b, rel)
};

}  // namespace

// Greedy pair extraction: the pair of operands shared by most sums (or products) becomes a
// node of its own, replaces the pair where it occurs, and the counts are updated, until no
// pair is shared by two nodes.
void LoweredPlan::extract_pairs(Kind kind) {
  const bool is_sum = kind == Kind::sum;
  const std::vector<int> nodes = reachable(kind);
  std::vector<std::vector<int>> args(ir_.size());
  std::vector<std::vector<signed char>> sign(ir_.size());
  for (int id : nodes) {
    args[id] = ir_[id].args;
    sign[id] = ir_[id].sign;
  }
  PairIndex index(is_sum, std::move(args), std::move(sign));
  for (int id : nodes) index.add_node(id);
  while (const auto key = index.most_shared()) {
    const auto [a, b, rel] = *key;
    const int p = is_sum ? sum({{a, 1}, {b, rel}}) : prod({a, b});
    index.grow(ir_.size());
    bool changed = false;
    for (int id : index.holders(*key))
      if (id != p) index.replace(id, *key, p), changed = true;
    if (!changed) index.drop_most_shared();  // only the pair node itself holds the pair
  }
  const auto [final_args, final_sign] = index.rewritten(ir_.size());
  std::vector<int> memo(ir_.size(), -1);
  for (auto& r : roots_) r.id = rebuild(r.id, final_args, final_sign, memo);
  for (auto& [gid, s] : out_) s.id = rebuild(s.id, final_args, final_sign, memo);
}

int LoweredPlan::rebuild(int id, const std::vector<std::vector<int>>& args,
                        const std::vector<std::vector<signed char>>& sign, std::vector<int>& memo) {
  if (static_cast<size_t>(id) < memo.size() && memo[id] >= 0) return memo[id];
  const bool mod = static_cast<size_t>(id) < args.size() && !args[id].empty();
  const Node n = ir_[id];
  std::vector<int> a = mod ? args[id] : n.args;
  const std::vector<signed char> s = mod ? sign[id] : n.sign;
  for (int& x : a) x = rebuild(x, args, sign, memo);
  int r = id;
  switch (n.kind) {
    case Kind::leaf: r = id; break;
    case Kind::prod: r = prod(a); break;
    case Kind::recip: r = recip(a[0]); break;
    case Kind::call: r = call(n.text, a); break;
    case Kind::sum: {
      std::vector<std::pair<int, int>> t;
      for (size_t i = 0; i < a.size(); ++i) t.push_back({a[i], s[i]});
      r = sum(t);
      break;
    }
  }
  if (memo.size() < ir_.size()) memo.resize(ir_.size(), -1);
  memo[id] = r;
  return r;
}

// ---------------------------------------------------------------------------------------
// Planning: emission form of every output, pair extraction, precompute slots.

LoweredPlan::LoweredPlan(ExpressionGraph& g, const std::vector<OutputGroup>& all_groups) : g_(g) {
  for (const auto& grp : all_groups)
    for (const auto& o : grp.outputs) {
      if (out_.count(o.node)) continue;
      Signed s = materialize(convert(o.node));
      if (!ir_[s.id].dynamic && s.sign < 0) {
        const Node& n = ir_[s.id];
        if (n.kind == Kind::leaf && n.text.rfind("Scalar(", 0) == 0)
          s.id = constant(-std::strtod(n.text.c_str() + 7, nullptr));
        else
          s.id = negate(s.id);
        s.sign = 1;
      }
      out_[o.node] = s;
      roots_.push_back(s);
    }
  // Products first (their pairs feed the terms of sums), then sums; a second round picks
  // up what the first made identical.
  for (int round = 0; round < 2; ++round) {
    extract_pairs(Kind::prod);
    extract_pairs(Kind::sum);
  }
  plan_precompute_slots(all_groups);
  find_supports();
}

// The support of every node an output reaches: its variables at their places in reading
// order. Operands have lower ids than their users, so one pass in id order suffices.
void LoweredPlan::find_supports() {
  std::vector<char> reached(ir_.size(), 0);
  for (const auto& r : roots_) reached[r.id] = 1;
  for (int id = static_cast<int>(ir_.size()) - 1; id >= 0; --id)
    if (reached[id])
      for (int a : ir_[id].args) reached[a] = 1;
  support_.assign(ir_.size(), {});
  for (size_t id = 0; id < ir_.size(); ++id) {
    if (!reached[id]) continue;
    const Node& n = ir_[id];
    using term_order::Group;
    switch (n.leaf) {
      case Leaf::param: support_[id] = {{Group::parameter, n.index, ""}}; break;
      case Leaf::input: support_[id] = {{Group::input, n.index, ""}}; break;
      case Leaf::state: support_[id] = {{Group::state, n.index, ""}}; break;
      case Leaf::constant: case Leaf::none: break;
    }
    for (int a : n.args) support_[id] = term_order::merged(support_[id], support_[a]);
  }
}

// Every parameter-only, non-leaf operand of a dynamic node (and every parameter-only
// output) gets a slot of precompute(), in first-use order.
void LoweredPlan::plan_precompute_slots(const std::vector<OutputGroup>& all_groups) {
  pre_slot_.assign(ir_.size(), -1);
  std::vector<char> seen(ir_.size(), 0);
  auto slot = [&](int id) {
    const Node& c = ir_[id];
    if (!c.dynamic && c.kind != Kind::leaf && pre_slot_[id] < 0) {
      pre_slot_[id] = static_cast<int>(pre_order_.size());
      pre_order_.push_back(id);
    }
  };
  std::function<void(int)> visit = [&](int id) {
    if (seen[id]) return;
    seen[id] = 1;
    const Node& n = ir_[id];
    if (!n.dynamic) return;
    for (int a : n.args) {
      visit(a);
      slot(a);
    }
  };
  for (const auto& grp : all_groups)
    for (const auto& o : grp.outputs) {
      const int id = out_.at(o.node).id;
      visit(id);
      slot(id);
    }
}


// ---------------------------------------------------------------------------------------
// Function plans: which nodes are temporaries, in which order statements come.

std::vector<size_t> LoweredPlan::operand_order(int id) const {
  const Node& n = ir_[id];
  std::vector<size_t> order(n.args.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](size_t i, size_t j) {
    const auto& a = support_[n.args[i]];
    const auto& b = support_[n.args[j]];
    if (term_order::before(a, b)) return true;
    if (term_order::before(b, a)) return false;
    return n.args[i] < n.args[j];
  });
  return order;
}

std::vector<size_t> LoweredPlan::sum_order(int id, int outer) const {
  const Node& n = ir_[id];
  std::vector<size_t> order = operand_order(id);
  term_order::first_added_first(order.begin(), order.end(), [&](size_t i) { return n.sign[i] * outer > 0; });
  return order;
}

bool LoweredPlan::is_inline_division(const Function& fn, int id) const {
  const Node& c = ir_[id];
  return c.kind == Kind::recip && fn.temp[id] < 0 && fn.uses[id] == 1 && (fn.precompute || c.dynamic);
}

// A function's region: precompute() computes parameter-only nodes; the other functions stop
// at them (they read them from pre.c).
bool LoweredPlan::inside(const Function& fn, int id) const { return fn.precompute || ir_[id].dynamic; }

// One use of `id`, and the first time it is seen one use of each of its operands.
void LoweredPlan::count_use(Function& fn, int id, std::vector<char>& seen) const {
  fn.uses[id]++;
  if (seen[id]) return;
  seen[id] = 1;
  if (!inside(fn, id)) return;
  for (int a : ir_[id].args) count_use(fn, a, seen);
}

// Post-order: a node used more than once becomes the next temporary, after its operands.
void LoweredPlan::define_temporaries(Function& fn, int id, std::vector<char>& done) const {
  const Node& n = ir_[id];
  if (done[id] || n.kind == Kind::leaf || !inside(fn, id)) return;
  done[id] = 1;
  for (int a : n.args) define_temporaries(fn, a, done);
  if (fn.uses[id] > 1) {
    fn.temp[id] = fn.num_temps++;
    fn.steps.push_back({Function::StepKind::define, id, fn.temp[id]});
  }
}

LoweredPlan::Function LoweredPlan::precompute_function() const {
  Function fn;
  fn.precompute = true;
  fn.uses.assign(ir_.size(), 0);
  fn.temp.assign(ir_.size(), -1);
  std::vector<char> seen(ir_.size(), 0), done(ir_.size(), 0);
  for (int id : pre_order_) {
    fn.uses[id]++;  // stored: always named
    count_use(fn, id, seen);
  }
  for (int id : pre_order_) {
    define_temporaries(fn, id, done);
    Function::Step store{Function::StepKind::store, id};
    store.slot = pre_slot_[id];
    fn.steps.push_back(store);
  }
  return fn;
}

LoweredPlan::Function LoweredPlan::part_of(const Function& full, int group, const std::vector<int>& outputs) const {
  using StepKind = Function::StepKind;
  if (!full.groups.at(group).guard.empty()) throw std::logic_error("LoweredPlan::part_of: a guarded group");
  Function part;
  part.uses = full.uses;
  part.temp = full.temp;
  part.num_temps = full.num_temps;
  part.groups.push_back({"", {}});
  // Every node the kept outputs read, inline or as a temporary.
  std::vector<char> needed(ir_.size(), 0);
  std::vector<int> stack;
  for (int k : outputs) {
    const Output& o = full.groups[group].outputs.at(k);
    part.groups[0].outputs.push_back(o);
    part.ops_before += g_.tree_ops(o.node);
    stack.push_back(out_.at(o.node).id);
  }
  while (!stack.empty()) {
    const int id = stack.back();
    stack.pop_back();
    if (needed[id]) continue;
    needed[id] = 1;
    if (ir_[id].kind == Kind::leaf || !inside(full, id)) continue;
    for (int a : ir_[id].args) stack.push_back(a);
  }
  // full's steps in full's order: its definitions the kept outputs need and their
  // assignments, renumbered into the part's one group.
  for (const Function::Step& s : full.steps) {
    if (s.kind == StepKind::define && needed[s.node]) part.steps.push_back(s);
    if (s.kind != StepKind::assign || s.group != group) continue;
    const auto kept = std::find(outputs.begin(), outputs.end(), s.output);
    if (kept == outputs.end()) continue;
    Function::Step step = s;
    step.group = 0;
    step.output = static_cast<int>(kept - outputs.begin());
    part.steps.push_back(step);
  }
  return part;
}

LoweredPlan::Function LoweredPlan::function(const std::vector<OutputGroup>& groups) const {
  using StepKind = Function::StepKind;
  Function fn;
  fn.groups = groups;
  fn.uses.assign(ir_.size(), 0);
  fn.temp.assign(ir_.size(), -1);
  std::vector<char> seen(ir_.size(), 0), done(ir_.size(), 0);
  for (const auto& grp : groups)
    for (const auto& o : grp.outputs) {
      fn.ops_before += g_.tree_ops(o.node);
      count_use(fn, out_.at(o.node).id, seen);
    }
  auto assign = [&](int g, int k) {
    const Signed o = out_.at(groups[g].outputs[k].node);
    Function::Step step{StepKind::assign, o.id, -1, g, k};
    step.sign = o.sign;
    fn.steps.push_back(step);
  };
  // Unguarded groups (f) first; guarded groups (Jacobians) share one outer block in
  // which all their temporaries are computed, each group then written under its guard.
  bool any_guarded = false;
  for (int g = 0; g < static_cast<int>(groups.size()); ++g) {
    if (!groups[g].guard.empty()) {
      any_guarded = true;
      continue;
    }
    for (int k = 0; k < static_cast<int>(groups[g].outputs.size()); ++k) {
      define_temporaries(fn, out_.at(groups[g].outputs[k].node).id, done);
      assign(g, k);
    }
  }
  if (!any_guarded) return fn;
  fn.steps.push_back({StepKind::open_any});
  for (const auto& grp : groups)
    if (!grp.guard.empty())
      for (const auto& o : grp.outputs) define_temporaries(fn, out_.at(o.node).id, done);
  for (int g = 0; g < static_cast<int>(groups.size()); ++g) {
    if (groups[g].guard.empty()) continue;
    fn.steps.push_back({StepKind::open_group, -1, -1, g});
    for (int k = 0; k < static_cast<int>(groups[g].outputs.size()); ++k) assign(g, k);
    fn.steps.push_back({StepKind::close});
  }
  fn.steps.push_back({StepKind::close});
  return fn;
}

}  // namespace quadgen::codegen
