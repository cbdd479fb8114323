#include "app/pipeline/loop.hpp"

#include <Eigen/Cholesky>
#include <fmt/core.h>
#include <fmt/ranges.h>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <random>

#include "io/interrupt.hpp"
#include "app/pipeline/shared_view.hpp"
#include "io/timing.hpp"
#include "io/version.hpp"
#include "sim/rng.hpp"
#include "sim/world.hpp"
#include "slam/health.hpp"

namespace wingman::app {

namespace {

// A NEES is a squared Mahalanobis distance: below zero or not finite, the covariance it was
// computed with is not positive definite, and every figure after it would be meaningless.
double checked_nees(double nees, const char* block) {
  if (nees >= 0 && std::isfinite(nees)) return nees;
  throw slam::NumericalFailure(fmt::format("numerical failure: the NEES of {} block is {} (its covariance "
                                           "is not positive definite)", block, nees));
}

// NEES (eq. 67) over the agents' positions and velocities.
double agent_nees(const slam::FilterState& s, const Eigen::VectorXd& truth) {
  const int d = s.kinematic_dim();
  const Eigen::VectorXd e = truth - s.x.head(d);
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(s.P.topLeftCorner(d, d));
  return checked_nees(ldlt.info() == Eigen::Success ? e.dot(ldlt.solve(e)) : eval::kNaN, "the agents'");
}

// NEES of one 3-vector block of the state against its marginal covariance.
double block_nees(const slam::FilterState& s, int pos, const Eigen::Vector3d& truth) {
  const Eigen::Vector3d e = truth - s.x.segment<3>(pos);
  const Eigen::LDLT<Eigen::Matrix3d> ldlt(s.P.block<3, 3>(pos, pos));
  return checked_nees(ldlt.info() == Eigen::Success ? e.dot(ldlt.solve(e)) : eval::kNaN,
                      slam::describe_state_element(s, pos).c_str());
}

// The filter at t = 0: the truth, or the truth plus a draw of the initial covariance.
slam::Estimator make_estimator(const RunConfig& cfg, const sim::Truth& truth, const std::vector<int>& cam_uav) {
  std::mt19937_64 rng = sim::make_stream(cfg.seed, "initial_estimate");
  std::normal_distribution<double> unit(0.0, 1.0);
  const auto& sigma = cfg.estimator.initial_sigma;
  auto initial = [&](const sim::KinematicState& k) {
    slam::AgentInit a{k.position, k.velocity};
    if (!sigma.draw) return a;
    a.position += sim::gaussian3(rng, unit, sigma.position);
    a.velocity += sim::gaussian3(rng, unit, sigma.velocity);
    return a;
  };
  std::vector<slam::CameraRig> rigs;
  std::vector<slam::AgentInit> cams;
  for (int u : cam_uav) {
    slam::CameraRig rig;
    rig.model = cfg.uavs[u].camera.camera();
    rig.R_CW = truth.commanded_R_CW();
    rig.offset = cfg.uavs[u].camera.offset;
    rig.orientation_sigma = cfg.estimator.measurement_noise.orientation_sigma;
    rigs.push_back(rig);
    cams.push_back(initial(truth.camera(u, 0.0)));
  }
  const slam::AgentInit lead = initial(truth.lead(0.0));
  return slam::Estimator(rigs, lead, cams, cfg.estimator, cfg.seed);
}

eval::RunRecord make_record(const RunConfig& cfg, const std::vector<int>& cam_uav) {
  eval::RunRecord rec;
  rec.scenario_path = cfg.source_path;
  rec.scenario_name = cfg.name;
  rec.variant = cfg.variant;
  rec.estimator_mode = slam::to_string(cfg.estimator.mode);
  rec.seed = cfg.seed;
  rec.software_version = kVersion;
  rec.agent_names.push_back("lead");
  for (int u : cam_uav) rec.agent_names.push_back(cfg.uavs[u].name);
  for (const auto& p : cfg.phases) rec.phases.push_back({p.name, p.t_start, p.t_end, sim::to_string(p.config)});
  const auto& q = cfg.estimator.process_noise;
  const double common = q.accel_sigma_common;
  rec.assumed.accel_sigma.push_back(std::hypot(common, q.accel_sigma_lead));
  for (std::size_t j = 0; j < cam_uav.size(); ++j) rec.assumed.accel_sigma.push_back(std::hypot(common, q.accel_sigma_uav));
  rec.assumed.pixel_sigma = cfg.estimator.measurement_noise.pixel_sigma;
  if (cfg.measurements != sim::MeasurementMode::Rendered) rec.assumed.truth_pixel_sigma = cfg.noise.pixel_sigma;
  for (int u : cam_uav) rec.outliers.push_back({cfg.uavs[u].name});
  if (!cfg.single_uav()) rec.outliers.push_back({"cooperative"});
  return rec;
}

using eval::StepCounts;

// A run in progress: the filter, what the record keeps of it, and the step's per-camera state.
class Run {
 public:
  Run(const RunConfig& cfg, const sim::Truth& truth, MeasurementSource& src)
      : cfg_(cfg),
        truth_(truth),
        src_(src),
        cam_uav_(cfg.filter_uavs()),
        est(make_estimator(cfg, truth, cam_uav_)),
        rec(make_record(cfg, cam_uav_)),
        in_view_(cam_uav_.size(), 0),
        sees_(cam_uav_.size(), false) {}

