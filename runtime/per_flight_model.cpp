#include "runtime/per_flight_model.hpp"

#include <algorithm>
#include <set>
#include <stdexcept>

namespace quadgen::runtime {

std::string per_flight_name(const std::string& parameter, int flight) {
  return flight <= 1 ? parameter : parameter + "@" + std::to_string(flight);
}

std::string shared_name(const std::string& name) { return name.substr(0, name.find('@')); }

std::map<std::string, double> mean_over_flights(const std::vector<std::pair<std::string, double>>& values) {
  std::map<std::string, std::pair<double, int>> sums;
  for (const auto& [name, value] : values) {
    auto& [sum, count] = sums[shared_name(name)];
    sum += value;
    ++count;
  }
  std::map<std::string, double> means;
  for (const auto& [name, sum_count] : sums) means[name] = sum_count.first / sum_count.second;
  return means;
}

int flight_of_name(const std::string& name) {
  const auto at = name.find('@');
  return at == std::string::npos ? 1 : std::stoi(name.substr(at + 1));
}

PerFlightModel::PerFlightModel(const DynamicModel& inner, std::vector<double> flight_starts,
                               const std::vector<std::string>& per_flight)
    : starts_(std::move(flight_starts)), t_input_(inner.input_index("t")), names_(inner.param_names()),
      p_(inner.params()) {
  if (t_input_ < 0) throw std::invalid_argument("per-flight parameters need the model's time input 't'");
  if (!std::is_sorted(starts_.begin(), starts_.end()))
    throw std::invalid_argument("per-flight parameters: the flights' start times must increase");
  const int np = inner.num_params();
  std::vector<int> shared;
  for (const auto& n : std::set<std::string>(per_flight.begin(), per_flight.end())) {
    const int j = inner.param_index(n);
    if (j < 0) throw std::invalid_argument("per-flight parameter '" + n + "' is not a parameter of the model");
    shared.push_back(j);
  }
  std::sort(shared.begin(), shared.end());
  for (size_t k = 0; k <= starts_.size(); ++k) {
    std::unique_ptr<DynamicModel> copy = inner.clone();
    if (!copy) throw std::invalid_argument("per-flight parameters need a model that can be copied");
    flights_.push_back(std::move(copy));
    std::vector<int> column(np);
    for (int j = 0; j < np; ++j) column[j] = j;
    if (k > 0)
      for (int j : shared) {
        column[j] = static_cast<int>(names_.size());
        names_.push_back(per_flight_name(inner.param_names()[j], static_cast<int>(k) + 1));
        p_.push_back(inner.params()[j]);
      }
    column_.push_back(std::move(column));
  }
}

PerFlightModel::PerFlightModel(const PerFlightModel& o)
    // The inner copies keep their restriction: so does the record of it. The copy shares the
    // layout, so blocks prepared by either serve both.
    : DynamicModel(o), starts_(o.starts_), t_input_(o.t_input_), names_(o.names_), p_(o.p_), column_(o.column_),
      restricted_to_(o.restricted_to_), layout_token_(o.layout_token_) {
  for (const auto& m : o.flights_) flights_.push_back(m->clone());
}

int PerFlightModel::flight_at(double t) const {
  return static_cast<int>(std::upper_bound(starts_.begin(), starts_.end(), t) - starts_.begin());
}

int PerFlightModel::param_column(int index, double t) const {
  const auto& column = column_[flight_at(t)];
  return index >= 0 && index < static_cast<int>(column.size()) ? column[index] : index;
}

void PerFlightModel::set_params(const std::vector<double>& p) {
  if (p.size() != names_.size()) throw std::invalid_argument("per-flight model: wrong number of parameters");
  p_ = p;
  for (size_t k = 0; k < flights_.size(); ++k) {
    std::vector<double> inner(column_[k].size());
    for (size_t j = 0; j < inner.size(); ++j) inner[j] = p_[column_[k][j]];
    flights_[k]->set_params(inner);
  }
}

void PerFlightModel::rhs(const double* x, const double* u, double* f, double* A, double* B, double* Bu) const {
  const int k = flight_at(u[t_input_]);
  const DynamicModel& m = *flights_[k];
  const int n = m.num_states(), np_inner = m.num_params(), np = num_params();
  if (B) inner_B_.resize(static_cast<size_t>(n) * np_inner);
  m.rhs(x, u, f, A, B ? inner_B_.data() : nullptr, Bu);
  if (!B) return;
  std::fill(B, B + static_cast<size_t>(n) * np, 0.0);
  const auto& column = column_[k];
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < np_inner; ++j) B[i * np + column[j]] = inner_B_[i * np_inner + j];
}

