#include "sim/synthetic_source.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "sim/rng.hpp"

namespace wingman::sim {

std::vector<Eigen::Vector3d> make_landmark_field(const Scenario& scn, const Truth& truth) {
  const Eigen::Vector4d box = truth.horizontal_extent();
  const double m = scn.field.margin;
  const double x0 = box(0) - m, y0 = box(1) - m, x1 = box(2) + m, y1 = box(3) + m;
  const auto n = static_cast<std::size_t>(std::llround(scn.field.density * (x1 - x0) * (y1 - y0)));
  auto rng = make_stream(scn.seed, "landmark_field");
  std::uniform_real_distribution<double> ux(x0, x1), uy(y0, y1),
      uz(-0.5 * scn.field.height_spread, 0.5 * scn.field.height_spread);
  std::vector<Eigen::Vector3d> pts;
  pts.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double x = ux(rng), y = uy(rng), z = scn.field.ground_height + uz(rng);
    pts.emplace_back(x, y, z);
  }
  return pts;
}

SyntheticSource::SyntheticSource(const Scenario& scn, const Truth& truth)
    : scn_(scn),
      truth_(truth),
      field_(make_landmark_field(scn, truth)),
      pixel_rng_(make_stream(scn.seed, "pixel_noise")),
      outlier_rng_(make_stream(scn.seed, "outliers")),
      select_rng_(make_stream(scn.seed, "selection")),
      gps_rng_(make_stream(scn.seed, "gps")),
      alt_rng_(make_stream(scn.seed, "altimeter")),
      range_rng_(make_stream(scn.seed, "range")),
      ahrs_rng_(make_stream(scn.seed, "ahrs")),
      injected_(scn.uavs.size() + 1, 0) {}

void SyntheticSource::bind(std::int64_t landmark, std::size_t point) {
  bound_[landmark] = point;
  bound_points_.insert(point);
}

void SyntheticSource::unbind(std::int64_t landmark) {
  auto it = bound_.find(landmark);
  if (it == bound_.end()) return;
  bound_points_.erase(it->second);
  bound_.erase(it);
}

std::optional<std::size_t> SyntheticSource::point_of(std::int64_t landmark) const {
  auto it = bound_.find(landmark);
  if (it == bound_.end()) return std::nullopt;
  return it->second;
}

std::optional<Eigen::Vector2d> SyntheticSource::true_pixel(int uav, double t,
                                                           const Eigen::Vector3d& p) const {
  const auto cam = scn_.uavs[uav].camera.camera();
  const Eigen::Vector3d p_C = truth_.camera_R_CW(uav, t) * (p - truth_.camera(uav, t).position);
  auto uv = cam.project(p_C);
  if (!uv || !cam.in_image(*uv)) return std::nullopt;
  return uv;
}

Eigen::Vector2d SyntheticSource::noisy(const Eigen::Vector2d& uv) {
  std::normal_distribution<double> n(0.0, scn_.noise.pixel_sigma);
  return {uv.x() + n(pixel_rng_), uv.y() + n(pixel_rng_)};
}

Eigen::Vector2d SyntheticSource::pixel_bias(int uav, std::size_t point) const {
  if (scn_.noise.pixel_bias_sigma <= 0) return Eigen::Vector2d::Zero();
  // Its own stream per camera and point, so the offset is the same whenever and however often
  // the point is observed, and the white noise's stream is untouched.
  auto rng = make_stream(scn_.seed ^ splitmix64(static_cast<std::uint64_t>(point)),
                         "pixel_bias/" + std::to_string(uav));
  std::normal_distribution<double> n(0.0, scn_.noise.pixel_bias_sigma);
  const double bx = n(rng);
  return {bx, n(rng)};
}

Eigen::Vector2d SyntheticSource::noisy(const Eigen::Vector2d& uv, int uav, std::size_t point) {
  return noisy(uv) + pixel_bias(uav, point);
}

Eigen::Vector2d SyntheticSource::outlier(const Eigen::Vector2d& uv) {
  std::uniform_real_distribution<double> mag(0.0, scn_.noise.outlier_max_px), ang(0.0, 2 * M_PI);
  const double e = mag(outlier_rng_), a = ang(outlier_rng_);
  return {uv.x() + e * std::cos(a), uv.y() + e * std::sin(a)};
}

std::vector<PixelObservation> SyntheticSource::observe_landmarks(
    int uav, double t, const std::vector<std::int64_t>& predicted) {
  std::vector<PixelObservation> out;
  std::bernoulli_distribution is_outlier(scn_.noise.outlier_fraction);
  for (std::int64_t id : predicted) {
    auto pt = point_of(id);
    if (!pt) continue;
    auto uv = true_pixel(uav, t, field_[*pt]);
    if (!uv) continue;
    PixelObservation o;
    o.landmark = id;
    o.point = *pt;
    o.true_uv = *uv;
    o.injected_outlier = is_outlier(outlier_rng_);
    o.uv = o.injected_outlier ? outlier(*uv) : noisy(*uv, uav, *pt);
    if (o.injected_outlier) ++injected_[uav];
    out.push_back(o);
  }
  return out;
}

