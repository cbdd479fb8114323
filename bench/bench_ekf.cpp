// One EKF step of the multi-UAV filter against the number of landmarks in the state, using only
// slam/: predict(0.1) -> landmarks_in_view for both cameras -> update_visual (1-point RANSAC and
// gating) with noisy pixels of at most 40 visible landmarks per camera, 5 % of them outliers, as a
// frontend would give -> cooperative initialisation of 2 new landmarks -> end_step().
//
// Setup (not timed): two nadir cameras at the paper's start positions, hovering; N landmarks on a
// 100 m x 100 m ground grid beneath them, about half in view of each camera and the rest out of
// view (initialised through initialise_from_matches from exact pixels with the gimbal pointed at
// them), so that with max_landmarks = N each new landmark evicts one out of view, as in a long
// run. Every iteration starts again from that same prepared filter (the copy is not timed), so the
// state dimension is the same at every iteration: 18 + 3N.
//
//   bench_ekf [--benchmark_filter=...]
#include <benchmark/benchmark.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <optional>
#include <random>
#include <stdexcept>
#include <tuple>
#include <vector>

#include "geometry/camera.hpp"
#include "io/heap.hpp"
#include "slam/estimator.hpp"

namespace {

using namespace wingman;
using Eigen::Vector2d;
using Eigen::Vector3d;

constexpr int kMaxPerCamera = 40;      // correspondences per camera a frontend would hand over
constexpr int kNewPerStep = 2;         // cooperative initialisations per step
constexpr double kPixelSigma = 3.0;    // px
constexpr double kOutlierFraction = 0.05;
constexpr double kOutlierMaxPx = 15.0;
constexpr double kGridSide = 100.0;    // m

Eigen::Matrix3d nadir() { return Eigen::Vector3d(1, -1, -1).asDiagonal(); }

// R_CW of a camera whose optical axis points from `from` towards `to`.
Eigen::Matrix3d look_at(const Vector3d& from, const Vector3d& to) {
  const Vector3d z = (to - from).normalized();
  const Vector3d a = std::abs(z.z()) < 0.9 ? Vector3d::UnitZ() : Vector3d::UnitX();
  const Vector3d x = z.cross(a).normalized();
  const Vector3d y = z.cross(x);
  Eigen::Matrix3d R;
  R.row(0) = x.transpose();
  R.row(1) = y.transpose();
  R.row(2) = z.transpose();
  return R;
}

// A filter with N landmarks, the truth of each, and fresh ground points to initialise.
struct Prepared {
  std::unique_ptr<slam::Estimator> est;
  std::vector<Vector3d> cam_truth;
  std::map<slam::LandmarkId, Vector3d> truth;
  std::vector<Vector3d> fresh;  // in view of both cameras, never in the map
};

std::vector<slam::CameraRig> nadir_rigs(int n) {
  slam::CameraRig rig;
  rig.model = geometry::PinholeCamera(200.1, 200.1, 500, 500, 1000, 1000);
  rig.R_CW = nadir();
  rig.orientation_sigma = 0.04;  // as the shipped scenes
  return std::vector<slam::CameraRig>(n, rig);
}

std::optional<Vector2d> pixel(const slam::CameraRig& rig, const Vector3d& cam, const Vector3d& p) {
  auto uv = slam::project_point(rig, cam, p);
  if (!uv || !rig.model.in_image(*uv, 1.0)) return std::nullopt;
  return uv;
}

// Camera j of a team: pairs like the paper's two (x -1.5 and 1.5, 15 and 17 m up), the first at
// y 0 and the others 3 m, -3 m, 6 m ... beside it.
std::vector<Vector3d> team(int n) {
  std::vector<Vector3d> out;
  for (int j = 0; j < n; ++j) {
    const int k = j / 2;
    const double y = 3.0 * ((k + 1) / 2) * (k % 2 ? 1 : -1);
    out.emplace_back(j % 2 ? 1.5 : -1.5, y, j % 2 ? 17 : 15);
  }
  return out;
}

Prepared prepare(int n_landmarks, int n_cameras = 2, bool offsets = false) {
  Prepared out;
  out.cam_truth = team(n_cameras);
  slam::EstimatorSettings cfg;
  cfg.process_noise.accel_sigma_lead = 0.1;  // white, per agent
  cfg.process_noise.accel_sigma_uav = 0.5;
  cfg.process_noise.accel_sigma_common = 0.0;
  cfg.measurement_noise.orientation_sigma = 0;
  // With offsets, each landmark carries the pixel offsets of the other cameras that observed it
  // (as the rendered scenes).
  cfg.measurement_noise.pixel_offset_sigma = offsets ? 0.75 : 0.0;
  cfg.gating.ransac_inlier_px = 4;
  cfg.map.max_landmarks = n_landmarks;
  cfg.map.max_misses = 1 << 30;                 // nothing is dropped for missing matches
  cfg.initialisation.min_parallax_deg = 1.0;  // the far, out-of-view part of the grid
  cfg.initialisation.low_parallax_inverse_depth = false;
  const auto nadir_rig = nadir_rigs(n_cameras);
  auto rigs = nadir_rig;
  std::vector<slam::AgentInit> cams;
  for (const Vector3d& c : out.cam_truth) cams.push_back({c, Vector3d::Zero()});
  out.est = std::make_unique<slam::Estimator>(rigs, slam::AgentInit{}, cams, cfg);
  slam::Estimator& est = *out.est;

  // Points of a square grid over the 100 m square beneath the cameras, in a shuffled order so
  // that any N of them cover the square evenly, with heights within +-1 m. A few out of view lie
  // too close to the cameras' baseline to triangulate; a slightly larger grid supplies others.
  const int side = static_cast<int>(std::ceil(std::sqrt(1.1 * n_landmarks))) + 1;
  const double step = kGridSide / (side - 1);
  std::vector<Vector3d> grid;
  std::mt19937_64 rng(n_landmarks);
  std::uniform_real_distribution<double> height(-1.0, 1.0);
  for (int i = 0; i < side; ++i)
    for (int j = 0; j < side; ++j)
      grid.emplace_back(-kGridSide / 2 + i * step, -kGridSide / 2 + j * step, height(rng));
  std::shuffle(grid.begin(), grid.end(), rng);

  const Vector3d mid = 0.5 * (out.cam_truth[0] + out.cam_truth[1]);
  for (const Vector3d& p : grid) {
    if (est.num_landmarks() == n_landmarks) break;
    // Nadir where both cameras see the point, else the gimbals point at it.
    const bool in_view =
        pixel(nadir_rig[0], out.cam_truth[0], p) && pixel(nadir_rig[1], out.cam_truth[1], p);
    const Eigen::Matrix3d R = in_view ? nadir() : look_at(mid, p);
    for (int j = 0; j < n_cameras; ++j) {
      est.set_camera_rotation(j, R);
      rigs[j].R_CW = R;
    }
    const auto uv_a = pixel(rigs[0], out.cam_truth[0], p), uv_b = pixel(rigs[1], out.cam_truth[1], p);
    if (!uv_a || !uv_b) throw std::logic_error("bench_ekf: grid point not in view");
    const auto r = est.initialise_from_matches({{0, 1, *uv_a, *uv_b}});
    if (r[0].id) out.truth[*r[0].id] = p;
  }
  for (int j = 0; j < n_cameras; ++j) est.set_camera_rotation(j, nadir());
  est.end_step();
  if (est.num_landmarks() != n_landmarks) throw std::logic_error("bench_ekf: wrong landmark count");
  if (offsets) {
    // A run's steady state: every camera has observed the landmarks in its view, so their
    // offsets are states (a camera's become states at its first observation).
    std::vector<slam::Correspondence> seen;
    for (int j = 0; j < n_cameras; ++j)
      for (const auto& p : est.landmarks_in_view(j))
        if (const auto uv = slam::project_point(est.camera(j), out.cam_truth[j], out.truth.at(p.id)))
          seen.push_back({j, p.id, *uv});
    est.update_visual(seen);
    est.end_step();
  }

  // Fresh points for the timed initialisations: between the grid's points, in view of both.
  for (int i = -6; i <= 6; ++i)
    for (int j = -6; j <= 6; ++j) {
      const Vector3d p(i * 5.0 + 1.3, j * 5.0 + 1.7, 0.5);
      if (pixel(est.camera(0), out.cam_truth[0], p) && pixel(est.camera(1), out.cam_truth[1], p))
        out.fresh.push_back(p);
    }
  std::shuffle(out.fresh.begin(), out.fresh.end(), rng);
  return out;
}

// Built once per size: Google Benchmark calls the function more than once per argument.
const Prepared& prepared(int n, int cameras, bool offsets) {
  static std::map<std::tuple<int, int, bool>, Prepared> cache;
  const auto key = std::make_tuple(n, cameras, offsets);
  auto it = cache.find(key);
  if (it == cache.end()) it = cache.emplace(key, prepare(n, cameras, offsets)).first;
  return it->second;
}

// One step of a team of `cameras` cameras over an `n`-landmark map.
void ekf_step(benchmark::State& state, int n, int cameras, bool offsets = false) {
  const Prepared& prep = prepared(n, cameras, offsets);
  std::mt19937_64 rng(42);
  std::normal_distribution<double> noise(0.0, kPixelSigma);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  auto noisy = [&](const Vector2d& uv) {
    if (unit(rng) < kOutlierFraction) {
      const double a = 2 * M_PI * unit(rng), r = kOutlierMaxPx * unit(rng);
      return Vector2d(uv + r * Vector2d(std::cos(a), std::sin(a)));
    }
    return Vector2d(uv + Vector2d(noise(rng), noise(rng)));
  };

  slam::Estimator est = *prep.est;
  std::size_t next_fresh = 0;
  double visible = 0, offered = 0, accepted = 0, initialised = 0, evicted = 0, dim = 0;
  for (auto _ : state) {
    state.PauseTiming();
    est = *prep.est;  // the same N-landmark filter at every iteration
    state.ResumeTiming();

    est.predict(0.1);
    std::vector<slam::Correspondence> cands;
    for (int j = 0; j < cameras; ++j) {
      const auto preds = est.landmarks_in_view(j);
      visible += preds.size();
      // At most kMaxPerCamera, spread over the predictions.
      const std::size_t take = std::min<std::size_t>(preds.size(), kMaxPerCamera);
      for (std::size_t i = 0; i < take; ++i) {
        const auto& p = preds[i * preds.size() / take];
        const auto uv = slam::project_point(est.camera(j), prep.cam_truth[j], prep.truth.at(p.id));
        if (uv) cands.push_back({j, p.id, noisy(*uv)});
      }
    }
    const auto vr = est.update_visual(cands);
    offered += cands.size();
    accepted += std::count(vr.accepted.begin(), vr.accepted.end(), true);

    std::vector<slam::CrossMatch> matches;
    for (int i = 0; i < kNewPerStep; ++i) {
      const Vector3d& p = prep.fresh[next_fresh++ % prep.fresh.size()];
      const auto uv_a = slam::project_point(est.camera(0), prep.cam_truth[0], p);
      const auto uv_b = slam::project_point(est.camera(1), prep.cam_truth[1], p);
      matches.push_back({0, 1, noisy(*uv_a), noisy(*uv_b)});
    }
    for (const auto& r : est.initialise_from_matches(matches)) initialised += r.id.has_value();
    evicted += est.end_step().size();
    dim += est.state().dim();
    benchmark::DoNotOptimize(est.state().x.data());
  }
  // items: EKF steps. Per step on average: state_dim, visible (landmarks predicted in view, both
  // cameras together), offered / accepted correspondences, init (new landmarks), evicted.
  state.SetItemsProcessed(state.iterations());
  const auto avg = benchmark::Counter::kAvgIterations;
  state.counters["landmarks"] = benchmark::Counter(est.num_landmarks());
  state.counters["state_dim"] = benchmark::Counter(dim, avg);
  state.counters["visible"] = benchmark::Counter(visible, avg);
  state.counters["offered"] = benchmark::Counter(offered, avg);
  state.counters["accepted"] = benchmark::Counter(accepted, avg);
  state.counters["init"] = benchmark::Counter(initialised, avg);
  state.counters["evicted"] = benchmark::Counter(evicted, avg);
}

void BM_EkfStep(benchmark::State& state) { ekf_step(state, static_cast<int>(state.range(0)), 2); }

// The team-size axis: 2 to 8 cameras over the same 200-landmark map (each camera offers at most 40
// correspondences), with white pixel noise (offsets 0) or with pixel offsets as states (offsets 1)
// for every landmark and every other camera that sees it (a run's steady state). A single UAV has
// no cooperative initialisation: docs/studies/team-size.md.
void BM_EkfTeam(benchmark::State& state) {
  ekf_step(state, 200, static_cast<int>(state.range(0)), state.range(1) != 0);
}

BENCHMARK(BM_EkfStep)
    ->ArgName("landmarks")
    ->Arg(50)
    ->Arg(100)
    ->Arg(200)
    ->Arg(400)
    ->Unit(benchmark::kMillisecond)
    ->MinTime(0.2);
// A step takes about 0.3 s here: a longer minimum for more than one iteration.
BENCHMARK(BM_EkfStep)->ArgName("landmarks")->Arg(800)->Unit(benchmark::kMillisecond)->MinTime(1.0);
BENCHMARK(BM_EkfTeam)
    ->ArgNames({"cameras", "offsets"})
    ->ArgsProduct({{2, 4, 6, 8}, {0, 1}})
    ->Unit(benchmark::kMillisecond)
    ->MinTime(0.5);

}  // namespace

// The wingman command's heap policy (io/heap.hpp), so that a step costs here what it costs there.
int main(int argc, char** argv) {
  wingman::io::keep_freed_memory_on_the_heap();
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
