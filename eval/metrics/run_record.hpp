// What one run leaves for evaluation: per-step truth and estimates, the landmarks the filter
// initialised with their truth, and the outlier bookkeeping. The pipeline (app/) fills it;
// metrics.hpp turns it into the paper's tables (docs/design.md, evaluation) and writers.hpp into files.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "geometry/lead_image.hpp"

namespace wingman::eval {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

struct AgentStep {
  Eigen::Vector3d p_true = Eigen::Vector3d::Zero(), v_true = Eigen::Vector3d::Zero();
  Eigen::Vector3d p_est = Eigen::Vector3d::Zero(), v_est = Eigen::Vector3d::Zero();
  // Orientation of the agent's frame in the world (q_WB), for the TUM files: the lead's heading
  // about z; a UAV's camera attitude (its state is the camera's position). "true" from the truth
  // (the lead's direction of travel; the camera's attitude with the gimbal error), "est" what the
  // run had (the heading of the estimated velocity; the commanded attitude the filter is given).
  Eigen::Quaterniond q_true = Eigen::Quaterniond::Identity(), q_est = Eigen::Quaterniond::Identity();
  Eigen::Vector3d p_sigma = Eigen::Vector3d::Zero();  // sqrt of diag of the position covariance
  // NEES of the position and of the velocity alone (3 dof each, their marginal covariances):
  // says which block of the state is over- or underconfident when the total is off.
  double nees_p = kNaN, nees_v = kNaN;
};

// Closed loop only (paper section 6): one UAV's formation at one step. "true" values come from
// the truth (lead, body position, yaw; psi_d from the true lead's bearing), "est" ones are what
// the controller computed from the estimator and the AHRS.
struct FormationStep {
  Eigen::Vector3d position_true = Eigen::Vector3d::Zero();  // body, for inter-UAV distances
  Eigen::Vector4d lambda_true = Eigen::Vector4d::Zero(), lambda_d_true = Eigen::Vector4d::Zero();
  Eigen::Vector4d lambda_est = Eigen::Vector4d::Zero(), lambda_d_est = Eigen::Vector4d::Zero();
  Eigen::Vector4d surface = Eigen::Vector4d::Zero();  // s of eq. 60
  Eigen::Vector4d command = Eigen::Vector4d::Zero();  // vx, vy, vz, w commanded (after limits)
  double yaw_true = 0, yaw_ahrs = 0;
  bool limited = false;
  // lambda - lambda_d with psi wrapped to (-pi, pi].
  Eigen::Vector4d error_true() const;
  Eigen::Vector4d error_est() const;
};

// A step's counts, each a steps.csv column of its name: a new count is one line in visit().
struct StepCounts {
  int landmarks_visible = 0;  // predicted in view of some camera
  int matches_offered = 0;    // landmark correspondences given to the filter
  int matches_accepted = 0;
  int initialised = 0;  // landmarks added this step
  template <class V>
  void visit(V&& v) const {
    v("landmarks_visible", landmarks_visible);
    v("matches_offered", matches_offered);
    v("matches_accepted", matches_accepted);
    v("initialised", initialised);
  }
};

// One value per stage of a step, in the order the stages run: rendered mode adds rendering, lead
// detection + features, and tracking + cross matching (`rendered_only`). StageTimings (ms, each a
// steps.csv column t_<stage>_ms) and the metrics' Timings (timings_ms.<stage>) are both this
// struct: a new stage is one line in visit_fields().
template <typename T>
struct ByStage {
  T predict{}, update{}, init{}, render{}, detect{}, match{};
  static constexpr int kStages = 6;

  // v(stage name, value, rendered_only)
  template <class V>
  void visit(V&& v) const { visit_fields(*this, v); }
  template <class V>
  void visit(V&& v) { visit_fields(*this, v); }
  // v(stage name, this stage's value, other's value, rendered_only)
  template <typename U, class V>
  void zip(ByStage<U>& other, V&& v) const {
    std::array<U*, kStages> o{};
    int i = 0;
    other.visit([&](const char*, U& x, bool) { o[static_cast<std::size_t>(i++)] = &x; });
    i = 0;
    visit([&](const char* name, const T& x, bool rendered_only) { v(name, x, *o[static_cast<std::size_t>(i++)], rendered_only); });
  }

