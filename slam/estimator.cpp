#include "slam/estimator.hpp"

#include <fmt/core.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <stdexcept>

#include "slam/ekf_update.hpp"
#include "slam/health.hpp"
#include "slam/motion_model.hpp"

namespace wingman::slam {

Estimator::Estimator(std::vector<CameraRig> cameras, const AgentInit& lead,
                     const std::vector<AgentInit>& camera_init, const EstimatorSettings& settings,
                     std::uint64_t seed)
    : cams_(std::move(cameras)),
      cfg_(settings),
      s_(static_cast<int>(cams_.size()),
         settings.measurement_noise.orientation_time_constant > 0 &&
             std::any_of(cams_.begin(), cams_.end(),
                         [](const CameraRig& c) { return c.orientation_sigma > 0; }),
         settings.process_noise.common_acceleration_state()),
      rng_(seed) {
  if (camera_init.size() != cams_.size())
    throw std::invalid_argument("Estimator: one initial state per camera");
  const double sp2 = cfg_.initial_sigma.position * cfg_.initial_sigma.position;
  const double sv2 = cfg_.initial_sigma.velocity * cfg_.initial_sigma.velocity;
  auto set = [&](int pos, const AgentInit& a) {
    s_.x.segment<3>(pos) = a.position;
    s_.x.segment<3>(pos + 3) = a.velocity;
    s_.P.block<3, 3>(pos, pos).diagonal().setConstant(sp2);
    s_.P.block<3, 3>(pos + 3, pos + 3).diagonal().setConstant(sv2);
  };
  set(FilterState::lead_pos(), lead);
  for (size_t j = 0; j < cams_.size(); ++j) set(FilterState::cam_pos(static_cast<int>(j)), camera_init[j]);
  for (int j = 0; j < num_cameras(); ++j)
    if (const int g = s_.gimbal(j); g >= 0)
      s_.P.block<2, 2>(g, g).diagonal().setConstant(cams_[j].orientation_sigma * cams_[j].orientation_sigma);
  if (const int a = s_.common_acceleration(); a >= 0)
    s_.P.block<3, 3>(a, a).diagonal().setConstant(cfg_.process_noise.common_state_sigma *
                                                  cfg_.process_noise.common_state_sigma);
}

void Estimator::predict(double dt) {
  const ProcessNoiseSettings& q = cfg_.process_noise;
  predict_constant_velocity(s_, dt, q.accel_sigma_lead.value, q.accel_sigma_uav.value, q.accel_sigma_common.value);
  for (int j = 0; j < num_cameras(); ++j)
    predict_gimbal_error(s_, j, dt, cams_[j].orientation_sigma, cfg_.measurement_noise.orientation_time_constant);
  predict_common_acceleration(s_, dt, q.common_state_sigma, q.common_state_time_constant);
  check_state(s_, "the prediction");
}

std::vector<LandmarkPrediction> Estimator::predictions_in_view(int cam) const {
  std::vector<LandmarkPrediction> out;
  const CameraRig& rig = cams_[cam];
  for (const auto& lm : s_.landmarks()) {
    auto uv = predict_landmark_pixel(s_, s_.x, lm, cam, rig);
    if (!uv || !rig.model.in_image(*uv, cfg_.map.image_margin_px)) continue;
    auto m = landmark_measurement(s_, lm, cam, rig, *uv, cfg_.measurement_noise.pixel_sigma.value);
    if (!m) continue;
    out.push_back({lm.id, *uv, innovation_covariance(s_, *m)});
  }
  return out;
}

std::vector<LandmarkPrediction> Estimator::landmarks_in_view(int cam) {
  auto out = predictions_in_view(cam);
  for (const auto& p : out) tracks_[p.id].expected = true;
  return out;
}

VisualUpdateResult Estimator::update_visual(
    const std::vector<Correspondence>& candidates,
    const std::vector<std::pair<int, Eigen::Vector2d>>& lead_pixels) {
  std::vector<Measurement> lead;
  for (const auto& [cam, uv] : lead_pixels)
    if (auto m = lead_projection_measurement(s_, cam, cams_[cam], uv, cfg_.measurement_noise.lead_sigma()))
      lead.push_back(std::move(*m));
  for (const auto& m : lead) check_measurement(m, fmt::format("the lead's pixel in camera {}", m.camera));
  for (const auto& c : candidates)
    if (!c.uv.allFinite())
      throw NumericalFailure(fmt::format("numerical failure: the pixel of landmark {} in camera {} is not finite",
                                         c.id, c.cam));
  VisualUpdateResult r = update_with_correspondences(s_, cams_, candidates, cfg_.gating,
                                                     cfg_.measurement_noise.pixel_sigma.value, rng_, lead);
  for (size_t i = 0; i < candidates.size(); ++i)
    if (r.accepted[i]) tracks_[candidates[i].id].matched = true;
  check_state(s_, fmt::format("the visual update ({} landmark pixels, {} lead pixels)", candidates.size(),
                              lead.size()));
  return r;
}

SensorUpdateResult Estimator::update_sensors(const SensorBatch& b) {
  std::vector<Measurement> ms;
  if (b.gps) ms.push_back(gps_measurement(s_, *b.gps, cfg_.measurement_noise.gps_sigma));
  for (const auto& [cam, z] : b.altimeter)
    ms.push_back(altimeter_measurement(s_, cam, cams_[cam], z, cfg_.measurement_noise.altimeter_sigma));
  for (const auto& [cam, z] : b.range)
    ms.push_back(range_measurement(s_, cam, cams_[cam], z, cfg_.measurement_noise.range_sigma));
  SensorUpdateResult r;
  r.offered = static_cast<int>(ms.size());
  if (ms.empty()) return r;
  std::vector<std::string> names;
  if (b.gps) names.push_back("the GPS fix");
  for (const auto& [cam, z] : b.altimeter) names.push_back(fmt::format("camera {}'s altimeter", cam));
  for (const auto& [cam, z] : b.range) names.push_back(fmt::format("camera {}'s range", cam));
  for (std::size_t i = 0; i < ms.size(); ++i) check_measurement(ms[i], names[i]);
  const auto ok = update_with_gated_measurements(s_, ms, cfg_.gating.probability);
  r.accepted = static_cast<int>(std::count(ok.begin(), ok.end(), true));
  check_state(s_, fmt::format("the sensor update ({})", fmt::join(names, ", ")));
  return r;
}

bool Estimator::make_room() {
  if (num_landmarks() < cfg_.map.landmark_cap(num_cameras())) return true;
  // Oldest landmark not expected in any camera this step: it has left the view.
  for (const auto& lm : s_.landmarks()) {
    auto it = tracks_.find(lm.id);
    if (it == tracks_.end() || !it->second.expected) {
      forget(lm.id);
      return true;
    }
  }
  return false;
}

void Estimator::forget(LandmarkId id) {
  s_.remove_landmark(id);
  tracks_.erase(id);
  evicted_.push_back(id);
}

std::vector<InitOutcome> Estimator::initialise_from_matches(const std::vector<CrossMatch>& matches) {
  std::vector<InitOutcome> out;
  out.reserve(matches.size());
  for (const auto& m : matches)
    if (!m.uv_a.allFinite() || !m.uv_b.allFinite())
      throw NumericalFailure(fmt::format("numerical failure: a cross match's pixels in cameras {} and {} are "
                                         "not finite", m.cam_a, m.cam_b));
  for (const auto& m : matches) {
    if (!make_room()) {
      out.push_back({std::nullopt, "map full"});
      continue;
    }
    auto r = initialise_cooperative(s_, m.cam_a, cams_[m.cam_a], m.uv_a, m.cam_b, cams_[m.cam_b],
                                    m.uv_b, cfg_.initialisation, cfg_.measurement_noise);
    if (!r.id && r.rejected_because == kLowParallax && cfg_.initialisation.low_parallax_inverse_depth)
      r = initialise_cooperative_inverse_depth(s_, m.cam_a, cams_[m.cam_a], m.uv_a, m.cam_b,
                                               cams_[m.cam_b], m.uv_b, cfg_.initialisation,
                                               cfg_.measurement_noise,
                                               cfg_.gating.probability);
    if (r.id) tracks_[*r.id].matched = true;  // seen now: no miss on its first step
    out.push_back(std::move(r));
  }
  if (!matches.empty()) check_state(s_, "cooperative landmark initialisation");
  return out;
}

InitOutcome Estimator::initialise_from_pixel(int cam, const Eigen::Vector2d& uv) {
  if (!uv.allFinite())
    throw NumericalFailure(fmt::format("numerical failure: a new landmark's pixel in camera {} is not finite", cam));
  if (!make_room()) return {std::nullopt, "map full"};
  auto r = initialise_inverse_depth(s_, cam, cams_[cam], uv, cfg_.initialisation, cfg_.measurement_noise);
  if (r.id) tracks_[*r.id].matched = true;
  check_state(s_, fmt::format("a landmark's initialisation from camera {}", cam));
  return r;
}

std::vector<LandmarkId> Estimator::end_step() {
  std::vector<LandmarkId> drop;
  for (auto& [id, t] : tracks_) {
    if (t.expected && !t.matched) ++t.misses;
    if (t.matched) t.misses = 0;
    if (t.misses >= cfg_.map.max_misses) drop.push_back(id);
    t.expected = t.matched = false;
  }
  std::sort(drop.begin(), drop.end());
  for (LandmarkId id : drop) forget(id);
  for (int j = 0; j < num_cameras(); ++j) convert_linear_landmarks(s_, j, cfg_.initialisation.linearity_threshold);
  check_covariance(s_, "the step's map management");
  std::vector<LandmarkId> removed;
  removed.swap(evicted_);
  return removed;
}

const char* to_string(EstimatorMode m) {
  return m == EstimatorMode::SingleUav ? "single" : "multi";
}

std::optional<Eigen::Vector3d> Estimator::landmark_position(LandmarkId id) const {
  const LandmarkSlot* lm = s_.find(id);
  if (!lm) return std::nullopt;
  return s_.landmark_position(*lm);
}

}  // namespace wingman::slam
