// Several flights of one airframe fitted together share the airframe's parameters, but some
// quantities belong to the flight, not to the airframe: a motor trim that changes when a
// motor, a propeller or the battery is re-seated, the wind of the day. PerFlightModel gives
// such parameters one value per flight around an unchanged model.
//
// Its parameters are the inner model's, which flight 1 uses, followed by one copy of each
// per-flight parameter for each further flight: "motor_gain.M2@2" is the second flight's
// motor_gain.M2. An evaluation belongs to the flight whose stretch of the joined clock
// (fit::join_flights) its time input "t" lies in, so fits, windowed simulations and
// predictions of the joined log need no notion of flights of their own. df/dp of a flight
// lands in that flight's columns; a per-flight parameter's other copies get zero.
#pragma once
#include <memory>
#include <string>
#include <map>
#include <utility>
#include <vector>

#include "runtime/dynamic_model.hpp"

namespace quadgen::runtime {

// "<parameter>@<flight>" for flights 2, 3, ... (flight 1 keeps the plain name).
std::string per_flight_name(const std::string& parameter, int flight);
// The parameter a name stands for ("motor_gain.M2@2" -> "motor_gain.M2"), and its flight
// (1 for a plain name).
std::string shared_name(const std::string& name);
int flight_of_name(const std::string& name);
// Each parameter's mean over its flights' copies (name, name@2, ...), by shared name: the
// airframe's value of a per-flight parameter; a parameter without copies keeps its value.
std::map<std::string, double> mean_over_flights(const std::vector<std::pair<std::string, double>>& values);

class PerFlightModel : public DynamicModel {
 public:
  // `flight_starts`: where flights 2..K begin on the joined clock (increasing); `per_flight`:
  // names of the inner parameters that take one value per flight. The inner model must be
  // copyable (clone) and have the time input "t". Throws std::invalid_argument otherwise.
  PerFlightModel(const DynamicModel& inner, std::vector<double> flight_starts, const std::vector<std::string>& per_flight);
  PerFlightModel(const PerFlightModel& other);

  int num_flights() const { return static_cast<int>(flights_.size()); }
  int flight_at(double t) const;  // 0-based flight of this time on the joined clock

  int num_states() const override { return flights_[0]->num_states(); }
  int num_inputs() const override { return flights_[0]->num_inputs(); }
  int num_params() const override { return static_cast<int>(names_.size()); }
  const std::vector<std::string>& state_names() const override { return flights_[0]->state_names(); }
  const std::vector<std::string>& input_names() const override { return flights_[0]->input_names(); }
  const std::vector<std::string>& param_names() const override { return names_; }
  const std::vector<double>& params() const override { return p_; }
  void set_params(const std::vector<double>& p) override;
  void rhs(const double* x, const double* u, double* f, double* A, double* B, double* Bu) const override;
  ParamBlock param_block(std::vector<int> rows, std::vector<int> columns) const override;
  void rhs_block(const double* x, const double* u, double* f, const ParamBlock& block, double* B) const override;
  void rhs_rows(const double* x, const double* u, const std::vector<int>& rows, double* f) const override {
    flights_[flight_at(u[t_input_])]->rhs_rows(x, u, rows, f);
  }
  void restrict_param_jacobian(const std::vector<int>& columns) override;
  std::vector<Parameter> parameters() const override;  // a flight's copy as flight 1's, renamed
  int num_outputs() const override { return flights_[0]->num_outputs(); }
  void measurement(const double* x, double t, double* h, double* H, double* Hp) const override;
  int input_delay_param() const override { return flights_[0]->input_delay_param(); }  // flight 1's copy
  const std::vector<int>& rotor_speed_states() const override { return flights_[0]->rotor_speed_states(); }
  std::unique_ptr<DynamicModel> clone() const override { return std::make_unique<PerFlightModel>(*this); }
  int param_column(int index, double t) const override;

 private:
  std::vector<std::unique_ptr<DynamicModel>> flights_;  // the inner model, one copy per flight
  std::vector<double> starts_;
  int t_input_ = -1;
  std::vector<std::string> names_;
  std::vector<double> p_;
  // column_[k][j]: the column of inner parameter j for flight k in this model's parameters.
  std::vector<std::vector<int>> column_;
  mutable std::vector<double> inner_B_;
  std::vector<int> restricted_to_;  // the columns of the last restrict_param_jacobian (empty: all)
  // What a ParamBlock of this model carries (prepared_by): made with the layout of columns,
  // shared by the copies and the blocks, so a block of another per-flight model of the same
  // size is not read with this one's columns.
  std::shared_ptr<const void> layout_token_ = std::make_shared<const char>(0);
};

}  // namespace quadgen::runtime