 private:
  template <class S, class V>
  static void visit_fields(S& s, V& v) {
    v("predict", s.predict, false);
    v("update", s.update, false);
    v("init", s.init, false);
    v("render", s.render, true);
    v("detect", s.detect, true);
    v("match", s.match, true);
  }
};

// A step's wall time by stage, ms.
struct StageTimings : ByStage<double> {
  // Every stage summed, in their order.
  double total() const {
    double sum = 0;
    visit([&](const char*, double ms, bool) { sum += ms; });
    return sum;
  }
};

struct StepRecord {
  int k = 0;
  double t = 0;
  int phase = -1;                // index into RunRecord::phases, -1 outside every phase
  std::vector<AgentStep> agents;  // same order as RunRecord::agent_names
  double nees = kNaN;             // eq. 67 over agents' positions and velocities
  int nees_dof = 0;
  int landmarks = 0;              // in the state after this step
  StepCounts counts;
  StageTimings t_ms;
  std::vector<FormationStep> formation;  // closed loop: per RunRecord::formation_uavs; else empty
};

struct LandmarkRecord {
  std::int64_t id = 0;
  Eigen::Vector3d truth = Eigen::Vector3d::Zero();
  double t_init = 0;
  int init_phase = -1;
  Eigen::Vector3d est_init = Eigen::Vector3d::Zero();
  // Estimate at the end of the phase it was initialised in (or when removed, if earlier).
  Eigen::Vector3d est_phase_end = Eigen::Vector3d::Zero();
  // Estimate at the end of the run (or when removed).
  Eigen::Vector3d est_final = Eigen::Vector3d::Zero();
  double t_removed = kNaN;  // NaN while still in the map at the end
  std::string origin;       // "cooperative" or "inverse_depth"
};

// Table 3 bookkeeping for one channel: "uav1", "uav2", ... or "cooperative".
struct OutlierCounts {
  std::string channel;
  long correspondences = 0;     // produced by the frontend (or the synthetic source)
  long injected = 0;            // synthetic outliers injected (0 with real matching)
  long outliers = 0;            // outliers among them: corrupted by the synthetic source, or
                                // (real matching) > 3 px from the true projection
  long accepted = 0;            // correspondences the filter accepted
  long outliers_accepted = 0;   // outliers among those
};

// One tracked correspondence offered to the filter (rendered mode, `wingman run
// --correspondences`): where the frontend put the landmark and where it truly projects. Kept per
// step and landmark so that errors can be followed along a track (tools/track_error.py).
struct TrackedCorrespondence {
  int k = 0;
  double t = 0;
  int cam = 0;
  std::int64_t landmark = 0;
  Eigen::Vector2d uv = Eigen::Vector2d::Zero();
  Eigen::Vector2d true_uv = Eigen::Vector2d::Constant(kNaN);  // NaN: the landmark has no truth
  bool outlier = false;   // the ground-truth label (> 3 px, occluded or no truth)
  bool accepted = false;  // by the filter's RANSAC and gate
};

// One camera frame's lead detection beside the lead's ground truth (lead.csv).
struct LeadFrameRecord {
  int k = 0;
  double t = 0;
  int cam = 0;
  Eigen::Vector2d detected = Eigen::Vector2d::Constant(kNaN);  // NaN: nothing detected
  bool has_truth = false;  // false: a replay of a dataset without cam0_lead0
  geometry::LeadImage truth;
};

// A run's use of the frame cache (render/frame_cache.hpp); provenance and timing, not a result.
struct FrameCacheRecord {
  bool used = false;
  std::string dir;
  long hits = 0, misses = 0, corrupt = 0, stores = 0, evicted = 0;
  double read_ms = 0, write_ms = 0;  // wall time over the run
  double bytes_read = 0, bytes_written = 0;
};

// Rendered mode only: what the lead detector did against the truth, over every camera frame.
struct FrontendRecord {
  bool enabled = false;
  std::string detector;   // feature detector, e.g. "orb"
  std::string renderer;   // GL context description, or the dataset a replay reads
  bool frames_rendered = true;  // false: a replay's frames were loaded from files
  // frontend.oracle_pixels: correct correspondences carried their exact projections (a diagnostic
  // run; its figures are not the frontend's).
  bool oracle_pixels = false;
  long frames = 0;        // camera frames processed
  long lead_in_view = 0;  // frames whose true lead reference point projects inside the image
  long lead_detected = 0; // of those, frames with a detection within lead_match_px of the truth
  long lead_false = 0;    // detections farther than lead_match_px, or with the lead out of view
  double lead_match_px = 10;
  double detect_busy_ms = 0;  // detection's whole duration over the run (partly behind rendering)
  // Active search: the share of each frame's pixels the feature detector processed, summed over
  // the frames (1 per frame detected whole).
  double searched_fraction_sum = 0;
  // Region rendering: frames of which only the frontend's regions were drawn; of those, the ones
  // drawn again whole because the lead was not in its finder's window, and the prefetched ones
  // whose step's own plan asked for pixels the predicted plan had not drawn.
  long region_frames = 0, whole_frame_retries = 0, region_fills = 0;
  std::vector<double> lead_error_px;  // detection to true projection, for the lead_detected frames
  // Tracked correspondences the filter accepted: pixel to the landmark's true projection (NaN when
  // the landmark has no truth). Says whether the labelled outliers are near misses or mismatches.
  std::vector<double> accepted_error_px;
  // Every tracked correspondence, when asked for (about 83 000 on the 210 s paper scene, multi-UAV).
  bool record_correspondences = false;
  std::vector<TrackedCorrespondence> correspondences;
  std::vector<LeadFrameRecord> lead_frames;  // every camera frame, in order
  FrameCacheRecord frame_cache;
};

struct PhaseInfo {
  std::string name;
  double t_start = 0, t_end = 0;
  std::string config;  // "1", "2", "3", "integrated"
};

// The noise the filter assumed, beside its input, for the consistency diagnosis.
struct AssumedNoise {
  std::vector<double> accel_sigma;  // per agent (agent_names order): sqrt(common^2 + own^2), m/s^2
  double pixel_sigma = kNaN;        // px per axis
  double truth_pixel_sigma = kNaN;  // synthetic: the truth's noise.pixel_sigma; NaN when rendered
};

struct RunRecord {
  std::string scenario_path, scenario_name, variant;
  std::string estimator_mode;  // "multi" or "single"
  std::uint64_t seed = 0;
  std::string software_version;
  std::vector<std::string> agent_names;  // "lead", "uav1", "uav2", ...
  std::vector<PhaseInfo> phases;
  std::vector<StepRecord> steps;
  std::vector<LandmarkRecord> landmarks;
  std::vector<OutlierCounts> outliers;
  FrontendRecord frontend;
  AssumedNoise assumed;
  double wall_time_s = 0;
  // The filter's numerical breakdown (estimator.on_numerical_failure: record): the steps end
  // before it; empty message when none.
  struct NumericalFailure {
    int step = 0;
    double t = 0;
    std::string message;
  } numerical_failure;
  // Closed loop (section 6): the controlled UAVs and when formation metrics start in a phase.
  bool closed_loop = false;
  std::vector<std::string> formation_uavs;
  double settling_time = 10.0;
};

inline Eigen::Vector4d wrapped_difference(const Eigen::Vector4d& a, const Eigen::Vector4d& b) {
  Eigen::Vector4d e = a - b;
  e(3) = std::remainder(e(3), 2 * M_PI);
  if (e(3) <= -M_PI) e(3) += 2 * M_PI;
  return e;
}
inline Eigen::Vector4d FormationStep::error_true() const {
  return wrapped_difference(lambda_true, lambda_d_true);
}
inline Eigen::Vector4d FormationStep::error_est() const {
  return wrapped_difference(lambda_est, lambda_d_est);
}

}  // namespace wingman::eval