  void update(double t, StepCounts& n, eval::StageTimings& tm);
  void initialise(double t, int phase, StepCounts& n, eval::StageTimings& tm);
  void end_step(double t);
  void record_step(int k, double t, const StepCounts& n, const eval::StageTimings& tm);
  void snapshot_landmarks(int phase);
  int cameras() const { return static_cast<int>(cam_uav_.size()); }
  const RunConfig& cfg() const { return cfg_; }
  const sim::Truth& truth() const { return truth_; }
  bool active(sim::Sensor s, double t, int cam) const {
    return cfg_.sensor_active(s, t, cfg_.uavs[cam_uav_[cam]].name);
  }

 private:
  void update_sensors(double t);
  void add(slam::LandmarkId id, int cam, std::int64_t handle, const Eigen::Vector2d& uv, double t,
           int phase, const char* origin, StepCounts& n);
  void initialise_pairs(double t, int phase, std::vector<int>& added, StepCounts& n, eval::StageTimings& tm);
  void initialise_points(int cam, int need, double t, int phase, StepCounts& n, eval::StageTimings& tm);

  const RunConfig& cfg_;
  const sim::Truth& truth_;
  MeasurementSource& src_;
  std::vector<int> cam_uav_;

 public:
  slam::Estimator est;
  eval::RunRecord rec;

