#include "sim/budget.hpp"

#include <fmt/core.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>

#include "sim/truth.hpp"

namespace wingman::sim {
namespace {

// Bytes per unit (docs/reliability.md has the measurements): a step's records with one agent's
// share (smoke.yaml over 3e5 steps peaks at 0.91 GB), a synthetic landmark, a terrain vertex (CPU
// mesh and its GL copy), a pixel of a rendered frame (colour, depth, gray, GL buffers, the
// prefetched next frame).
constexpr double kStepBytes = 1000, kAgentStepBytes = 700, kLandmarkBytes = 96, kVertexBytes = 96,
                 kPixelBytes = 48;
// Wall time on 2 cores: a synthetic step of the paper scene (5 ms) and a rendered camera frame
// (render + detect + match, about twice the paper scene's 40 ms), both on the safe side.
constexpr double kSyntheticStepSeconds = 5e-3, kRenderedFrameSeconds = 0.08;

// The flight's horizontal bounding box, sampled at most 10 000 times (the analytic trajectory
// plus each agent's offset from the lead), so estimating never costs what it guards against.
Eigen::Vector4d sampled_extent(const Scenario& s, double& max_abs_z) {
  Eigen::Vector4d box(INFINITY, INFINITY, -INFINITY, -INFINITY);
  max_abs_z = 0;
  const int n = 10000;
  const Eigen::Vector3d origin = nominal_motion(s.lead.trajectory, 0).position;
  for (int k = 0; k <= n; ++k) {
    const Eigen::Vector3d p = nominal_motion(s.lead.trajectory, s.duration * k / n).position - origin;
    auto grow = [&](const Eigen::Vector3d& start) {
      box(0) = std::min(box(0), p.x() + start.x());
      box(1) = std::min(box(1), p.y() + start.y());
      box(2) = std::max(box(2), p.x() + start.x());
      box(3) = std::max(box(3), p.y() + start.y());
      max_abs_z = std::max(max_abs_z, std::abs(p.z() + start.z()));
    };
    grow(s.lead.initial_position);
    for (const auto& u : s.uavs) grow(u.initial_position);
  }
  if (s.control.enabled) {
    // Closed loop: the field covers a circle around the lead as wide as the farthest UAV may be
    // (ClosedLoopTruth::horizontal_extent): its initial offset or lambda_d, plus 10 m.
    double r = 0;
    for (const auto& u : s.uavs) r = std::max(r, (u.initial_position - s.lead.initial_position).head<2>().norm());
    for (const auto& c : s.control.uavs) r = std::max(r, c.lambda_d.head<2>().norm());
    box += Eigen::Vector4d(-r - 10, -r - 10, r + 10, r + 10);
  }
  return box;
}

}  // namespace

RunEstimate estimate_run(const Scenario& s) {
  RunEstimate e;
  e.steps = s.duration * s.rate;
  const double agents = 1.0 + static_cast<double>(s.uavs.size());
  const Eigen::Vector4d box = sampled_extent(s, e.max_abs_z_m);
  const double wx = box(2) - box(0), wy = box(3) - box(1);
  e.extent_m = std::max(wx, wy);
  const double m = s.field.margin;
  e.landmarks = s.field.density * (wx + 2 * m) * (wy + 2 * m);
  e.bytes = (e.steps + 1) * (kStepBytes + agents * kAgentStepBytes);
  e.seconds = e.steps * kSyntheticStepSeconds;
  if (s.measurements == MeasurementMode::Rendered) {
    const auto& t = s.world.terrain;
    const double side = t.extent > 0 ? t.extent : e.extent_m + 2 * t.margin;
    e.terrain_vertices = std::pow(side / t.resolution + 2, 2);
    for (const auto& u : s.uavs) e.pixels += double(u.camera.width) * u.camera.height;
    const double texture = double(s.world.texture.size) * s.world.texture.size * 4 * 4.0 / 3;
    e.bytes += e.terrain_vertices * kVertexBytes + e.pixels * kPixelBytes + texture +
               s.duration / 0.1 * 48;  // the terrain's samples of a ground lead's path
    e.seconds += e.steps * static_cast<double>(s.uavs.size()) * kRenderedFrameSeconds;
  } else {
    e.bytes += e.landmarks * kLandmarkBytes;
  }
  return e;
}

double memory_available() {
  const double pages = static_cast<double>(::sysconf(_SC_PHYS_PAGES));
  const double page = static_cast<double>(::sysconf(_SC_PAGE_SIZE));
  double bytes = pages > 0 && page > 0 ? pages * page : 8.0 * (1ull << 30);
  struct rlimit rl {};
  if (::getrlimit(RLIMIT_AS, &rl) == 0 && rl.rlim_cur != RLIM_INFINITY)
    bytes = std::min(bytes, static_cast<double>(rl.rlim_cur));
  return bytes * RunLimits::kMemoryFraction;
}

std::string bytes_text(double b) {
  if (!std::isfinite(b)) return fmt::format("{} bytes", b);
  if (b >= 1024.0 * 1024 * 1024 * 1024) return fmt::format("{:.3g} TiB", b / (1024.0 * 1024 * 1024 * 1024));
  if (b >= 1024.0 * 1024 * 1024) return fmt::format("{:.3g} GiB", b / (1024.0 * 1024 * 1024));
  return fmt::format("{:.3g} MiB", b / (1024.0 * 1024));
}

std::string duration_text(double s) {
  if (!std::isfinite(s)) return fmt::format("{} s", s);
  if (s >= 86400 * 365.0) return fmt::format("{:.3g} years", s / (86400 * 365.0));
  if (s >= 86400) return fmt::format("{:.3g} days", s / 86400);
  if (s >= 3600) return fmt::format("{:.3g} h", s / 3600);
  return fmt::format("{:.3g} min", s / 60);
}

}  // namespace wingman::sim
