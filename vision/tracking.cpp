// Gated descriptor tracking of map landmarks (see tracking.hpp).
#include "vision/tracking.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>

#include "geometry/bounds_check.hpp"

namespace wingman::vision {

void TrackingSettings::validate() const {
  geometry::check_bounds(*this, "tracking settings");
  // The limit of the one field no scenario key sets:
  if (duplicate_radius_px < 0)
    throw std::invalid_argument("tracking settings: duplicate_radius_px must be >= 0, got " +
                                std::to_string(duplicate_radius_px));
}

double default_tracking_distance(const cv::Mat& descriptors) {
  if (descriptors.type() == CV_8U) return 0.15 * 8.0 * descriptors.cols;
  return default_max_descriptor_distance(descriptors);
}

Eigen::Vector2d gate_half_extent(const Eigen::Matrix2d& S, const TrackingSettings& cfg) {
  // Bounding box of the ellipse r^T S^-1 r <= g: half-widths sqrt(g S_ii).
  Eigen::Vector2d half(std::sqrt(cfg.gate_d2 * S(0, 0)), std::sqrt(cfg.gate_d2 * S(1, 1)));
  if (cfg.max_search_radius_px > 0) half = half.cwiseMin(cfg.max_search_radius_px);
  return half;
}

TrackingResult track_landmarks(const std::vector<LandmarkPrediction>& predictions,
                               const Features& frame, const DescriptorStore& store,
                               const TrackingSettings& cfg) {
  cfg.validate();
  TrackingResult res;
  const int n = frame.size();
  res.keypoint_used.assign(n, false);
  if (n == 0) return res;
  const double max_dist = cfg.max_distance > 0 ? cfg.max_distance : default_tracking_distance(frame.descriptors);

  // Keypoints sorted by u, so each gate scans only its column band.
  std::vector<int> by_u(n);
  std::iota(by_u.begin(), by_u.end(), 0);
  std::sort(by_u.begin(), by_u.end(),
            [&](int a, int b) { return frame.keypoints[a].pt.x < frame.keypoints[b].pt.x; });
  std::vector<float> us(n);
  for (int k = 0; k < n; ++k) us[k] = frame.keypoints[by_u[k]].pt.x;

  std::vector<TrackCandidate> proposals;
  for (const auto& p : predictions) {
    if (!store.contains(p.id)) {
      ++res.no_descriptor;
      continue;
    }
    ++res.searched;
    Eigen::LLT<Eigen::Matrix2d> llt(p.S);
    if (llt.info() != Eigen::Success || !p.uv.allFinite()) {
      ++res.empty_gate;
      continue;
    }
    const Eigen::Matrix2d Sinv = llt.solve(Eigen::Matrix2d::Identity());
    const Eigen::Vector2d half = gate_half_extent(p.S, cfg);
    const double hu = half.x(), hv = half.y();
    const auto lo = std::lower_bound(us.begin(), us.end(), static_cast<float>(p.uv.x() - hu));
    const auto hi = std::upper_bound(us.begin(), us.end(), static_cast<float>(p.uv.x() + hu));

    struct Hit { int k; double dist, d2; };
    std::vector<Hit> hits;
    for (auto it = lo; it != hi; ++it) {
      const int k = by_u[it - us.begin()];
      const Eigen::Vector2d r = frame.pixel(k) - p.uv;
      if (std::abs(r.y()) > hv) continue;
      if (cfg.max_search_radius_px > 0 && r.norm() > cfg.max_search_radius_px) continue;
      const double d2 = r.dot(Sinv * r);
      if (d2 > cfg.gate_d2) continue;
      hits.push_back({k, store.distance(p.id, frame.descriptors.row(k), frame.norm, cfg.match_latest_descriptor), d2});
    }
    if (hits.empty()) {
      ++res.empty_gate;
      continue;
    }
    const auto best = std::min_element(hits.begin(), hits.end(), [](const Hit& a, const Hit& b) {
      return a.dist < b.dist || (a.dist == b.dist && a.d2 < b.d2);
    });
    if (best->dist > max_dist) {
      ++res.too_far;
      continue;
    }
    double second = std::numeric_limits<double>::infinity();
    for (const auto& h : hits) {
      if (&h == &*best) continue;
      if ((frame.pixel(h.k) - frame.pixel(best->k)).norm() <= cfg.duplicate_radius_px) continue;
      second = std::min(second, h.dist);
    }
    if (!(best->dist < cfg.ratio * second)) {
      ++res.ambiguous;
      continue;
    }
    proposals.push_back({p.id, frame.pixel(best->k), best->k, best->dist, best->d2});
  }

  // One landmark per keypoint: the smallest descriptor distance wins, then the smallest d^2.
  std::sort(proposals.begin(), proposals.end(), [](const TrackCandidate& a, const TrackCandidate& b) {
    if (a.distance != b.distance) return a.distance < b.distance;
    if (a.d2 != b.d2) return a.d2 < b.d2;
    return a.id < b.id;
  });
  for (const auto& c : proposals) {
    if (res.keypoint_used[c.keypoint]) {
      ++res.lost_conflict;
      continue;
    }
    res.keypoint_used[c.keypoint] = true;
    res.candidates.push_back(c);
  }
  std::sort(res.candidates.begin(), res.candidates.end(),
            [](const TrackCandidate& a, const TrackCandidate& b) { return a.id < b.id; });
  return res;
}

std::vector<int> free_keypoints(const Features& frame, const std::vector<bool>& keypoint_used,
                                const std::vector<LandmarkPrediction>& predictions,
                                double min_separation_px) {
  if (!keypoint_used.empty() && static_cast<int>(keypoint_used.size()) != frame.size())
    throw std::invalid_argument("free_keypoints: keypoint_used has " +
                                std::to_string(keypoint_used.size()) + " entries for " +
                                std::to_string(frame.size()) + " keypoints");
  std::vector<int> out;
  const double r2 = min_separation_px * min_separation_px;
  for (int k = 0; k < frame.size(); ++k) {
    if (!keypoint_used.empty() && keypoint_used[k]) continue;
    const Eigen::Vector2d uv = frame.pixel(k);
    const bool near = std::any_of(predictions.begin(), predictions.end(),
                                  [&](const LandmarkPrediction& p) { return (p.uv - uv).squaredNorm() < r2; });
    if (!near) out.push_back(k);
  }
  return out;
}

}  // namespace wingman::vision
