// Equation-error residuals: at every logged sample, the model's accelerations evaluated at
// the measured state and commands against the measured ones: specific force from the
// accelerometer (or the derivative of the velocity), and the derivative of the gyro.
// Jacobians come from the model's analytic df/dp.
// Effects that act before the dynamics are applied to the data instead: input_delay shifts
// the logged commands, motor_lag filters the commanded rotor speeds into the rotor-speed
// states, attitude_bias turns the logged attitude back into the true one; their Jacobian
// columns are central differences of the residuals, as are those of any parameter that
// shapes the commanded rotor speeds the lag filters (the motor map). Suits logs with good state estimates
// and IMU data; it needs no integration and so cannot drift. (Multiple shooting, which
// compares integrated windows with the pose, is the other formulation; see README.)
#pragma once
#include <array>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "runtime/data_side_effects.hpp"
#include "runtime/dynamic_model.hpp"
#include "fit/flight_data.hpp"
#include "fit/least_squares.hpp"

namespace quadgen::fit {

// The first sample at or after t of samples in time order, as std::lower_bound finds it.
// With a cursor (the answer of the previous lookup) it searches on from there when t has not
// gone back: the times a pass looks up rise, so that is a step or two, where the binary
// search over the whole flight was a twentieth of a diagnosis' time.
std::vector<FlightSample>::const_iterator first_at_or_after(const std::vector<FlightSample>& samples, double t,
                                                            size_t* cursor = nullptr);

class EquationErrorModel : public ResidualModel {
 public:
  // The model's parameters are the fit parameters; `use_accelerometer` picks specific
  // force (body) over differentiated velocity (world) for the translational channels.
  // `use` selects channels by name (empty: all six).
  // Differentiated channels (gyro, and velocity without an accelerometer):
  //  - kFiltered: the log's derivative is a local quadratic (Savitzky-Golay) fit over
  //    +-window, and the model's accelerations, evaluated at the middle of every sample
  //    interval with the commands held over it, go through the same filter. Exact for
  //    any signal content, zero-order-held commands included; samples whose window leaves
  //    a contiguous stretch of the log are not used.
  //  - kPointwise: the model at each sample against the derivatives stored in the flight
  //    (acc_world, rate_dot); right only for slowly varying signals.
  enum class Derivatives { kFiltered, kPointwise };
  EquationErrorModel(runtime::DynamicModel& model, Flight flight, bool use_accelerometer,
                     std::vector<std::string> use = {}, Derivatives d = Derivatives::kFiltered,
                     double window = 0.05);
  int num_residuals() const override { return static_cast<int>(rows_.size() * used_.size()); }
  // How the acceleration over a sample interval is approximated: at the interval's middle
  // (state averaged), or as the mean of its ends. Their difference bounds the
  // discretisation error of estimates (diagnose adds it to intervals).
  enum class Quadrature { kMidpoint, kTrapezoid };
  void set_quadrature(Quadrature q) { quadrature_ = q; }
  // Sample (index into flight().samples) of each residual row.
  const std::vector<size_t>& rows() const { return rows_; }
  void evaluate(const double* p, double* r, double* J) const override { evaluate_free(p, r, J, {}); }
  void evaluate_free(const double* p, double* r, double* J, const std::vector<bool>& free) const override;
  void evaluate_columns(const std::vector<double>& p, double* r, double* J,
                        const std::vector<int>& columns) const override;
  int channel_of(int i) const override { return i % static_cast<int>(used_.size()); }
  std::vector<std::string> channels() const override;
  std::unique_ptr<ResidualModel> clone() const override;  // with its own copy of the dynamic model
  // Residuals of all six channels of every row (rows() x 6), at these parameters.
  void all_channels(const double* p, std::vector<double>& r6) const;
  std::vector<double> all_channels(const std::vector<FitParameter>& ps) const;
  // What the residuals compare the model with, in the same six channels of every row
  // (rows() x 6): the filtered derivatives of the log (or its stored derivatives, pointwise),
  // the accelerometer's specific force for the translation when it is used. The model's
  // accelerations at p are all_channels(p) plus these.
  std::vector<double> measured_channels() const;
  const Flight& flight() const { return flight_; }
  // Into how many parts, each on a thread of its own, the last split of an evaluation went
  // (evaluation_threads.hpp; 0 before the first). For tests, which cannot otherwise tell a
  // split evaluation from one that stayed on the calling thread: both give the same numbers.
  size_t last_split_parts() const { return helpers_.last_parts; }

