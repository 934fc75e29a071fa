#include "derive/added_terms.hpp"

#include <stdexcept>

#include "derive/dynamics.hpp"
#include "model/units.hpp"
#include "runtime/rigid_body_state.hpp"

namespace quadgen {

using GiNaC::ex;
using GiNaC::matrix;

namespace {

// A regressor's symbolic value and SI dimension.
struct Regressor {
  ex value;
  Dimension dim;
};

Regressor base_regressor(ModelContext& c, const AddedTerm& t, const std::string& name) {
  auto centre = [&](const std::string& n) {
    for (const auto& [k, v] : t.centres)
      if (k == n) return v;
    throw std::invalid_argument("added term on " + t.channel + ": no centre given for " + n);
  };
  const Dimension none, speed = parse_unit("m/s").dim, rate = parse_unit("rad/s").dim;
  if (name == "1") return {1, none};
  if (name == "v_bx" || name == "v_by" || name == "v_bz") {
    const matrix vb = c.R.transpose().mul(c.velocity);
    return {vb(static_cast<unsigned>(name[3] - 'x'), 0), speed};
  }
  if (name == "p" || name == "q" || name == "r") return {c.omega(static_cast<unsigned>(name == "p" ? 0 : name == "q" ? 1 : 2), 0), rate};
  if (name == "dU") {
    ex sum = 0;
    const size_t n = c.vehicle.rotors.size();
    for (size_t i = 0; i < n; ++i) sum += c.model.inputs[i].sym;
    return {sum / static_cast<int>(n) -
                c.add_constant("term_" + t.channel + "_centre_U", "1", centre("dU"), "mean rotor command dU is taken about"),
            none};
  }
  if (name == "dvbat") {
    ex vbat;
    bool found = false;
    for (const auto& in : c.model.inputs)
      if (in.name == "vbat") vbat = in.sym, found = true;
    if (!found) vbat = c.add_input("vbat", "V", "battery voltage");
    return {vbat - c.add_constant("term_" + t.channel + "_centre_vbat", "V", centre("dvbat"),
                                  "battery voltage dvbat is taken about"),
            parse_unit("V").dim};
  }
  throw std::invalid_argument("added term on " + t.channel + ": unknown regressor '" + name +
                              "' (known: 1, v_bx, v_by, v_bz, p, q, r, dU, dvbat and products a*b)");
}

Regressor regressor(ModelContext& c, const AddedTerm& t, const std::string& name) {
  const auto star = name.find('*');
  if (star == std::string::npos) return base_regressor(c, t, name);
  const Regressor a = base_regressor(c, t, name.substr(0, star)), b = base_regressor(c, t, name.substr(star + 1));
  return {a.value * b.value, a.dim * b.dim};
}

// Where a term acts: the channel it was found in (runtime::rigid_body's names) and its axis.
struct Channel {
  enum class Kind { kAngular, kWorldAcceleration, kBodyAcceleration } kind;
  unsigned axis;
};

Channel channel_of(const std::string& name) {
  namespace rb = runtime::rigid_body;
  for (unsigned i = 0; i < 3; ++i) {
    if (name == rb::kResidualChannels[3 + i]) return {Channel::Kind::kAngular, i};
    if (name == rb::kWorldAccelerationChannels[i]) return {Channel::Kind::kWorldAcceleration, i};
    if (name == rb::kResidualChannels[i]) return {Channel::Kind::kBodyAcceleration, i};
  }
  throw std::invalid_argument("added term: unknown channel '" + name + "'");
}

}  // namespace

void add_terms(ModelContext& c, const std::vector<AddedTerm>& terms) {
  for (const AddedTerm& t : terms) {
    const Channel channel = channel_of(t.channel);
    const bool angular = channel.kind == Channel::Kind::kAngular;
    const Dimension channel_dim = parse_unit(runtime::rigid_body::kResidualChannelUnits[angular ? 3 : 0]).dim;
    ex sum = 0;
    for (size_t k = 0; k < t.coefficients.size(); ++k) {
      const auto& [name, value] = t.coefficients[k];
      const Regressor r = regressor(c, t, name);
      const double bound = 10 * std::abs(value) + 1e-12;
      const ex coefficient = c.add_param("term_" + t.channel + "_" + std::to_string(k + 1), (channel_dim / r.dim).str(),
                                         value, -bound, bound, true,
                                         "coefficient of " + name + " in the term added to " + t.channel +
                                             " (found beyond the catalogue by quadgen diagnose)");
      sum += coefficient * r.value;
    }
    matrix unit_axis(3, 1);
    unit_axis(channel.axis, 0) = 1;
    if (angular) {
      const ex xx = c.p("J_xx"), yy = c.p("J_yy"), zz = c.p("J_zz"), xy = c.p("J_xy"), xz = c.p("J_xz"), yz = c.p("J_yz");
      const matrix J(3, 3, GiNaC::lst{xx, xy, xz, xy, yy, yz, xz, yz, zz});
      c.extra_body_torque = c.extra_body_torque.add(J.mul(unit_axis).mul_scalar(sum));
    } else if (channel.kind == Channel::Kind::kWorldAcceleration) {
      c.extra_body_force = c.extra_body_force.add(c.R.transpose().mul(unit_axis).mul_scalar(c.p("mass") * sum));
    } else {
      c.extra_body_force = c.extra_body_force.add(unit_axis.mul_scalar(c.p("mass") * sum));
    }
  }
}

}  // namespace quadgen
