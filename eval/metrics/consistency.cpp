#include "eval/metrics/consistency.hpp"

#include <algorithm>
#include <cmath>

#include "eval/metrics/metrics.hpp"
#include "geometry/chi2.hpp"
#include "eval/metrics/nees_null.hpp"

namespace wingman::eval {

double windowed_rms_bound(const std::vector<Eigen::Vector3d>& a, int window) {
  const int n = static_cast<int>(a.size());
  if (n == 0) return 0;
  window = std::clamp(window, 1, n);
  std::vector<Eigen::Vector3d> s(n + 1, Eigen::Vector3d::Zero());  // prefix sums of the squares
  for (int i = 0; i < n; ++i) s[i + 1] = s[i] + a[i].cwiseAbs2();
  double worst = 0;
  for (int i = 0; i + window <= n; ++i) worst = std::max(worst, ((s[i + window] - s[i]) / window).maxCoeff());
  return std::sqrt(worst);
}

std::pair<double, double> chi2_mean_band(int dof, double n_eff) {
  const double n = std::max(n_eff, 1.0);
  return {geometry::chi2_quantile(0.005, dof * n) / n, geometry::chi2_quantile(0.995, dof * n) / n};
}

namespace {

// Agent a's position (or velocity) NEES over the steps of phase p where it is finite.
std::vector<double> block_series(const RunRecord& run, int p, std::size_t a, bool velocity) {
  std::vector<double> out;
  for (const StepRecord& s : run.steps) {
    if (s.k == 0 || s.phase != p || a >= s.agents.size()) continue;
    const double v = velocity ? s.agents[a].nees_v : s.agents[a].nees_p;
    if (std::isfinite(v)) out.push_back(v);
  }
  return out;
}

// Independent looks a series of n steps is worth: n over its integrated autocorrelation (about
// the series' own mean), summed up to its first non-positive lag (a single run's estimate is
// noisy beyond it).
double independent_looks(const std::vector<double>& x) {
  const std::size_t n = x.size();
  if (n < 4) return static_cast<double>(n);
  double mean = 0;
  for (double v : x) mean += v;
  mean /= static_cast<double>(n);
  double c0 = 0;
  for (double v : x) c0 += (v - mean) * (v - mean);
  if (!(c0 > 0)) return static_cast<double>(n);
  std::vector<double> acf = {1.0};
  for (std::size_t h = 1; h <= n / 4; ++h) {
    double c = 0;
    for (std::size_t i = h; i < n; ++i) c += (x[i] - mean) * (x[i - h] - mean);
    if (!(c > 0)) break;
    acf.push_back(c / c0);
  }
  return std::clamp(static_cast<double>(n) / integrated_correlation_steps(acf), 1.0, static_cast<double>(n));
}

// The truth's accelerations of agent a in phase p, from its velocity's differences.
double truth_acceleration(const RunRecord& run, int p, std::size_t a) {
  std::vector<Eigen::Vector3d> acc;
  double dt = 0;
  for (std::size_t k = 1; k < run.steps.size(); ++k) {
    const StepRecord &s = run.steps[k], &prev = run.steps[k - 1];
    if (s.phase != p || a >= s.agents.size() || a >= prev.agents.size()) continue;
    dt = s.t - prev.t;
    if (dt > 0) acc.push_back((s.agents[a].v_true - prev.agents[a].v_true) / dt);
  }
  if (acc.empty() || !(dt > 0)) return kNaN;
  return windowed_rms_bound(acc, std::max(1, static_cast<int>(std::lround(kAccelerationWindowS / dt))));
}

double pixel_error(const RunRecord& run) {
  if (std::isfinite(run.assumed.truth_pixel_sigma)) return run.assumed.truth_pixel_sigma;
  double sum = 0;
  long n = 0;
  for (double e : run.frontend.accepted_error_px)
    if (std::isfinite(e) && e < 3.0) sum += e * e, ++n;  // the label inliers: the noise, not the mismatches
  return n > 0 ? std::sqrt(sum / (2.0 * n)) : kNaN;
}

}  // namespace

Consistency diagnose_consistency(const RunRecord& run, const Metrics& m) {
  Consistency c;
  const double pixel = pixel_error(run);
  for (std::size_t p = 0; p < run.phases.size(); ++p) {
    for (std::size_t a = 0; a < run.agent_names.size(); ++a) {
      for (bool velocity : {false, true}) {
        const std::vector<double> x = block_series(run, static_cast<int>(p), a, velocity);
        if (x.empty()) continue;
        const double mean = velocity ? m.nees.velocity_per_phase.at(a).at(p) : m.nees.position_per_phase.at(a).at(p);
        const double looks = independent_looks(x);
        const auto [lo, hi] = chi2_mean_band(3, looks);
        ++c.blocks_checked;
        if (!std::isfinite(mean) || (mean >= lo && mean <= hi)) continue;
        ConsistencyFinding f;
        f.phase = run.phases[p].name;
        f.agent = run.agent_names[a];
        f.block = velocity ? "velocity" : "position";
        f.nees = mean;
        f.band_lo = lo;
        f.band_hi = hi;
        f.independent_looks = looks;
        f.verdict = mean > hi ? "overconfident" : "conservative";
        if (a < run.assumed.accel_sigma.size()) f.assumed_accel_sigma = run.assumed.accel_sigma[a];
        f.truth_accel = truth_acceleration(run, static_cast<int>(p), a);
        f.assumed_pixel_sigma = run.assumed.pixel_sigma;
        f.pixel_error = pixel;
        c.findings.push_back(f);
      }
    }
  }
  return c;
}

}  // namespace wingman::eval
