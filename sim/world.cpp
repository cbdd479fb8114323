#include "sim/world.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "sim/rng.hpp"
#include "sim/sun.hpp"
#include "sim/scenario.hpp"
#include "sim/truth.hpp"

namespace wingman::sim {

double lead_reference_height(const WorldSpec& w) { return w.lead.height + kLeadCueLift; }

TerrainModel::TerrainModel(const Scenario& scn, const OpenLoopTruth& truth)
    : spec_(scn.world.terrain), follow_(scn.world.lead.kind == LeadModelSpec::Kind::Ground) {
  const Eigen::Vector4d box = truth.horizontal_extent();
  const Eigen::Vector2d centre(0.5 * (box(0) + box(2)), 0.5 * (box(1) + box(3)));
  double half = spec_.extent > 0 ? 0.5 * spec_.extent
                                 : 0.5 * std::max(box(2) - box(0), box(3) - box(1)) + spec_.margin;
  // Whole mesh cells, so vertices sit on a grid of `resolution`.
  half = std::ceil(half / spec_.resolution) * spec_.resolution;
  bounds_ = {centre.x() - half, centre.y() - half, centre.x() + half, centre.y() + half};

  // Relief: a sum of seeded plane waves with wavelengths from relief_scale down to a quarter of
  // it, amplitudes falling with wavelength; normalised so the peak is at most `relief`.
  auto rng = make_stream(scn.world.seed.resolve(scn.seed), "terrain");
  std::uniform_real_distribution<double> ang(0, 2 * M_PI);
  double total = 0;
  for (int i = 0; i < 8; ++i) {
    const double lambda = spec_.relief_scale / std::pow(1.22, i);
    const double dir = ang(rng);
    const double k = 2 * M_PI / lambda;
    const double amp = lambda / spec_.relief_scale;
    waves_.push_back({k * std::cos(dir), k * std::sin(dir), ang(rng), amp});
    total += amp;
  }
  for (auto& w : waves_) w.amp *= spec_.relief / total;

  if (follow_) {
    const double h = lead_reference_height(scn.world);
    // Every 0.1 s: the nearest sample is then within a few cm of the nearest path point.
    const int n = std::max(1, static_cast<int>(std::ceil(scn.duration / 0.1)));  // duration may be 0
    for (int k = 0; k <= n; ++k) {
      const Eigen::Vector3d p = truth.lead(k * scn.duration / n).position;
      path_.emplace_back(p.x(), p.y(), p.z() - h);
    }
  }
}

double TerrainModel::relief(double x, double y) const {
  double z = spec_.mean_height;
  for (const auto& w : waves_) z += w.amp * std::sin(w.kx * x + w.ky * y + w.phase);
  return z;
}

double TerrainModel::distance_to_path(double x, double y, double* path_ground) const {
  double best = std::numeric_limits<double>::infinity();
  double ground = 0;
  for (const auto& p : path_) {
    const double d2 = (p.x() - x) * (p.x() - x) + (p.y() - y) * (p.y() - y);
    if (d2 < best) {
      best = d2;
      ground = p.z();
    }
  }
  if (path_ground) *path_ground = ground;
  return std::sqrt(best);
}

double TerrainModel::height(double x, double y) const {
  const double base = relief(x, y);
  if (!follow_) return base;
  double road = 0;
  const double d = distance_to_path(x, y, &road);
  if (d <= spec_.road_half_width) return road;
  // Around a ground lead the land follows its road (which rises and falls with the lead) plus
  // the relief, so the road is neither a trench nor a dyke.
  const double s = std::min(1.0, (d - spec_.road_half_width) / spec_.road_blend);
  const double w = s * s * (3 - 2 * s);  // smoothstep
  return road + w * (base - spec_.mean_height);
}

Eigen::Vector3d TerrainModel::normal(double x, double y) const {
  const double e = 0.25;
  const double dx = (height(x + e, y) - height(x - e, y)) / (2 * e);
  const double dy = (height(x, y + e) - height(x, y - e)) / (2 * e);
  return Eigen::Vector3d(-dx, -dy, 1).normalized();
}

std::vector<WorldObject> scatter_objects(const Scenario& scn, const TerrainModel& terrain) {
  const ObjectsSpec& spec = scn.world.objects;
  const Eigen::Vector4d& b = terrain.bounds();
  const double area_ha = (b(2) - b(0)) * (b(3) - b(1)) / 1e4;
  auto rng = make_stream(scn.world.seed.resolve(scn.seed), "world_objects");
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<WorldObject> out;
  auto place = [&](WorldObject::Type type, double per_ha) {
    const int n = static_cast<int>(std::round(per_ha * area_ha));
    for (int i = 0; i < n; ++i) {
      WorldObject o;
      o.type = type;
      const double x = b(0) + u(rng) * (b(2) - b(0)), y = b(1) + u(rng) * (b(3) - b(1));
      o.yaw = u(rng) * 2 * M_PI;
      o.seed = static_cast<std::uint32_t>(rng());
      double footprint = 0;
      switch (type) {
        case WorldObject::Type::Boulder: {
          const double r = 0.4 + 1.4 * u(rng);
          o.size = {2 * r, 2 * r * (0.6 + 0.4 * u(rng)), r * (0.6 + 0.6 * u(rng))};
          const double g = 0.45 + 0.25 * u(rng);
          o.colour = {g, g * 0.97, g * 0.92};
          footprint = r;
          break;
        }
        case WorldObject::Type::Tree: {
          const double h = 3 + 3 * u(rng);
          o.size = {h * 0.45, h * 0.45, h};
          o.colour = {0.18 + 0.1 * u(rng), 0.38 + 0.15 * u(rng), 0.15 + 0.08 * u(rng)};
          footprint = o.size.x() / 2;
          break;
        }
        case WorldObject::Type::Building: {
          o.size = {6 + 8 * u(rng), 5 + 6 * u(rng), 2.5 + 2.5 * u(rng)};
          const double g = 0.6 + 0.3 * u(rng);
          o.colour = {g, g * (0.85 + 0.1 * u(rng)), g * (0.75 + 0.15 * u(rng))};
          footprint = 0.5 * o.size.head<2>().norm();
          break;
        }
      }
      if (terrain.distance_to_path(x, y) < spec.clearance + footprint &&
          scn.world.lead.kind == LeadModelSpec::Kind::Ground)
        continue;
      // Sit on the lowest corner so nothing floats on a slope.
      double z = terrain.height(x, y);
      for (double sx : {-1.0, 1.0})
        for (double sy : {-1.0, 1.0})
          z = std::min(z, terrain.height(x + sx * footprint * 0.7, y + sy * footprint * 0.7));
      o.position = {x, y, z};
      out.push_back(o);
    }
  };
  place(WorldObject::Type::Building, spec.buildings);
  place(WorldObject::Type::Tree, spec.trees);
  place(WorldObject::Type::Boulder, spec.boulders);
  return out;
}

WorldDescription describe_world(const Scenario& scn) {
  const OpenLoopTruth truth(scn);
  TerrainModel terrain(scn, truth);
  auto objects = scatter_objects(scn, terrain);
  return {scn.world, std::move(terrain), std::move(objects), scn.source_path, scn.world.seed.resolve(scn.seed)};
}

double lead_heading(const Truth& truth, double t) {
  const KinematicState k = truth.lead(t);
  Eigen::Vector3d v = k.velocity;
  if (v.head<2>().norm() < 1e-6) v = truth.lead(t + 0.1).position - k.position;
  return std::atan2(v.y(), v.x());
}

LeadPose lead_pose(const Truth& truth, double t, const WorldSpec& world) {
  LeadPose p;
  p.position = truth.lead(t).position;
  p.yaw = lead_heading(truth, t) + world.lead.yaw_offset;
  return p;
}

std::vector<LeadPose> uav_body_poses(const Truth& truth, double t, const WorldSpec& world) {
  std::vector<LeadPose> out;
  if (!world.uav_bodies.enabled) return out;
  // The model's bottom centre `above` over the camera, which hangs under the body.
  for (int j = 0; j < static_cast<int>(truth.scenario().uavs.size()); ++j)
    out.push_back({truth.camera(j, t).position + Eigen::Vector3d(0, 0, world.uav_bodies.above), truth.uav_yaw(j, t)});
  return out;
}

}  // namespace wingman::sim

namespace wingman::sim {

Eigen::Vector3d LightSpec::travel() const {
  if (sun.enabled) return -sun_vector(sun.latitude, sun.longitude, sun.day_of_year, sun.time_utc);
  return direction.normalized();
}

}  // namespace wingman::sim
