// Correction with landmark correspondences: individual chi^2 compatibility, then 1-point RANSAC
// for EKF (Civera, Grasa, Davison and Montiel, JFR 2010, Alg. 1): hypotheses from single
// matches pick the low-innovation inliers, which update the filter; the remaining compatible
// matches are rescued if they pass the chi^2 gate after that update.
#pragma once

#include <Eigen/Core>
#include <random>
#include <vector>

#include "slam/measurement_models.hpp"
#include "slam/settings.hpp"
#include "slam/state.hpp"

namespace wingman::slam {

// One candidate correspondence: landmark `id` seen at pixel `uv` by camera `cam`.
struct Correspondence {
  int cam = 0;
  LandmarkId id = -1;
  Eigen::Vector2d uv = Eigen::Vector2d::Zero();
};


struct VisualUpdateResult {
  std::vector<bool> accepted;  // per candidate
  int compatible = 0;          // passed the individual gate
  int hypotheses = 0;
  int low_innovation_inliers = 0;
  int rescued = 0;
  std::vector<bool> companion_accepted;
};

// `companions` (e.g. lead projections of the same frames) are gated on their own and join the
// first joint update, so the gimbal noise they share with the landmarks is modelled jointly.
VisualUpdateResult update_with_correspondences(FilterState& s, const std::vector<CameraRig>& cams,
                                               const std::vector<Correspondence>& candidates,
                                               const GatingSettings& gating, double sigma_px,
                                               std::mt19937_64& rng,
                                               const std::vector<Measurement>& companions = {});

// Gated batch update with other measurements (lead projection, GPS, altimeter, range): each is
// tested on its own against the chi^2 gate of its dimension; the compatible ones update jointly.
std::vector<bool> update_with_gated_measurements(FilterState& s, const std::vector<Measurement>& ms,
                                                 double gate_probability);

}  // namespace wingman::slam
