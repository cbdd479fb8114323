// The consistent-filter reference of the Monte Carlo NEES test (eval/nees_null): autocorrelation,
// AR fit and the simulated fraction of steps inside the 95 % bounds, on processes whose answers
// are known.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "eval/metrics/nees_null.hpp"

using namespace wingman::eval;

namespace {
// `runs` AR(1) series of `steps` steps with unit variance and lag-1 correlation rho.
std::vector<std::vector<double>> ar1_runs(int runs, std::size_t steps, double rho, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n(0.0, 1.0);
  std::vector<std::vector<double>> out(runs, std::vector<double>(steps));
  for (auto& r : out) {
    double z = n(rng);
    for (auto& v : r) {
      v = z;
      z = rho * z + std::sqrt(1 - rho * rho) * n(rng);
    }
  }
  return out;
}

std::vector<std::size_t> iota(std::size_t from, std::size_t to) {
  std::vector<std::size_t> v;
  for (std::size_t k = from; k < to; ++k) v.push_back(k);
  return v;
}
}  // namespace

TEST(NeesNull, AutocorrelationOfAnAr1ProcessIsRhoToTheLag) {
  const auto runs = ar1_runs(50, 2000, 0.9, 7);
  const auto acf = nees_autocorrelation(runs, 0, 2000, 20);
  ASSERT_EQ(acf.size(), 21u);
  EXPECT_DOUBLE_EQ(acf[0], 1.0);
  EXPECT_NEAR(acf[1], 0.9, 0.01);
  EXPECT_NEAR(acf[5], std::pow(0.9, 5), 0.02);
  EXPECT_NEAR(acf[20], std::pow(0.9, 20), 0.03);
  // 1 + 2 sum rho^h = (1 + rho) / (1 - rho) = 19 when the lags reach far enough (60 lags:
  // 0.9^60 = 0.002); a noisy estimate, 17.8-20.2 over eight seeds.
  EXPECT_NEAR(integrated_correlation_steps(nees_autocorrelation(runs, 0, 2000, 60)), 19.0, 2.5);
}

TEST(NeesNull, TooFewRunsOrStepsGiveAWhiteProcess) {
  EXPECT_EQ(nees_autocorrelation(ar1_runs(1, 100, 0.9, 1), 0, 100, 10).size(), 1u);
  EXPECT_EQ(nees_autocorrelation(ar1_runs(5, 100, 0.9, 1), 10, 11, 10).size(), 1u);
  EXPECT_THROW(nees_autocorrelation(ar1_runs(5, 100, 0.9, 1), 0, 101, 10), std::invalid_argument);
}

TEST(NeesNull, LevinsonDurbinRecoversAnAr1AndAnAr2) {
  std::vector<double> acf;
  for (int h = 0; h <= 6; ++h) acf.push_back(std::pow(0.8, h));
  const Autoregression a1 = fit_autoregression(acf);
  ASSERT_EQ(a1.phi.size(), 6u);
  EXPECT_NEAR(a1.phi[0], 0.8, 1e-12);
  for (std::size_t i = 1; i < a1.phi.size(); ++i) EXPECT_NEAR(a1.phi[i], 0.0, 1e-12);
  EXPECT_NEAR(a1.innovation_variance, 1 - 0.64, 1e-12);
  // AR(2) z_k = 0.5 z_{k-1} + 0.3 z_{k-2} + e: Yule-Walker gives r1 = 0.5 / 0.7, r_h = 0.5 r_{h-1} + 0.3 r_{h-2}.
  std::vector<double> r = {1.0, 0.5 / 0.7};
  for (int h = 2; h <= 5; ++h) r.push_back(0.5 * r[h - 1] + 0.3 * r[h - 2]);
  const Autoregression a2 = fit_autoregression(r);
  EXPECT_NEAR(a2.phi[0], 0.5, 1e-12);
  EXPECT_NEAR(a2.phi[1], 0.3, 1e-12);
  EXPECT_NEAR(a2.phi[2], 0.0, 1e-12);
  EXPECT_NEAR(a2.innovation_variance, 1 - 0.5 * r[1] - 0.3 * r[2], 1e-12);
}