 private:
  std::map<slam::LandmarkId, std::size_t> lm_record_;  // filter id -> index in rec.landmarks
  std::vector<int> in_view_;                            // this step's predictions, per camera
  std::vector<bool> sees_;                              // landmarks switched on this step
};

// Landmark correspondences for what the filter predicts in view, with the lead's projections
// of the same frames (eq. 5-6); then GPS, altimeter and range.
void Run::update(double t, StepCounts& n, eval::StageTimings& tm) {
  const auto t0 = io::Clock::now();
  Labelled<LandmarkObservation> obs;
  for (int j = 0; j < cameras(); ++j) {
    sees_[j] = active(sim::Sensor::Landmarks, t, j);
    in_view_[j] = 0;
    if (!sees_[j]) continue;
    const auto preds = est.landmarks_in_view(j);
    in_view_[j] = static_cast<int>(preds.size());
    n.landmarks_visible += in_view_[j];
    const auto tm0 = io::Clock::now();
    Labelled<LandmarkObservation> seen = src_.landmarks(j, preds);
    for (std::size_t i = 0; i < seen.size(); ++i) obs.add(std::move(seen.items[i]), seen.labels[i]);
    tm.match += io::ms_since(tm0);
  }
  std::vector<slam::Correspondence> cands;
  for (const auto& o : obs.items) cands.push_back(o.c);
  std::vector<std::pair<int, Eigen::Vector2d>> lead_pixels;
  for (int j = 0; j < cameras(); ++j)
    if (active(sim::Sensor::LeadProjection, t, j))
      if (auto uv = src_.lead_pixel(j)) lead_pixels.emplace_back(j, *uv);
  const auto vr = est.update_visual(cands, lead_pixels);
  for (std::size_t i = 0; i < obs.size(); ++i) {
    const TruthLabel& label = obs.labels[i];
    auto& oc = rec.outliers[obs.items[i].c.cam];
    ++oc.correspondences;
    if (label.injected) ++oc.injected;
    if (label.outlier) ++oc.outliers;
    src_.verdict(obs.items[i], label, vr.accepted[i]);
    if (!vr.accepted[i]) continue;
    ++n.matches_accepted;
    ++oc.accepted;
    if (label.outlier) ++oc.outliers_accepted;
  }
  n.matches_offered = static_cast<int>(cands.size());
  update_sensors(t);
  tm.update = io::ms_since(t0) - tm.match;
}

void Run::update_sensors(double t) {
  SensorRequest wanted;
  wanted.gps = cfg_.sensor_active(sim::Sensor::Gps, t, "lead");
  for (int j = 0; j < cameras(); ++j) {
    wanted.altimeter.push_back(active(sim::Sensor::Altimeter, t, j));
    wanted.range.push_back(active(sim::Sensor::Range, t, j));
  }
  est.update_sensors(src_.sensors(wanted));
}

// A new landmark's record for Table 5, with its truth when the source can tell it.
void Run::add(slam::LandmarkId id, int cam, std::int64_t handle, const Eigen::Vector2d& uv, double t,
              int phase, const char* origin, StepCounts& n) {
  ++n.initialised;
  const auto truth_point = src_.added(id, cam, handle, uv);
  if (!truth_point) return;  // no rendered surface there: left out of Table 5
  eval::LandmarkRecord lr;
  lr.id = id;
  lr.truth = *truth_point;
  lr.t_init = t;
  lr.init_phase = phase;
  lr.est_init = lr.est_phase_end = lr.est_final = *est.landmark_position(id);
  lr.origin = origin;
  lm_record_[id] = rec.landmarks.size();
  rec.landmarks.push_back(lr);
}

// New landmarks where a camera sees fewer than the target: cooperatively from pairs of cameras
// (eq. 47-52), or from one camera's pixels in inverse depth (the single-UAV baseline, and multi-UAV
// cameras the pairs left short when monocular_fill is on).
void Run::initialise(double t, int phase, StepCounts& n, eval::StageTimings& tm) {
  const auto t0 = io::Clock::now();
  const double match0 = tm.match;
  const int target = cfg_.estimator.map.target_per_camera;
  if (cfg_.single_uav()) {
    if (sees_[0] && target - in_view_[0] > 0) initialise_points(0, target - in_view_[0], t, phase, n, tm);
  } else {
    std::vector<int> added(cameras(), 0);  // this step's cooperative landmarks, per camera
    initialise_pairs(t, phase, added, n, tm);
    for (int j = 0; j < cameras() && cfg_.estimator.initialisation.monocular_fill; ++j) {
      const int need = target - in_view_[j] - added[j];
      if (sees_[j] && need > 0) initialise_points(j, need, t, phase, n, tm);
    }
  }
  tm.init = io::ms_since(t0) - (tm.match - match0);
}

// Every pair of cameras that shares view, most shared first; a pair asks for the larger deficit
// its two cameras still have after the pairs before it.
void Run::initialise_pairs(double t, int phase, std::vector<int>& added, StepCounts& n, eval::StageTimings& tm) {
  const int target = cfg_.estimator.map.target_per_camera;
  auto deficit = [&](int j) { return target - in_view_[j] - added[j]; };
  eval::OutlierCounts& coop = rec.outliers.back();
  for (const auto& pr : pairs_sharing_view(est, sees_)) {
    const int need = std::max(deficit(pr.first), deficit(pr.second));
    if (need <= 0) continue;
    const auto tm0 = io::Clock::now();
    const auto found = src_.pairs(pr.first, pr.second, need, est);
    tm.match += io::ms_since(tm0);
    std::vector<slam::CrossMatch> cm;
    for (const auto& p : found.items) cm.push_back(p.m);
    const auto outcomes = est.initialise_from_matches(cm);
    for (std::size_t i = 0; i < found.size(); ++i) {
      const TruthLabel& label = found.labels[i];
      ++coop.correspondences;
      if (label.injected) ++coop.injected;
      if (label.outlier) ++coop.outliers;
      if (!outcomes[i].id) continue;
      ++coop.accepted;
      if (label.outlier) ++coop.outliers_accepted;
      const PairObservation& p = found.items[i];
      add(*outcomes[i].id, pr.first, p.handle, p.m.uv_a, t, phase, "cooperative", n);
      ++added[pr.first], ++added[pr.second];
    }
  }
}

void Run::initialise_points(int cam, int need, double t, int phase, StepCounts& n, eval::StageTimings& tm) {
  const auto tm0 = io::Clock::now();
  const auto points = src_.points(cam, need);
  tm.match += io::ms_since(tm0);
  for (const auto& p : points)
    if (auto r = est.initialise_from_pixel(cam, p.uv); r.id)
      add(*r.id, cam, p.handle, p.uv, t, phase, "inverse_depth", n);
}

// Map management; a removed landmark keeps its last estimate in the record.
void Run::end_step(double t) {
  for (slam::LandmarkId id : est.end_step()) {
    src_.removed(id);
    if (auto it = lm_record_.find(id); it != lm_record_.end()) rec.landmarks[it->second].t_removed = t;
  }
}

// Latest estimate of every landmark in the map; a landmark removed later keeps its last one.
void Run::snapshot_landmarks(int phase) {
  for (const auto& slot : est.state().landmarks()) {
    auto it = lm_record_.find(slot.id);
    if (it == lm_record_.end()) continue;
    auto& lr = rec.landmarks[it->second];
    lr.est_final = est.state().landmark_position(slot);
    if (phase == lr.init_phase) lr.est_phase_end = lr.est_final;
  }
}

void Run::record_step(int k, double t, const StepCounts& n, const eval::StageTimings& tm) {
  eval::StepRecord st;
  st.k = k;
  st.t = t;
  st.phase = cfg_.phase_at(t);
  const auto& s = est.state();
  Eigen::VectorXd x_true(s.kinematic_dim());
  auto agent = [&](const sim::KinematicState& tr, int pos, const Eigen::Quaterniond& q_true,
                   const Eigen::Quaterniond& q_est) {
    eval::AgentStep a;
    a.q_true = q_true;
    a.q_est = q_est;
    a.p_true = tr.position;
    a.v_true = tr.velocity;
    a.p_est = s.x.segment<3>(pos);
    a.v_est = s.x.segment<3>(pos + 3);
    a.p_sigma = s.P.block<3, 3>(pos, pos).diagonal().cwiseMax(0.0).cwiseSqrt();
    if (k > 0) {
      a.nees_p = block_nees(s, pos, tr.position);
      a.nees_v = block_nees(s, pos + 3, tr.velocity);
    }
    x_true.segment<3>(pos) = tr.position;
    x_true.segment<3>(pos + 3) = tr.velocity;
    st.agents.push_back(a);
  };
  const auto about_z = [](double yaw) { return Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ())); };
  const Eigen::Vector3d v_lead = s.x.segment<3>(slam::FilterState::lead_pos() + 3);
  agent(truth_.lead(t), slam::FilterState::lead_pos(), about_z(sim::lead_heading(truth_, t)),
        about_z(std::atan2(v_lead.y(), v_lead.x())));
  const Eigen::Quaterniond q_commanded(Eigen::Matrix3d(truth_.commanded_R_CW().transpose()));
  for (int j = 0; j < cameras(); ++j)
    agent(truth_.camera(cam_uav_[j], t), slam::FilterState::cam_pos(j),
          Eigen::Quaterniond(Eigen::Matrix3d(truth_.camera_R_CW(cam_uav_[j], t).transpose())), q_commanded);
  st.nees = k == 0 ? eval::kNaN : agent_nees(s, x_true);
  st.nees_dof = s.kinematic_dim();
  st.landmarks = est.num_landmarks();
  st.counts = n;
  st.t_ms = tm;
  rec.steps.push_back(std::move(st));
}

