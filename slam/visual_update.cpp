#include "slam/visual_update.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <utility>

#include "geometry/chi2.hpp"
#include "slam/ekf_update.hpp"

namespace wingman::slam {

namespace {
double gate_threshold(double probability, int dof) {
  // Cached: the gates are asked for thousands of times with the same arguments.
  static thread_local double last_p = -1, last_thr = 0;
  static thread_local int last_dof = -1;
  if (probability != last_p || dof != last_dof) {
    last_p = probability;
    last_dof = dof;
    last_thr = geometry::chi2_quantile(probability, dof);
  }
  return last_thr;
}

// The compatible candidates update the pixel offsets of their cameras: those not yet states
// become states (exact: until now they were independent noise), and the measurements are built
// again on the grown state.
void state_offsets_of(FilterState& s, const std::vector<CameraRig>& cams,
                      const std::vector<Correspondence>& candidates, const std::vector<int>& compatible,
                      double sigma_px, std::vector<Measurement>& meas) {
  std::vector<std::pair<LandmarkId, int>> unstated;
  for (int i : compatible)
    if (s.find(candidates[i].id)->unstated_offset_variance(candidates[i].cam) > 0)
      unstated.emplace_back(candidates[i].id, candidates[i].cam);
  if (unstated.empty()) return;
  s.state_pixel_offsets(unstated);
  for (int i : compatible) {
    const auto& c = candidates[i];
    auto m = landmark_measurement(s, *s.find(c.id), c.cam, cams[c.cam], c.uv, sigma_px);
    if (!m) throw std::logic_error("state_offsets_of: a compatible measurement no longer projects");
    meas[i] = std::move(*m);
  }
}
}  // namespace

VisualUpdateResult update_with_correspondences(FilterState& s, const std::vector<CameraRig>& cams,
                                               const std::vector<Correspondence>& candidates,
                                               const GatingSettings& cfg, double sigma_px,
                                               std::mt19937_64& rng,
                                               const std::vector<Measurement>& companions) {
  VisualUpdateResult res;
  std::vector<bool>* companion_accepted = &res.companion_accepted;
  std::vector<const Measurement*> extra;
  companion_accepted->assign(companions.size(), false);
  for (size_t i = 0; i < companions.size(); ++i) {
    const auto& m = companions[i];
    if (mahalanobis_squared(m, innovation_covariance(s, m)) > gate_threshold(cfg.probability, m.dim()))
      continue;
    extra.push_back(&m);
    (*companion_accepted)[i] = true;
  }
  res.accepted.assign(candidates.size(), false);
  const double gate2 = gate_threshold(cfg.probability, 2);

  // Individual compatibility at the prior.
  std::vector<int> compatible;
  std::vector<Measurement> meas(candidates.size());
  for (size_t i = 0; i < candidates.size(); ++i) {
    const auto& c = candidates[i];
    const LandmarkSlot* lm = s.find(c.id);
    if (!lm) continue;
    auto m = landmark_measurement(s, *lm, c.cam, cams[c.cam], c.uv, sigma_px);
    if (!m) continue;
    if (mahalanobis_squared(*m, innovation_covariance(s, *m)) > gate2) continue;
    meas[i] = std::move(*m);
    compatible.push_back(static_cast<int>(i));
  }
  res.compatible = static_cast<int>(compatible.size());
  state_offsets_of(s, cams, candidates, compatible, sigma_px, meas);
  // One joint update of the companions with the chosen candidates; on failure nothing is accepted.
  auto joint_update = [&](const std::vector<int>& chosen) {
    std::vector<const Measurement*> batch = extra;
    for (int i : chosen) batch.push_back(&meas[i]);
    if (ekf_update(s, batch)) {
      for (int i : chosen) res.accepted[i] = true;
    } else {
      companion_accepted->assign(companions.size(), false);
    }
  };
  if (compatible.empty() || !cfg.one_point_ransac) {
    joint_update(compatible);
    return res;
  }

  // 1-point RANSAC: each hypothesis is the state corrected by one match alone.
  std::vector<int> best;
  std::uniform_int_distribution<size_t> pick(0, compatible.size() - 1);
  const double inlier2 = cfg.ransac_inlier_px * cfg.ransac_inlier_px;
  int needed = cfg.ransac_max_hypotheses;
  for (int h = 0; h < needed && h < cfg.ransac_max_hypotheses; ++h) {
    const int i = compatible[pick(rng)];
    const Eigen::VectorXd x_h = s.x + single_measurement_correction(s, meas[i]);
    std::vector<int> inliers;
    for (int j : compatible) {
      const auto& c = candidates[j];
      auto uv = predict_landmark_pixel(s, x_h, *s.find(c.id), c.cam, cams[c.cam]);
      if (uv && (*uv - c.uv).squaredNorm() < inlier2) inliers.push_back(j);
    }
    ++res.hypotheses;
    if (inliers.size() > best.size()) {
      best = std::move(inliers);
      const double eps = static_cast<double>(best.size()) / compatible.size();
      needed = eps >= 1.0 ? 1
                          : static_cast<int>(std::ceil(std::log(1 - cfg.ransac_success_probability) /
                                                       std::log(1 - eps)));
    }
  }
  res.low_innovation_inliers = static_cast<int>(best.size());
  joint_update(best);

  // Rescue the high-innovation inliers with the corrected state and covariance.
  std::vector<Measurement> rescued;
  std::vector<int> rescued_idx;
  for (int i : compatible) {
    if (res.accepted[i]) continue;
    const auto& c = candidates[i];
    auto m = landmark_measurement(s, *s.find(c.id), c.cam, cams[c.cam], c.uv, sigma_px);
    if (!m || mahalanobis_squared(*m, innovation_covariance(s, *m)) > gate2) continue;
    rescued.push_back(std::move(*m));
    rescued_idx.push_back(i);
  }
  if (!rescued.empty()) {
    std::vector<const Measurement*> batch;
    for (const auto& m : rescued) batch.push_back(&m);
    if (ekf_update(s, batch)) {
      for (int i : rescued_idx) res.accepted[i] = true;
      res.rescued = static_cast<int>(rescued_idx.size());
    }
  }
  return res;
}

std::vector<bool> update_with_gated_measurements(FilterState& s, const std::vector<Measurement>& ms,
                                                 double gate_probability) {
  std::vector<bool> ok(ms.size(), false);
  std::vector<const Measurement*> batch;
  for (size_t i = 0; i < ms.size(); ++i) {
    const double d2 = mahalanobis_squared(ms[i], innovation_covariance(s, ms[i]));
    if (d2 <= gate_threshold(gate_probability, ms[i].dim())) {
      ok[i] = true;
      batch.push_back(&ms[i]);
    }
  }
  if (!ekf_update(s, batch)) std::fill(ok.begin(), ok.end(), false);
  return ok;
}

}  // namespace wingman::slam
