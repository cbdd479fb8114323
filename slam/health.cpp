#include "slam/health.hpp"

#include <fmt/core.h>
#include <fmt/ranges.h>

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>

namespace wingman::slam {
namespace {

constexpr const char* kAxes = "xyz";

[[noreturn]] void fail(const FilterState& s, const std::string& stage, int i, const std::string& what) {
  throw NumericalFailure(fmt::format("numerical failure in the filter after {}: {} of {} (state index {} "
                                     "of {})",
                                     stage, what, describe_state_element(s, i), i, s.dim()));
}

}  // namespace

std::string describe_state_element(const FilterState& s, int i) {
  if (i < s.kinematic_dim()) {
    const int agent = i / 6, k = i % 6;
    const std::string who = agent == 0 ? "lead" : fmt::format("camera {}", agent - 1);
    return fmt::format("{} {} {}", who, k < 3 ? "position" : "velocity", kAxes[k % 3]);
  }
  for (int j = 0; j < s.num_cameras(); ++j)
    if (const int g = s.gimbal(j); g >= 0 && i >= g && i < g + 2)
      return fmt::format("camera {} gimbal angle about {}", j, kAxes[i - g]);
  if (const int a = s.common_acceleration(); a >= 0 && i >= a && i < a + 3)
    return fmt::format("common acceleration {}", kAxes[i - a]);
  for (const auto& lm : s.landmarks())
    if (i >= lm.offset && i < lm.offset + lm.dim())
      return fmt::format("landmark {} parameter {}", lm.id, i - lm.offset);
  return "an unassigned element";
}

void check_state(const FilterState& s, const std::string& stage) {
  const int n = s.dim();
  for (int i = 0; i < n; ++i) {
    if (!std::isfinite(s.x[i])) fail(s, stage, i, fmt::format("estimate {}", s.x[i]));
    const double v = s.P(i, i);
    if (!std::isfinite(v) || v < 0) fail(s, stage, i, fmt::format("variance {}", v));
  }
  for (int i = 0; i < s.agent_dim(); ++i)
    for (int j = 0; j < n; ++j) {
      const double c = s.P(i, j);
      if (!std::isfinite(c))
        fail(s, stage, i, fmt::format("covariance {} with {}", c, describe_state_element(s, j)));
      if (c * c > s.P(i, i) * s.P(j, j) * (1 + 1e-6) + 1e-300)
        fail(s, stage, i, fmt::format("covariance {} with {} beyond the variances' bound {} (P is "
                                      "no longer positive semi-definite)",
                                      c, describe_state_element(s, j), std::sqrt(s.P(i, i) * s.P(j, j))));
    }
}

void check_covariance(const FilterState& s, const std::string& stage) {
  // Each pair (i, j), i >= j, once, in tiles: P(j, i) runs along a row, and a row of a
  // column-major P of thousands of states misses the cache at every element.
  const int n = s.dim();
  constexpr int kTile = 64;
  for (int j0 = 0; j0 < n; j0 += kTile)
    for (int i0 = j0; i0 < n; i0 += kTile)
      for (int j = j0; j < std::min(j0 + kTile, n); ++j)
        for (int i = std::max(i0, j); i < std::min(i0 + kTile, n); ++i) {
          const double a = s.P(i, j), b = s.P(j, i);
          if (!std::isfinite(a) || !std::isfinite(b))
            fail(s, stage, i, fmt::format("covariance {} with {}", std::isfinite(a) ? b : a, describe_state_element(s, j)));
          if (std::abs(a - b) > 1e-9 * (std::abs(a) + std::abs(b)) + 1e-300)
            fail(s, stage, i, fmt::format("covariance with {} not symmetric ({} against {})",
                                          describe_state_element(s, j), a, b));
        }
  const int k = s.agent_dim();
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(s.P.topLeftCorner(k, k));
  const Eigen::VectorXd d = ldlt.vectorD();
  const double scale = s.P.diagonal().head(k).cwiseAbs().maxCoeff();
  for (int i = 0; i < k; ++i)
    if (!(d[i] >= -1e-9 * scale))
      fail(s, stage, i, fmt::format("pivot {} of the agents' covariance (not positive semi-definite)", d[i]));
}

void check_measurement(const Measurement& m, const std::string& what) {
  if (m.z.allFinite() && m.h.allFinite() && m.R.allFinite()) return;
  throw NumericalFailure(fmt::format("numerical failure: {} is not finite (observed [{}], predicted [{}])",
                                     what, fmt::join(m.z.data(), m.z.data() + m.z.size(), ", "),
                                     fmt::join(m.h.data(), m.h.data() + m.h.size(), ", ")));
}

}  // namespace wingman::slam