// One step k > 0 at time t: predict, measure, update, initialise, record, control.
void run_step(Run& run, MeasurementSource& source, const LoopHooks& hooks, int k, double t) {
  const RunConfig& cfg = run.cfg();
  const int phase = cfg.phase_at(t);
  if (hooks.advance) hooks.advance(k, t);
  eval::StageTimings tm;
  StepCounts n;
  auto t0 = io::Clock::now();
  run.est.predict(cfg.dt());
  tm.predict = io::ms_since(t0);
  // The gimbal's commanded orientation is a known input (nadir).
  for (int j = 0; j < run.cameras(); ++j) run.est.set_camera_rotation(j, run.truth().commanded_R_CW());
  const StageTimes st = source.begin_step(k, t, run.est);
  // Stage times add up to the step's wall time: detection is what it added beyond producing
  // the frames (it overlaps the next camera's); its full duration is the source's to report.
  tm.render = st.render_ms;
  tm.detect = std::max(0.0, st.wall_ms - st.render_ms);
  run.update(t, n, tm);
  run.snapshot_landmarks(phase);
  run.initialise(t, phase, n, tm);
  run.end_step(t);
  source.end_step(t);
  run.record_step(k, t, n, tm);
  if (hooks.control) hooks.control(k, t, run.est, run.rec.steps.back());
}

