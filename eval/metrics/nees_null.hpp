// What an exactly consistent filter would show on the Monte Carlo NEES test, given how these
// runs' errors are correlated in time. The average NEES of N runs is inside its 95 % chi^2 bounds
// on 95 % of the steps only on average: its error decorrelates over seconds, so the fraction of a
// phase's steps inside is itself a random number with a wide spread. We fit an AR(p) model to the
// runs' NEES autocorrelation (Levinson-Durbin on the biased estimate, which is positive
// semi-definite), simulate a Gaussian process with that correlation and read it through the
// chi^2 bounds. A consistent filter's average NEES is a monotone function of such a process with
// the exact chi^2 marginal, so a step is inside exactly when |z| <= 1.96.
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

namespace wingman::eval {

// Phi^-1(0.975): the two-sided 95 % bounds of a standard normal.
inline constexpr double kZ975 = 1.959963984540054;

// Normalised autocorrelation r(0) = 1 .. r(max_lag) of the runs' series about their per-step
// mean, over the steps [first, last). Every run must be finite there. Biased estimator (sums over
// the overlap divided by the whole length), so the sequence is positive semi-definite.
std::vector<double> nees_autocorrelation(const std::vector<std::vector<double>>& per_run,
                                         std::size_t first, std::size_t last, std::size_t max_lag);

// z_k = sum_i phi_i z_{k-i} + e_k with var(e) = innovation_variance and var(z) = 1.
struct Autoregression {
  std::vector<double> phi;
  double innovation_variance = 1.0;
};
// Yule-Walker by Levinson-Durbin from r(0) = 1 .. r(p). Stops early where the estimate is
// singular (a partial correlation of magnitude >= 1).
Autoregression fit_autoregression(const std::vector<double>& acf);

// 1 + 2 sum r(h): how many steps one independent look at the NEES is worth.
double integrated_correlation_steps(const std::vector<double>& acf);

struct ConsistentFilterInside {
  std::vector<double> median;     // per range: median fraction of its steps inside the bounds
  std::vector<double> p_below;    // per range: probability the fraction is under `target`
  double p_all_at_target = 0;     // probability the first ranges_in_all are all at or above it
};
// `sims` simulated series of `steps` steps; each range is a list of step indices.
ConsistentFilterInside simulate_consistent_inside(const Autoregression& ar, std::size_t steps,
                                                  const std::vector<std::vector<std::size_t>>& ranges,
                                                  std::size_t ranges_in_all, double target, int sims,
                                                  std::uint64_t seed);

}  // namespace wingman::eval