 private:
  runtime::DynamicModel* model_;  // the caller's, or owned_model_ in a clone
  std::shared_ptr<runtime::DynamicModel> owned_model_;
  Flight flight_;
  bool accel_;
  int g_index_;
  std::vector<int> used_;  // indices into the six channels
  runtime::DataSideParams data_side_;  // parameters applied to the data
  runtime::ExtraInputs extra_;  // where t and vbat go (indices, the same in a clone)
  std::vector<int> speed_states_;  // w_<rotor> state of each rotor (motor_lag)
  // Samples [lo, hi) of the log: a range of whole contiguous stretches.
  struct SampleSpan {
    size_t lo = 0, hi = 0;
  };
  // Every column those parameters take over the flight (several when they differ by flight),
  // with the stretches whose residuals it can change: a per-flight copy changes its own
  // flight's only, so its difference quotient re-evaluates that flight, not the joined log.
  std::vector<int> data_side_columns_;
  std::vector<SampleSpan> data_side_spans_;
  Derivatives derivatives_;
  std::vector<size_t> rows_;
  // kFiltered: for each row, the first sample of its window, the weights of the model's
  // interval accelerations, and the measured derivatives (velocity world, gyro body).
  std::vector<size_t> window_start_;
  std::vector<std::vector<double>> interval_weights_;
  std::vector<std::array<double, 6>> measured_;
  std::vector<bool> interval_ok_;  // interval k -> k+1 lies inside a contiguous stretch
  // Interval k -> k+1 is long enough (> runtime::kRotorRestartGap) that the rotors restart
  // after it.
  std::vector<bool> rotors_restart_;
  bool rotors_continue(size_t k) const { return !rotors_restart_[k - 1]; }
  double gap_ = 0;  // s: a longer sample interval is a gap
  void mark_contiguous_intervals();
  void find_data_side_columns();
  std::vector<std::pair<int, size_t>> commanded_speed_columns() const;
  void build_filter(double window);
  Quadrature quadrature_ = Quadrature::kMidpoint;
  // Scratch of one evaluation, not state, kept to reuse the allocations (one instance serves
  // one thread; clone()): a search evaluates thousands of times, and arrays of the whole
  // flight allocated afresh each time cost page faults (a third of an instrumented run's time,
  // whose allocator hands out fresh memory) and zero-filling. Not copied with the instance.
  struct Scratch {
    std::vector<double> X, U;    // prepare(): states and inputs of every sample
    std::vector<double> tau;     // prepare(): each rotor's lag at every sample
    std::vector<double> F, Bm;   // interval_accelerations()
    std::vector<double> r6, J6;  // evaluate_packed() of fewer than six channels
    std::vector<double> packed;  // evaluate_free(): the packed Jacobian before it is spread out
    std::vector<double> mean_speed;  // prepare(): rotor speeds averaged over each interval (motor_lag)
    Scratch() = default;
    Scratch(const Scratch&) {}
    Scratch& operator=(const Scratch&) { return *this; }
  };
  mutable Scratch scratch_;
  // Copies of the dynamic model for the helper threads of a split evaluation
  // (evaluation_threads.hpp), made when first needed; each remembers the parameters and
  // Jacobian columns it was last given (a residuals() call splits twice, and setting
  // parameters reruns the model's precompute step). Not copied with the instance: a clone()
  // makes its own.
  struct Helper {
    std::unique_ptr<runtime::DynamicModel> model;
    std::vector<double> params;
    std::vector<int> columns = {-1};  // none passed yet
  };
  struct Helpers {
    std::vector<Helper> list;
    size_t last_parts = 0;
    Helpers() = default;
    Helpers(const Helpers&) {}
    Helpers& operator=(const Helpers&) {
      list.clear();
      last_parts = 0;
      return *this;
    }
  };
  mutable Helpers helpers_;
  // Runs part(model, lo, hi) over [lo, hi), split between this thread (model_) and helper
  // threads, each with its own copy of the model at parameters p and, when `columns` is
  // given, computing those Jacobian columns.
  template <class Part>
  void split_over_cores(size_t lo, size_t hi, const double* p, const std::vector<int>* columns,
                        const Part& part) const;
  static std::vector<std::string> channel_names();  // all six, in order
  // The used channels (evaluate_packed) or all six (evaluate6) of every row, the Jacobian
  // packed to `columns`.
  void evaluate_packed(const double* p, double* r, double* J, const std::vector<int>& columns) const;
  void evaluate6(const double* p, double* r, double* J, const std::vector<int>& columns) const;
  // Full model state and inputs of every sample (states row-major ns x n, inputs ns x nu).
  // Only the samples in `span` are filled (the others stay zero).
  void prepare(const double* p, std::vector<double>& X, std::vector<double>& U, SampleSpan span) const;
  // prepare()'s rotor-speed states (motor_lag): the commands' speeds through each rotor's lag
  // (scratch_.tau), and their means over each interval into scratch_.mean_speed.
  void filter_rotor_speeds(std::vector<double>& X, const std::vector<double>& U, SampleSpan span) const;
  // Rotor commands interpolated at t; `cursor` (optional) carries the search's position
  // from one lookup to the next of a pass in time order.
  void commands_at(double t, double* u, size_t* cursor = nullptr) const;
  // The model's inputs at sample s with the commands logged at command_time (s.t less a
  // delay): the rotor commands, and the time and battery voltage where the model has them.
  void inputs_at(const FlightSample& s, double command_time, double* u, size_t* cursor = nullptr) const;
  SampleSpan all_samples() const { return {0, flight_.samples.size()}; }
  // First and one-past-last residual row whose sample lies in `span`.
  std::pair<size_t, size_t> rows_in(SampleSpan span) const;
  // Residuals (and the df/dp columns in `columns`, packed) of the rows in `span`: row i of
  // that range at r + 6 i, its Jacobian rows at J + 6 i columns.size(). A search step frees a few of the 30-80
  // parameters of a per-flight model; the Jacobian work follows the free ones.
  void residuals(const double* p, double* r, double* J, SampleSpan span, const std::vector<int>& columns) const;
  void interval_accelerations(const double* p, const std::vector<double>& X, const std::vector<double>& U,
                              std::vector<double>& F, std::vector<double>* Bm, SampleSpan span,
                              const std::vector<int>& columns) const;
  // What the rows of one residuals() call share (read only) and what each part of it keeps
  // per row (its own scratch).
  struct Evaluation {
    const double* p;
    const std::vector<double>& X;  // prepare()
    const std::vector<double>& U;
    const std::vector<double>& F;   // interval accelerations (filtered derivatives)
    const std::vector<double>& Bm;  // and their df/dp columns
    const std::vector<int>& columns;
    bool jacobian;
  };
  struct RowScratch {
    std::vector<double> f, B;  // the model's f and df/dp at the row's sample
    std::vector<double> a6, Ba6;  // the six accelerations the row compares (B packed to `columns`)
    double measured[6];
  };
  void row_accelerations(const runtime::DynamicModel& model, const Evaluation& e, size_t row, RowScratch& s) const;
  void row_residuals(const Evaluation& e, size_t row, const RowScratch& s, double* rk, double* Jk) const;
};


}  // namespace quadgen::fit