// Which UAV each filter camera is, for messages that name cameras by index.
std::string camera_legend(const eval::RunRecord& rec) {
  std::vector<std::string> parts;
  for (std::size_t j = 1; j < rec.agent_names.size(); ++j)
    parts.push_back(fmt::format("camera {} is {}", j - 1, rec.agent_names[j]));
  return fmt::format("{}", fmt::join(parts, ", "));
}

}  // namespace

eval::RunRecord run_loop(const RunConfig& cfg, const sim::Truth& truth, MeasurementSource& source,
                         const LoopHooks& hooks, const ProgressFn& progress, const StateObserver& observer) {
  const auto wall0 = io::Clock::now();
  Run run(cfg, truth, source);
  run.record_step(0, 0.0, {}, {});
  if (hooks.control) hooks.control(0, 0.0, run.est, run.rec.steps.back());
  const int N = cfg.num_steps();
  for (int k = 1; k <= N; ++k) {
    io::throw_if_interrupted();  // SIGINT/SIGTERM: stop between steps, the caller's staging goes
    const double t = k * cfg.dt();
    try {
      run_step(run, source, hooks, k, t);
    } catch (const slam::NumericalFailure& e) {
      const std::string what = fmt::format("{}: step {} (t = {} s; {}): {}", cfg.source_path, k, t,
                                           camera_legend(run.rec), e.what());
      if (cfg.estimator.on_numerical_failure == slam::OnNumericalFailure::Stop) throw slam::NumericalFailure(what);
      // Record: the steps before it are the results; a partly recorded step is dropped.
      if (static_cast<int>(run.rec.steps.size()) > k) run.rec.steps.resize(static_cast<std::size_t>(k));
      run.rec.numerical_failure = {k, t, what};
      break;
    }
    if (observer) observer(k, run.est.state());
    if (progress) progress(k + 1, N + 1);  // steps done of all, t = 0 counted as the summary counts it
  }
  source.finish(run.rec);
  run.rec.wall_time_s = std::chrono::duration<double>(io::Clock::now() - wall0).count();
  return std::move(run.rec);
}

}  // namespace wingman::app
