// What the simulation gets wrong, channel by channel: the equation-error residuals'
// size, bias and whiteness (autocorrelation against its confidence band), a test for slow
// structure the noise cannot produce, and the correlation with physically meaningful
// signals (rotor commands, thrust, body velocity, height, time, battery, command rates).
#pragma once
#include <string>
#include <vector>

#include "fit/flight_data.hpp"

namespace quadgen::diagnose {

// Signals a residual may depend on, sampled like the flight.
struct SignalSet {
  std::vector<std::string> names;
  std::vector<std::vector<double>> values;  // values[signal][sample]
};
SignalSet physical_signals(const fit::Flight& flight, const std::vector<std::string>& rotors);

struct Correlation {
  std::string signal;
  double r = 0;        // Pearson correlation
  double p_value = 1;  // with the residual's effective sample size
};

struct ChannelAnalysis {
  std::string name, unit;
  int samples = 0;
  double rms = 0, bias = 0, sigma = 0;
  // Integrated autocorrelation time (1 + 2 sum of the initial positive autocorrelations):
  // how many samples carry the information of one independent one.
  double tau_int = 1;
  std::vector<double> acf;    // lags 0..max_lag
  double acf_band = 0;        // +-1.96/sqrt(n): white noise stays inside
  double acf_outside = 0;     // fraction of lags beyond the short-range correlation outside the band
  // Slow structure: means over 1 s windows against what the short-range correlated noise
  // would give (chi2 with one degree of freedom per window).
  double slow_rms = 0, slow_ratio = 0, slow_p_value = 1;
  double worst_window_t0 = 0, worst_window_t1 = 0, worst_window_mean = 0;
  std::vector<Correlation> correlations;  // strongest first
};

struct ResidualAnalysis {
  std::vector<ChannelAnalysis> channels;
};

// r6: ns x 6 residuals (model - measurement) of a flight; t: sample times.
ResidualAnalysis analyse_residuals(const std::vector<double>& r6, const std::vector<std::string>& channel_names,
                                   const std::vector<std::string>& channel_units, const std::vector<double>& t,
                                   const SignalSet& signals);

// Integrated autocorrelation time of a series (used to discount autocorrelated residuals).
double integrated_autocorrelation_time(const std::vector<double>& x, int max_lag = 100);

// Autocorrelation of a series at lags 0..max_lag (its mean removed; the biased estimator, as
// usual for ACF plots).
std::vector<double> autocorrelation(const std::vector<double>& x, int max_lag);

// Bartlett's effective sample size for the correlation of two autocorrelated series of n
// samples, from their autocorrelations: n / (1 + 2 sum_{k=1..lag} rho_x(k) rho_y(k)), kept
// within [3, n].
double bartlett_effective_n(const std::vector<double>& acf_x, const std::vector<double>& acf_y, size_t n, int lag);

}  // namespace quadgen::diagnose