TEST(NeesNull, WhiteStepsAreInsideOn95PercentAndAlmostNeverUnder90) {
  const Autoregression white;  // no coefficients, unit variance
  const auto sim = simulate_consistent_inside(white, 1000, {iota(0, 1000)}, 1, 0.9, 500, 3);
  EXPECT_NEAR(sim.median[0], 0.95, 0.01);
  EXPECT_LT(sim.p_below[0], 0.01);  // binomial sd 0.007: 0.9 is 7 sd away
  EXPECT_GT(sim.p_all_at_target, 0.99);
}

TEST(NeesNull, CorrelatedStepsKeep95PercentOnAverageButOftenFallUnder90) {
  Autoregression ar;
  ar.phi = {0.99};
  ar.innovation_variance = 1 - 0.99 * 0.99;
  const std::vector<std::vector<std::size_t>> phases = {iota(0, 700), iota(700, 1400), iota(1400, 2100)};
  const auto sim = simulate_consistent_inside(ar, 2100, phases, 3, 0.9, 2000, 5);
  for (int p = 0; p < 3; ++p) {
    EXPECT_GT(sim.median[p], 0.95);  // skewed: most phases stay inside, a few fall far
    EXPECT_GT(sim.p_below[p], 0.05);
    EXPECT_LT(sim.p_below[p], 0.4);
  }
  // Three nearly independent phases: all at target about as often as the product.
  const double product = (1 - sim.p_below[0]) * (1 - sim.p_below[1]) * (1 - sim.p_below[2]);
  EXPECT_NEAR(sim.p_all_at_target, product, 0.05);
  EXPECT_LT(sim.p_all_at_target, 0.9);
  // The same seed repeats.
  const auto again = simulate_consistent_inside(ar, 2100, phases, 3, 0.9, 2000, 5);
  EXPECT_EQ(again.p_below, sim.p_below);
}

// The simulation runs eight series side by side; each must come out exactly as the plain loop
// over one series at a time makes it (the loop below, which the code used before), for a number
// of series that does not fill the last group of eight.
TEST(NeesNull, InterleavedSeriesMatchTheOneAtATimeLoopExactly) {
  // An AR(40) fitted to a slowly decaying correlation, like the paper runs' NEES.
  std::vector<double> acf(41);
  for (std::size_t h = 0; h < acf.size(); ++h) acf[h] = std::exp(-static_cast<double>(h) / 15.0);
  const Autoregression ar = fit_autoregression(acf);
  ASSERT_GT(ar.phi.size(), 10u);
  const std::vector<std::vector<std::size_t>> ranges = {iota(0, 120), iota(120, 300), iota(0, 300)};
  const int sims = 21;
  const double target = 0.9;

  std::vector<std::vector<double>> fractions(ranges.size());
  std::vector<double> p_below(ranges.size(), 0.0);
  int all_at_target = 0;
  {
    const std::size_t p = ar.phi.size(), burn_in = 3 * p + 1;
    std::mt19937_64 rng(9);
    std::normal_distribution<double> white(0.0, std::sqrt(ar.innovation_variance));
    std::vector<double> z(burn_in + 300);
    for (int s = 0; s < sims; ++s) {
      for (std::size_t k = 0; k < z.size(); ++k) {
        double v = white(rng);
        for (std::size_t i = 0; i < p && i < k; ++i) v += ar.phi[i] * z[k - 1 - i];
        z[k] = v;
      }
      bool all = true;
      for (std::size_t r = 0; r < ranges.size(); ++r) {
        int inside = 0;
        for (std::size_t k : ranges[r]) inside += std::abs(z[burn_in + k]) <= kZ975;
        const double f = static_cast<double>(inside) / static_cast<double>(ranges[r].size());
        fractions[r].push_back(f);
        if (f < target) {
          p_below[r] += 1.0;
          if (r < 2) all = false;
        }
      }
      all_at_target += all;
    }
  }
  const auto sim = simulate_consistent_inside(ar, 300, ranges, 2, target, sims, 9);
  for (std::size_t r = 0; r < ranges.size(); ++r) {
    auto f = fractions[r];
    std::nth_element(f.begin(), f.begin() + static_cast<std::ptrdiff_t>(f.size() / 2), f.end());
    EXPECT_EQ(sim.median[r], f[f.size() / 2]) << r;
    EXPECT_EQ(sim.p_below[r], p_below[r] / sims) << r;
  }
  EXPECT_EQ(sim.p_all_at_target, static_cast<double>(all_at_target) / sims);
  // Not a vacuous comparison: the phases are short enough that some series fall under 90 %.
  EXPECT_GT(p_below[0], 0.0);
  EXPECT_LT(p_below[0], sims);
}