std::vector<std::size_t> SyntheticSource::unmapped_in_view(int uav, double t) const {
  std::vector<std::size_t> v;
  for (std::size_t i = 0; i < field_.size(); ++i)
    if (!bound_points_.count(i) && true_pixel(uav, t, field_[i])) v.push_back(i);
  return v;
}

std::vector<std::size_t> SyntheticSource::spread(int uav, double t, std::vector<std::size_t> cand,
                                                 int count) {
  // A 4 x 4 grid over the image: prefer candidates in cells holding the fewest mapped points, as
  // a feature detector with bucketing would.
  constexpr int kGrid = 4;
  const auto& cs = scn_.uavs[uav].camera;
  auto cell = [&](const Eigen::Vector2d& uv) {
    const int cx = std::clamp(static_cast<int>(uv.x() / cs.width * kGrid), 0, kGrid - 1);
    const int cy = std::clamp(static_cast<int>(uv.y() / cs.height * kGrid), 0, kGrid - 1);
    return cy * kGrid + cx;
  };
  std::vector<int> occupancy(kGrid * kGrid, 0);
  for (std::size_t p : bound_points_)
    if (auto uv = true_pixel(uav, t, field_[p])) ++occupancy[cell(*uv)];
  std::shuffle(cand.begin(), cand.end(), select_rng_);
  std::vector<std::size_t> picked;
  while (static_cast<int>(picked.size()) < count && !cand.empty()) {
    // Take one candidate from the emptiest cell, then update that cell's count.
    std::size_t best = 0;
    int best_occ = 1 << 30;
    for (std::size_t i = 0; i < cand.size(); ++i) {
      const int occ = occupancy[cell(*true_pixel(uav, t, field_[cand[i]]))];
      if (occ < best_occ) {
        best_occ = occ;
        best = i;
      }
    }
    picked.push_back(cand[best]);
    ++occupancy[cell(*true_pixel(uav, t, field_[cand[best]]))];
    cand.erase(cand.begin() + static_cast<long>(best));
  }
  return picked;
}

std::vector<PointPair> SyntheticSource::cross_matches(int uav_a, int uav_b, double t, int count) {
  std::vector<std::size_t> both;
  for (std::size_t i : unmapped_in_view(uav_a, t))
    if (true_pixel(uav_b, t, field_[i])) both.push_back(i);
  std::bernoulli_distribution is_outlier(scn_.noise.cooperative_outlier_fraction);
  std::vector<PointPair> out;
  for (std::size_t i : spread(uav_a, t, std::move(both), count)) {
    PointPair p;
    p.point = i;
    p.uv_a = noisy(*true_pixel(uav_a, t, field_[i]), uav_a, i);
    const Eigen::Vector2d true_b = *true_pixel(uav_b, t, field_[i]);
    p.injected_outlier = is_outlier(outlier_rng_);
    p.uv_b = p.injected_outlier ? outlier(true_b) : noisy(true_b, uav_b, i);
    if (p.injected_outlier) ++injected_.back();
    out.push_back(p);
  }
  return out;
}

std::vector<PixelObservation> SyntheticSource::new_points(int uav, double t, int count) {
  std::vector<PixelObservation> out;
  for (std::size_t i : spread(uav, t, unmapped_in_view(uav, t), count)) {
    PixelObservation o;
    o.point = i;
    o.true_uv = *true_pixel(uav, t, field_[i]);
    o.uv = noisy(o.true_uv, uav, i);
    out.push_back(o);
  }
  return out;
}

std::optional<Eigen::Vector2d> SyntheticSource::lead_pixel(int uav, double t) {
  auto uv = true_pixel(uav, t, truth_.lead(t).position);
  if (!uv) return std::nullopt;
  return noisy(*uv);
}

Eigen::Vector3d SyntheticSource::gps(double t) {
  std::normal_distribution<double> n(0.0, scn_.noise.gps_sigma);
  return truth_.lead(t).position + Eigen::Vector3d(n(gps_rng_), n(gps_rng_), n(gps_rng_));
}

double SyntheticSource::altimeter(int uav, double t) {
  std::normal_distribution<double> n(0.0, scn_.noise.altimeter_sigma);
  return truth_.uav(uav, t).position.z() + n(alt_rng_);
}

double SyntheticSource::range(int uav, double t) {
  std::normal_distribution<double> n(0.0, scn_.noise.range_sigma);
  return (truth_.lead(t).position - truth_.uav(uav, t).position).norm() + n(range_rng_);
}

double SyntheticSource::ahrs_yaw(int uav, double t) {
  std::normal_distribution<double> n(0.0, scn_.noise.ahrs_yaw_sigma);
  double a = std::remainder(truth_.uav_yaw(uav, t) + n(ahrs_rng_), 2 * M_PI);
  return a <= -M_PI ? a + 2 * M_PI : a;
}

}  // namespace wingman::sim