// Each flight's block holds the inner columns whose copy for that flight is asked for;
// place[k][q] is where the flight's q-th inner column goes in the block asked for. The other
// columns of the block (another flight's copies) are zero for this flight, as in rhs().
DynamicModel::ParamBlock PerFlightModel::param_block(std::vector<int> rows, std::vector<int> columns) const {
  ParamBlock b{std::move(rows), std::move(columns), {}, {}, {}, layout_token_};
  for (size_t k = 0; k < flights_.size(); ++k) {
    std::vector<int> inner, place;
    for (size_t q = 0; q < b.columns.size(); ++q)
      for (size_t j = 0; j < column_[k].size(); ++j)
        if (column_[k][j] == b.columns[q]) {
          inner.push_back(static_cast<int>(j));
          place.push_back(static_cast<int>(q));
        }
    b.inner.push_back(flights_[k]->param_block(b.rows, inner));
    b.place.push_back(std::move(place));
  }
  return b;
}

void PerFlightModel::rhs_block(const double* x, const double* u, double* f, const ParamBlock& block, double* B) const {
  if (block.prepared_by != layout_token_ || block.inner.size() != flights_.size())
    return DynamicModel::rhs_block(x, u, f, block, B);
  const int k = flight_at(u[t_input_]);
  const ParamBlock& in = block.inner[static_cast<size_t>(k)];
  const size_t rows = block.rows.size(), nc = block.columns.size(), nc_inner = in.columns.size();
  inner_B_.resize(rows * nc_inner);
  flights_[static_cast<size_t>(k)]->rhs_block(x, u, f, in, inner_B_.data());
  std::fill(B, B + rows * nc, 0.0);
  const auto& place = block.place[static_cast<size_t>(k)];
  for (size_t i = 0; i < rows; ++i)
    for (size_t q = 0; q < nc_inner; ++q) B[i * nc + static_cast<size_t>(place[q])] = inner_B_[i * nc_inner + q];
}

std::vector<Parameter> PerFlightModel::parameters() const {
  const std::vector<Parameter> inner = flights_[0]->parameters();
  std::vector<Parameter> out(names_.size());
  for (size_t k = 0; k < column_.size(); ++k)
    for (size_t j = 0; j < inner.size(); ++j) {
      Parameter& p = out[column_[k][j]];
      p = inner[j];
      p.name = names_[column_[k][j]];
      p.value = p_[column_[k][j]];
    }
  return out;
}

void PerFlightModel::measurement(const double* x, double t, double* h, double* H, double* Hp) const {
  const int k = flight_at(t);
  const DynamicModel& m = *flights_[k];
  const int ny = m.num_outputs(), np_inner = m.num_params(), np = num_params();
  std::vector<double> inner_Hp(Hp ? static_cast<size_t>(ny) * np_inner : 0);
  m.measurement(x, t, h, H, Hp ? inner_Hp.data() : nullptr);
  if (!Hp) return;
  std::fill(Hp, Hp + static_cast<size_t>(ny) * np, 0.0);
  const auto& column = column_[k];
  for (int i = 0; i < ny; ++i)
    for (int j = 0; j < np_inner; ++j) Hp[i * np + column[j]] = inner_Hp[i * np_inner + j];
}

void PerFlightModel::restrict_param_jacobian(const std::vector<int>& columns) {
  if (columns == restricted_to_) return;  // a cache: the same columns as the last call
  restricted_to_ = columns;
  // An inner column is needed when any flight's copy of it is.
  std::set<int> wanted(columns.begin(), columns.end());
  std::vector<int> inner;
  for (size_t j = 0; j < column_[0].size(); ++j)
    for (const auto& column : column_)
      if (wanted.count(column[j])) {
        inner.push_back(static_cast<int>(j));
        break;
      }
  if (columns.empty()) inner.clear();
  for (auto& m : flights_) m->restrict_param_jacobian(inner);
}

}  // namespace quadgen::runtime
