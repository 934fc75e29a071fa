#include "derive/term_order.hpp"

#include <algorithm>
#include <tuple>

namespace quadgen::term_order {
using namespace GiNaC;

bool operator<(const Place& a, const Place& b) {
  return std::tie(a.group, a.index, a.name) < std::tie(b.group, b.index, b.name);
}
bool operator==(const Place& a, const Place& b) {
  return a.group == b.group && a.index == b.index && a.name == b.name;
}

Support merged(const Support& a, const Support& b) {
  Support out;
  std::set_union(a.begin(), a.end(), b.begin(), b.end(), std::back_inserter(out));
  return out;
}

bool before(const Support& a, const Support& b) {
  return std::lexicographical_compare(a.begin(), a.end(), b.begin(), b.end());
}

SymbolPlaces::SymbolPlaces(const SymbolicModel& m) {
  const auto place = [&](const std::vector<Variable>& vs, Group g) {
    for (size_t i = 0; i < vs.size(); ++i) places_.emplace(vs[i].sym, Place{g, static_cast<int>(i), ""});
  };
  place(m.constants, Group::constant);
  place(m.params, Group::parameter);
  place(m.inputs, Group::input);
  place(m.states, Group::state);
}

const Support& SymbolPlaces::support(const ex& e) {
  const auto it = memo_.find(e);
  if (it != memo_.end()) return it->second;
  Support s;
  if (is_a<symbol>(e)) {
    const auto p = places_.find(e);
    s.push_back(p != places_.end() ? p->second : Place{Group::other, 0, ex_to<symbol>(e).get_name()});
  } else {
    for (size_t i = 0; i < e.nops(); ++i) s = merged(s, support(e.op(i)));
  }
  return memo_.emplace(e, std::move(s)).first->second;
}

}  // namespace quadgen::term_order
