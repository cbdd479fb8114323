#include "eval/metrics/nees_null.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>

namespace wingman::eval {

std::vector<double> nees_autocorrelation(const std::vector<std::vector<double>>& per_run,
                                         std::size_t first, std::size_t last, std::size_t max_lag) {
  if (per_run.size() < 2 || last <= first + 1) return {1.0};
  const std::size_t n = last - first;
  max_lag = std::min(max_lag, n - 1);
  std::vector<double> mean(n, 0.0);
  for (const auto& run : per_run) {
    if (run.size() < last) throw std::invalid_argument("nees_autocorrelation: a run is too short");
    for (std::size_t k = 0; k < n; ++k) mean[k] += run[first + k];
  }
  for (double& m : mean) m /= static_cast<double>(per_run.size());
  std::vector<double> acf(max_lag + 1, 0.0);
  std::vector<double> d(n);
  for (const auto& run : per_run) {
    for (std::size_t k = 0; k < n; ++k) d[k] = run[first + k] - mean[k];
    for (std::size_t h = 0; h <= max_lag; ++h)
      for (std::size_t k = 0; k + h < n; ++k) acf[h] += d[k] * d[k + h];
  }
  if (!(acf[0] > 0)) return {1.0};
  for (std::size_t h = max_lag + 1; h-- > 0;) acf[h] /= acf[0];
  return acf;
}

Autoregression fit_autoregression(const std::vector<double>& acf) {
  Autoregression ar;
  double e = 1.0;
  std::vector<double> phi, prev;
  for (std::size_t m = 1; m < acf.size(); ++m) {
    double num = acf[m];
    for (std::size_t i = 1; i < m; ++i) num -= phi[i - 1] * acf[m - i];
    const double k = num / e;
    if (!(std::abs(k) < 1.0)) break;
    prev = phi;
    phi.push_back(k);
    for (std::size_t i = 1; i < m; ++i) phi[i - 1] = prev[i - 1] - k * prev[m - i - 1];
    e *= 1.0 - k * k;
  }
  ar.phi = std::move(phi);
  ar.innovation_variance = e;
  return ar;
}

double integrated_correlation_steps(const std::vector<double>& acf) {
  double s = 1.0;
  for (std::size_t h = 1; h < acf.size(); ++h) s += 2.0 * acf[h];
  return s;
}

ConsistentFilterInside simulate_consistent_inside(const Autoregression& ar, std::size_t steps,
                                                  const std::vector<std::vector<std::size_t>>& ranges,
                                                  std::size_t ranges_in_all, double target, int sims,
                                                  std::uint64_t seed) {
  ConsistentFilterInside out;
  out.median.assign(ranges.size(), 0.0);
  out.p_below.assign(ranges.size(), 0.0);
  if (sims <= 0 || steps == 0) return out;
  for (const auto& range : ranges)
    for (std::size_t k : range)
      if (k >= steps) throw std::out_of_range("simulate_consistent_inside: a range step is past `steps`");
  const std::size_t p = ar.phi.size();
  const std::size_t burn_in = 3 * p + 1;
  const std::size_t n = burn_in + steps;
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> white(0.0, std::sqrt(ar.innovation_variance));
  // kLanes series at a time, step-major (z[k * kLanes + j]): each series' sum runs in the same
  // order as one series alone would (same result to the bit), but the lanes' sums are independent,
  // so they overlap instead of waiting on one chain of additions (the AR order is up to 600).
  constexpr std::size_t kLanes = 8;
  std::vector<double> z(n * kLanes);
  std::vector<std::vector<double>> fractions(ranges.size());
  int all_at_target = 0;
  for (int s0 = 0; s0 < sims; s0 += static_cast<int>(kLanes)) {
    const std::size_t lanes = std::min<std::size_t>(kLanes, static_cast<std::size_t>(sims - s0));
    // The innovations, drawn series after series as before.
    for (std::size_t j = 0; j < lanes; ++j)
      for (std::size_t k = 0; k < n; ++k) z[k * kLanes + j] = white(rng);
    for (std::size_t k = 0; k < n; ++k) {
      double v[kLanes];
      for (std::size_t j = 0; j < kLanes; ++j) v[j] = z[k * kLanes + j];
      for (std::size_t i = 0; i < p && i < k; ++i) {
        const double c = ar.phi[i];
        const double* past = &z[(k - 1 - i) * kLanes];
        for (std::size_t j = 0; j < kLanes; ++j) v[j] += c * past[j];
      }
      for (std::size_t j = 0; j < kLanes; ++j) z[k * kLanes + j] = v[j];
    }
    for (std::size_t j = 0; j < lanes; ++j) {
      bool all = true;
      for (std::size_t r = 0; r < ranges.size(); ++r) {
        if (ranges[r].empty()) continue;
        int inside = 0;
        for (std::size_t k : ranges[r]) inside += std::abs(z[(burn_in + k) * kLanes + j]) <= kZ975;
        const double f = static_cast<double>(inside) / static_cast<double>(ranges[r].size());
        fractions[r].push_back(f);
        if (f < target) {
          out.p_below[r] += 1.0;
          if (r < ranges_in_all) all = false;
        }
      }
      all_at_target += all;
    }
  }
  for (std::size_t r = 0; r < ranges.size(); ++r) {
    auto& f = fractions[r];
    if (f.empty()) {
      out.median[r] = out.p_below[r] = std::nan("");
      continue;
    }
    std::nth_element(f.begin(), f.begin() + static_cast<std::ptrdiff_t>(f.size() / 2), f.end());
    out.median[r] = f[f.size() / 2];
    out.p_below[r] /= sims;
  }
  out.p_all_at_target = static_cast<double>(all_at_target) / sims;
  return out;
}

}  // namespace wingman::eval
