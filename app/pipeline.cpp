#include "app/pipeline.hpp"
#include "app/timing.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <functional>
#include <map>
#include <memory>
#include <opencv2/imgproc.hpp>
#include <random>
#include <stdexcept>
#include <thread>

#include "app/rendered_frontend.hpp"
#include "app/version.hpp"
#include "datasets/dataset.hpp"
#include "control/formation.hpp"
#include "control/sliding_mode.hpp"
#include "sim/closed_loop_truth.hpp"
#include "sim/rng.hpp"
#include "sim/synthetic_source.hpp"
#include "sim/truth.hpp"
#include "slam/estimator.hpp"

namespace wingman::app {

namespace {



// NEES (eq. 67) over the agents' positions and velocities.
double agent_nees(const slam::FilterState& s, const Eigen::VectorXd& truth) {
  const int d = s.kinematic_dim();
  const Eigen::VectorXd e = truth - s.x.head(d);
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(s.P.topLeftCorner(d, d));
  if (ldlt.info() != Eigen::Success) return eval::kNaN;
  return e.dot(ldlt.solve(e));
}

// NEES of one 3-vector block of the state against its marginal covariance.
double block_nees(const slam::FilterState& s, int pos, const Eigen::Vector3d& truth) {
  const Eigen::Vector3d e = truth - s.x.segment<3>(pos);
  const Eigen::LDLT<Eigen::Matrix3d> ldlt(s.P.block<3, 3>(pos, pos));
  if (ldlt.info() != Eigen::Success) return eval::kNaN;
  return e.dot(ldlt.solve(e));
}

// What a closed loop adds to the open-loop step: bring the truth to t before anything is
// measured, and compute the commands from the updated estimate (filling the step's record).
struct LoopHooks {
  std::function<void(int k, double t)> advance;
  std::function<void(int k, double t, const slam::Estimator&, eval::StepRecord&)> control;
  // Dataset replay: frames and sensor samples from the dataset, not the renderer and the
  // synthetic source (a sample missing at step k is not fed).
  FrameSource frames;
  std::optional<vision::FeatureSettings> features;  // empty: the scenario's frontend section
  std::function<std::optional<Eigen::Vector3d>(int k)> gps;
  std::function<std::optional<double>(int k, int uav)> altimeter, range;
};

// Synthetic mode: every measurement from `source`. Rendered mode: the visual ones from rendered
// frames through the vision frontend, the others (GPS, altimeter, range) still from `source`.
eval::RunRecord run_loop(const RunConfig& scn, const sim::Truth& truth,
                         sim::SyntheticSource& source, const ProgressFn& progress,
                         const StateObserver& observer, const LoopHooks& hooks,
                         const RenderedOptions& ro) {
  const auto wall0 = Clock::now();
  const bool single = scn.single_uav();

  // Cameras in the filter, by UAV index: every UAV (multi) or only the baseline's (single).
  std::vector<int> cam_uav;
  if (single) {
    cam_uav.push_back(scn.uav_index(scn.estimator.single_uav));
  } else {
    for (int j = 0; j < static_cast<int>(scn.uavs.size()); ++j) cam_uav.push_back(j);
  }
  const int ncam = static_cast<int>(cam_uav.size());
  std::unique_ptr<RenderedFrontend> fe;
  // Open loop: step k+1's truth is known at step k, so its frames can render during step k.
  const bool prefetch = !scn.closed_loop() && ro.prefetch && !hooks.frames;
  if (hooks.frames)
    fe = std::make_unique<RenderedFrontend>(scn, cam_uav, hooks.frames, hooks.features);
  else if (scn.measurements == sim::MeasurementMode::Rendered) {
    // With the prefetch, detection keeps one core busy while the frames render: llvmpipe (Mesa's
    // software rasteriser, one thread per core by default) gets the others. 1.20x against 0.99x
    // real time on the paper scene on 2 cores (docs/results.md). LP_NUM_THREADS set by the user
    // wins; a GPU driver ignores it.
    if (prefetch) {
      const unsigned cores = std::max(2u, std::thread::hardware_concurrency());
      setenv("LP_NUM_THREADS", std::to_string(cores - 1).c_str(), /*overwrite=*/0);
    }
    fe = std::make_unique<RenderedFrontend>(scn, cam_uav, ro.gl);
  }
  if (fe && !ro.video.empty()) fe->open_video(ro.video);
  if (fe) fe->set_prefetch(prefetch);

  // The filter's initial estimate: the truth, or the truth plus a draw of the initial covariance.
  std::mt19937_64 init_rng = sim::make_stream(scn.seed, "initial_estimate");
  std::normal_distribution<double> unit(0.0, 1.0);
  auto initial_estimate = [&](const sim::KinematicState& k) {
    slam::AgentInit a{k.position, k.velocity};
    if (!scn.estimator.initial_sigma.draw) return a;
    a.position += sim::gaussian3(init_rng, unit, scn.estimator.initial_sigma.position);
    a.velocity += sim::gaussian3(init_rng, unit, scn.estimator.initial_sigma.velocity);
    return a;
  };
  std::vector<slam::CameraRig> rigs;
  std::vector<slam::AgentInit> cam_init;
  for (int u : cam_uav) {
    slam::CameraRig rig;
    rig.model = scn.uavs[u].camera.camera();
    rig.R_CW = truth.commanded_R_CW();
    rig.offset = scn.uavs[u].camera.offset;
    rig.orientation_sigma = scn.estimator.measurement_noise.orientation_sigma;
    rigs.push_back(rig);
    cam_init.push_back(initial_estimate(truth.camera(u, 0.0)));
  }
  const slam::AgentInit lead0 = initial_estimate(truth.lead(0.0));
  slam::Estimator est(rigs, lead0, cam_init, scn.estimator, scn.seed);

  eval::RunRecord rec;
  rec.scenario_path = scn.source_path;
  rec.scenario_name = scn.name;
  rec.variant = scn.variant;
  rec.estimator_mode = slam::to_string(scn.estimator.mode);
  rec.seed = scn.seed;
  rec.software_version = kVersion;
  rec.agent_names.push_back("lead");
  for (int u : cam_uav) rec.agent_names.push_back(scn.uavs[u].name);
  for (const auto& p : scn.phases)
    rec.phases.push_back({p.name, p.t_start, p.t_end, sim::to_string(p.config)});
  for (int u : cam_uav) rec.outliers.push_back({scn.uavs[u].name});
  if (!single) rec.outliers.push_back({"cooperative"});
  eval::OutlierCounts* coop = single ? nullptr : &rec.outliers.back();
  if (fe) {
    rec.frontend.enabled = true;
    rec.frontend.detector = fe->detector_name();
    rec.frontend.renderer = fe->renderer_description();
    rec.frontend.oracle_pixels = scn.frontend.oracle_pixels;
    rec.frontend.record_correspondences = ro.correspondences;
  }

  std::map<slam::LandmarkId, std::size_t> lm_record;  // filter id -> index in rec.landmarks
  const int target = scn.estimator.map.target_per_camera;

  auto record_step = [&](int k, double t, int visible, int offered, int accepted, int initialised,
                         double tp, double tu, double ti, double tr = 0, double td = 0,
                         double tm = 0) {
    eval::StepRecord st;
    st.k = k;
    st.t = t;
    st.phase = scn.phase_at(t);
    const auto& s = est.state();
    Eigen::VectorXd x_true(s.kinematic_dim());
    auto agent = [&](const sim::KinematicState& tr, int pos) {
      eval::AgentStep a;
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
    agent(truth.lead(t), slam::FilterState::lead_pos());
    for (int j = 0; j < ncam; ++j) agent(truth.camera(cam_uav[j], t), slam::FilterState::cam_pos(j));
    st.nees = k == 0 ? eval::kNaN : agent_nees(s, x_true);
    st.nees_dof = s.kinematic_dim();
    st.landmarks = est.num_landmarks();
    st.landmarks_visible = visible;
    st.matches_offered = offered;
    st.matches_accepted = accepted;
    st.initialised = initialised;
    st.t_predict_ms = tp;
    st.t_update_ms = tu;
    st.t_init_ms = ti;
    st.t_render_ms = tr;
    st.t_detect_ms = td;
    st.t_match_ms = tm;
    rec.steps.push_back(std::move(st));
  };
  // Latest estimate of every landmark in the map; a landmark removed later keeps its last one.
  auto snapshot_landmarks = [&](int phase) {
    for (const auto& slot : est.state().landmarks()) {
      auto it = lm_record.find(slot.id);
      if (it == lm_record.end()) continue;
      auto& lr = rec.landmarks[it->second];
      lr.est_final = est.state().landmark_position(slot);
      if (phase == lr.init_phase) lr.est_phase_end = lr.est_final;
    }
  };

  record_step(0, 0.0, 0, 0, 0, 0, 0, 0, 0);
  if (hooks.control) hooks.control(0, 0.0, est, rec.steps.back());
  const int N = scn.num_steps();
  const double dt = scn.dt();
  for (int k = 1; k <= N; ++k) {
    const double t = k * dt;
    const int phase = scn.phase_at(t);
    if (hooks.advance) hooks.advance(k, t);

    auto t0 = Clock::now();
    est.predict(dt);
    const double t_predict = ms_since(t0);
    double t_render = 0, t_detect = 0, t_match = 0;
    if (fe) {
      for (int j = 0; j < ncam; ++j) est.set_camera_rotation(j, truth.commanded_R_CW());
      const StageTimes st = fe->render_and_detect(truth, k, t, est, rec.frontend);
      // Stage times add up to the step's wall time: detection is what it added beyond rendering
      // (it overlaps the next camera's render); its full duration is kept in the frontend record.
      t_render = st.render_ms;
      t_detect = std::max(0.0, st.wall_ms - st.render_ms);
      rec.frontend.detect_busy_ms += st.detect_ms;
    }

    // Landmark correspondences for what the filter predicts in view, by identity.
    t0 = Clock::now();
    std::vector<slam::Correspondence> cands;
    std::vector<sim::PixelObservation> obs_all;
    std::vector<int> cand_channel;
    std::vector<LabelledCorrespondence> labelled;  // rendered mode, parallel to cands
    double t_track = 0;
    std::vector<int> in_view(ncam, 0);
    std::vector<bool> sees_landmarks(ncam, false);
    int visible = 0;
    for (int j = 0; j < ncam; ++j) {
      const auto& name = scn.uavs[cam_uav[j]].name;
      if (!scn.sensor_active(sim::Sensor::Landmarks, t, name)) continue;
      sees_landmarks[j] = true;
      est.set_camera_rotation(j, truth.commanded_R_CW());
      const auto preds = est.landmarks_in_view(j);
      in_view[j] = static_cast<int>(preds.size());
      visible += in_view[j];
      if (fe) {
        const auto tm0 = Clock::now();
        for (const auto& lc : fe->track(j, preds)) {
          cands.push_back(lc.c);
          labelled.push_back(lc);
          cand_channel.push_back(j);
        }
        t_track += ms_since(tm0);
        continue;
      }
      std::vector<std::int64_t> ids;
      for (const auto& p : preds) ids.push_back(p.id);
      for (const auto& o : source.observe_landmarks(cam_uav[j], t, ids)) {
        cands.push_back({j, o.landmark, o.uv});
        obs_all.push_back(o);
        cand_channel.push_back(j);
      }
    }
    std::vector<std::pair<int, Eigen::Vector2d>> lead_pixels;
    for (int j = 0; j < ncam; ++j)
      if (scn.sensor_active(sim::Sensor::LeadProjection, t, scn.uavs[cam_uav[j]].name))
        if (auto uv = fe ? fe->lead_pixel(j) : source.lead_pixel(cam_uav[j], t))
          lead_pixels.emplace_back(j, *uv);
    const auto vr = est.update_visual(cands, lead_pixels);
    int accepted = 0;
    for (size_t i = 0; i < cands.size(); ++i) {
      auto& oc = rec.outliers[cand_channel[i]];
      ++oc.correspondences;
      // Synthetic mode: an outlier is a correspondence the source corrupted (DESIGN.md §3);
      // rendered mode: one the ground-truth labels put > 3 px from the true projection (§7).
      const bool outlier = fe ? labelled[i].outlier : obs_all[i].injected_outlier;
      if (!fe && outlier) ++oc.injected;
      if (outlier) ++oc.outliers;
      if (fe && rec.frontend.record_correspondences) {
        const LabelledCorrespondence& lc = labelled[i];
        rec.frontend.correspondences.push_back(
            {k, t, lc.c.cam, lc.c.id, lc.c.uv, lc.true_uv, lc.outlier, bool(vr.accepted[i])});
      }
      if (vr.accepted[i]) {
        ++accepted;
        ++oc.accepted;
        if (outlier) ++oc.outliers_accepted;
        if (fe) {
          fe->accepted(labelled[i], k);
          rec.frontend.accepted_error_px.push_back(labelled[i].error_px);
        }
      }
    }

    slam::SensorBatch batch;
    if (scn.sensor_active(sim::Sensor::Gps, t, "lead")) {
      if (!hooks.gps)
        batch.gps = source.gps(t);
      else if (auto g = hooks.gps(k))
        batch.gps = *g;
    }
    for (int j = 0; j < ncam; ++j) {
      const int u = cam_uav[j];
      const auto& name = scn.uavs[u].name;
      if (scn.sensor_active(sim::Sensor::Altimeter, t, name)) {
        if (!hooks.altimeter)
          batch.altimeter.emplace_back(j, source.altimeter(u, t));
        else if (auto a = hooks.altimeter(k, u))
          batch.altimeter.emplace_back(j, *a);
      }
      if (scn.sensor_active(sim::Sensor::Range, t, name)) {
        if (!hooks.range)
          batch.range.emplace_back(j, source.range(u, t));
        else if (auto r = hooks.range(k, u))
          batch.range.emplace_back(j, *r);
      }
    }
    est.update_sensors(batch);
    const double t_update = ms_since(t0) - t_track;
    t_match += t_track;
    snapshot_landmarks(phase);

    // New landmarks where a camera sees fewer than the target.
    t0 = Clock::now();
    int initialised = 0;
    double t_cross = 0;
    // A new landmark's record for Table 5, with its truth.
    auto record_landmark = [&](slam::LandmarkId id, const Eigen::Vector3d& truth_point,
                               const char* origin) {
      eval::LandmarkRecord lr;
      lr.id = id;
      lr.truth = truth_point;
      lr.t_init = t;
      lr.init_phase = phase;
      lr.est_init = lr.est_phase_end = lr.est_final = *est.landmark_position(id);
      lr.origin = origin;
      lm_record[id] = rec.landmarks.size();
      rec.landmarks.push_back(lr);
    };
    // Rendered mode: the landmark's truth is the back-projection of its first observation.
    auto add_rendered = [&](slam::LandmarkId id, int cam, int keypoint, const Eigen::Vector2d& uv,
                            const char* origin) {
      ++initialised;
      const auto truth_point = fe->added(id, cam, keypoint, uv, k);
      if (!truth_point) return;  // no rendered surface there: left out of Table 5
      record_landmark(id, *truth_point, origin);
    };
    auto add_record = [&](slam::LandmarkId id, std::size_t point, const char* origin) {
      source.bind(id, point);
      record_landmark(id, source.field()[point], origin);
      ++initialised;
    };
    if (single) {
      const int need = target - in_view[0];
      if (fe && sees_landmarks[0] && need > 0) {
        const auto tm0 = Clock::now();
        const auto pts = fe->new_points(0, need);
        t_cross += ms_since(tm0);
        for (const auto& p : pts) {
          auto r = est.initialise_from_pixel(0, p.c.uv);
          if (r.id) add_rendered(*r.id, 0, p.keypoint, p.c.uv, "inverse_depth");
        }
      } else if (sees_landmarks[0] && need > 0)
        for (const auto& o : source.new_points(cam_uav[0], t, need)) {
          auto r = est.initialise_from_pixel(0, o.uv);
          if (r.id) add_record(*r.id, o.point, "inverse_depth");
        }
    } else {
      // Pair each camera with the next; a pair asks for the larger deficit of its two cameras.
      std::map<std::pair<int, int>, int> pairs;
      for (int j = 0; j < ncam; ++j) {
        const int o = (j + 1) % ncam;
        const int need = target - in_view[j];
        if (o == j || need <= 0 || !sees_landmarks[j] || !sees_landmarks[o]) continue;
        auto key = std::minmax(j, o);
        pairs[key] = std::max(pairs[key], need);
      }
      std::vector<int> added(ncam, 0);  // this step's cooperative landmarks, per camera
      for (const auto& [pr, need] : pairs) {
        if (fe) {
          const auto tm0 = Clock::now();
          const auto pairs_found = fe->cross_match(pr.first, pr.second, need, est);
          t_cross += ms_since(tm0);
          std::vector<slam::CrossMatch> cm;
          for (const auto& p : pairs_found) cm.push_back(p.m);
          const auto outcomes = est.initialise_from_matches(cm);
          for (size_t i = 0; i < pairs_found.size(); ++i) {
            ++coop->correspondences;
            if (pairs_found[i].outlier) ++coop->outliers;
            if (!outcomes[i].id) continue;
            ++coop->accepted;
            if (pairs_found[i].outlier) ++coop->outliers_accepted;
            add_rendered(*outcomes[i].id, pr.first, pairs_found[i].keypoint_a, pairs_found[i].m.uv_a,
                         "cooperative");
            ++added[pr.first], ++added[pr.second];
          }
          continue;
        }
        const auto matches = source.cross_matches(cam_uav[pr.first], cam_uav[pr.second], t, need);
        std::vector<slam::CrossMatch> cm;
        for (const auto& m : matches) cm.push_back({pr.first, pr.second, m.uv_a, m.uv_b});
        const auto outcomes = est.initialise_from_matches(cm);
        for (size_t i = 0; i < matches.size(); ++i) {
          ++coop->correspondences;
          if (matches[i].injected_outlier) ++coop->injected, ++coop->outliers;
          if (!outcomes[i].id) continue;
          ++coop->accepted;
          if (matches[i].injected_outlier) ++coop->outliers_accepted;
          add_record(*outcomes[i].id, matches[i].point, "cooperative");
          ++added[pr.first], ++added[pr.second];
        }
      }
      // The cameras cooperative matching left short fill up on their own, in inverse depth.
      for (int j = 0; j < ncam && scn.estimator.initialisation.monocular_fill; ++j) {
        const int need = target - in_view[j] - added[j];
        if (!sees_landmarks[j] || need <= 0) continue;
        if (fe) {
          const auto tm0 = Clock::now();
          const auto pts = fe->new_points(j, need);
          t_cross += ms_since(tm0);
          for (const auto& p : pts)
            if (auto r = est.initialise_from_pixel(j, p.c.uv); r.id)
              add_rendered(*r.id, j, p.keypoint, p.c.uv, "inverse_depth");
        } else
          for (const auto& o : source.new_points(cam_uav[j], t, need))
            if (auto r = est.initialise_from_pixel(j, o.uv); r.id) add_record(*r.id, o.point, "inverse_depth");
      }
    }
    for (slam::LandmarkId id : est.end_step()) {
      source.unbind(id);
      if (fe) fe->removed(id);
      if (auto it = lm_record.find(id); it != lm_record.end()) rec.landmarks[it->second].t_removed = t;
    }
    const double t_init = ms_since(t0) - t_cross;
    if (fe) fe->write_video_frame(t);
    t_match += t_cross;

    record_step(k, t, visible, static_cast<int>(cands.size()), accepted, initialised, t_predict,
                t_update, t_init, t_render, t_detect, t_match);
    if (hooks.control) hooks.control(k, t, est, rec.steps.back());
    if (observer) observer(k, est.state());
    if (progress) progress(k, N);
  }
  rec.wall_time_s = std::chrono::duration<double>(Clock::now() - wall0).count();
  return rec;
}


// Section 7.3: the estimator's positions and the AHRS yaw feed one sliding-mode controller per
// UAV; its command, plus Delta_g (eq. 58), drives eq. 53 until the next step (ZOH, Fig. 7).
std::string fmt_missing(const datasets::Dataset& ds, const std::string& agent, int needed) {
  return ds.root.string() + "/" + agent + ": fewer frames or camera poses than the " +
         std::to_string(needed) + " steps to replay";
}

eval::RunRecord run_closed_loop(const RunConfig& scn, const ProgressFn& progress,
                                const StateObserver& observer, const RenderedOptions& ro) {
  if (scn.single_uav())
    throw std::invalid_argument("closed loop needs the multi-UAV estimator");
  sim::ClosedLoopTruth truth(scn);
  sim::SyntheticSource source(scn, truth);
  const int n = static_cast<int>(scn.uavs.size());
  const sim::InputDisturbance disturbance(scn.control.disturbance_bound, n,
                                          scn.control.disturbance_seed.value_or(scn.seed));
  std::vector<control::FormationController> ctrl;
  std::vector<control::UavPose> pose;
  for (int j = 0; j < n; ++j) {
    const auto& name = scn.uavs[j].name;
    const auto it = std::find_if(scn.control.uavs.begin(), scn.control.uavs.end(),
                                 [&](const sim::UavControlSpec& c) { return c.uav == name; });
    if (it == scn.control.uavs.end()) throw std::invalid_argument("no control entry for " + name);
    ctrl.emplace_back(control::DesiredFormation{it->lambda_d, it->yaw_d},
                      scn.controller, scn.uavs[j].camera.offset);
    pose.push_back({scn.uavs[j].initial_position, it->initial_yaw});
  }
  std::vector<control::BodyVelocity> cmd(n);
  const double dt = scn.dt();
  constexpr int kSubsteps = 10;  // Delta_g varies within a step; the command does not (ZOH)

  LoopHooks hooks;
  hooks.advance = [&](int, double t) {
    const double h = dt / kSubsteps;
    for (int j = 0; j < n; ++j) {
      control::UavPose q = pose[j];
      const double t0 = t - dt;
      for (int i = 0; i < kSubsteps; ++i) {
        const Eigen::Vector4d u = control::input_vector(cmd[j]) + disturbance(j, t0 + (i + 0.5) * h);
        q = control::propagate(q, control::body_velocity(u), h);
      }
      const Eigen::Vector3d v = (q.position - pose[j].position) / dt;
      pose[j] = q;
      truth.set_uav(j, q.position, v, q.yaw);
    }
    truth.set_time(t);
  };
  hooks.control = [&](int k, double t, const slam::Estimator& est, eval::StepRecord& st) {
    const auto lead = truth.lead(t);
    for (int j = 0; j < n; ++j) {
      control::ControllerInput in;
      in.lead_position = est.lead_position();
      in.lead_velocity = est.lead_velocity();
      in.camera_position = est.camera_position(j);
      in.yaw = source.ahrs_yaw(j, t);
      const auto out = ctrl[j].update(in, k == 0 ? 0.0 : dt);
      cmd[j] = out.command;
      eval::FormationStep f;
      f.position_true = pose[j].position;
      f.yaw_true = pose[j].yaw;
      f.yaw_ahrs = in.yaw;
      f.lambda_est = out.lambda;
      f.lambda_d_est = out.lambda_d;
      f.surface = out.surface;
      f.command = {cmd[j].vx, cmd[j].vy, cmd[j].vz, cmd[j].omega};
      f.limited = out.limited;
      f.lambda_true = control::formation_variables(lead.position, pose[j]);
      // The formation the truth asked for: the same lambda_d with psi_d from the true lead
      // (the controller's held psi_d while the bearing is undefined near the origin).
      f.lambda_d_true = out.lambda_d;
      const auto& d = ctrl[j].desired();
      if (d.yaw)
        f.lambda_d_true(3) = *d.yaw;
      else if (lead.position.head<2>().norm() >= scn.controller.lead_bearing_min_range)
        f.lambda_d_true(3) = control::FormationController::lead_bearing(lead.position, lead.velocity)(0);
      st.formation.push_back(f);
    }
  };

  eval::RunRecord rec = run_loop(scn, truth, source, progress, observer, hooks, ro);
  rec.closed_loop = true;
  for (const auto& u : scn.uavs) rec.formation_uavs.push_back(u.name);
  rec.settling_time = scn.control.settling_time;
  return rec;
}

eval::RunRecord run_open_loop(const RunConfig& scn, const ProgressFn& progress,
                              const StateObserver& observer, const RenderedOptions& ro) {
  const sim::OpenLoopTruth truth(scn);
  sim::SyntheticSource source(scn, truth);
  return run_loop(scn, truth, source, progress, observer, {}, ro);
}

}  // namespace

eval::RunRecord run_replay(const RunConfig& scn, const datasets::Dataset& ds,
                           const ProgressFn& progress,
                           const std::optional<vision::FeatureSettings>& features,
                           bool correspondences) {
  if (scn.closed_loop())
    throw std::invalid_argument(ds.root.string() +
                                ": a dataset holds an open-loop flight; its scenario has a control: section");
  const sim::OpenLoopTruth truth(scn);
  sim::SyntheticSource source(scn, truth);  // unused for measurements: everything is replayed
  const int n = static_cast<int>(scn.uavs.size());
  std::vector<const datasets::AgentData*> agent(n);
  for (int u = 0; u < n; ++u) agent[u] = &ds.agent(scn.uavs[u].name);  // throws naming the file
  const auto& lead = ds.agent("lead");
  const int steps = scn.num_steps();
  for (int u = 0; u < n; ++u) {
    const auto& a = *agent[u];
    if (static_cast<int>(a.frames.size()) < steps + 1 ||
        static_cast<int>(a.camera_pose.size()) < steps + 1)
      throw std::invalid_argument(fmt_missing(ds, a.name, steps + 1));
    // The frontend labels against the scenario's truth: it must be the truth the frames show.
    for (int k : {0, steps / 2, steps}) {
      const Eigen::Vector3d d = a.camera_pose[k].p - truth.camera(u, k * scn.dt()).position;
      if (d.norm() > 1e-3)
        throw std::invalid_argument(ds.root.string() + "/" + a.name +
                                    "/groundtruth/cam0.csv: camera positions differ from the truth "
                                    "of the dataset's scenario.yaml (" +
                                    std::to_string(d.norm()) + " m at step " + std::to_string(k) + ")");
    }
  }
  // Filter camera index -> UAV index, as run_loop numbers them.
  std::vector<int> cam_uav;
  if (scn.single_uav())
    cam_uav.push_back(scn.uav_index(scn.estimator.single_uav));
  else
    for (int u = 0; u < n; ++u) cam_uav.push_back(u);

  auto at = [&](const auto& samples, int k) -> const auto* {
    const std::int64_t t_ns = datasets::step_ns(k, scn.rate);
    auto it = std::lower_bound(samples.begin(), samples.end(), t_ns,
                               [](const auto& s, std::int64_t v) { return s.t_ns < v; });
    return it != samples.end() && it->t_ns == t_ns ? &*it : nullptr;
  };
  LoopHooks hooks;
  hooks.features = features;
  hooks.frames = [&](int cam, int k) {
    const auto& a = *agent[cam_uav[cam]];
    render::Frame f;
    cv::Mat img = ds.load_image(a.name, a.frames[k]);
    if (img.channels() == 1) cv::cvtColor(img, img, cv::COLOR_GRAY2RGB);
    f.rgb = img;
    f.depth = ds.load_depth(a.name, a.frames[k]);
    return f;
  };
  hooks.gps = [&](int k) -> std::optional<Eigen::Vector3d> {
    if (const auto* s = at(lead.gps, k)) return s->value;
    return std::nullopt;
  };
  hooks.altimeter = [&](int k, int u) -> std::optional<double> {
    if (const auto* s = at(agent[u]->altimeter, k)) return s->value;
    return std::nullopt;
  };
  hooks.range = [&](int k, int u) -> std::optional<double> {
    if (const auto* s = at(agent[u]->range, k)) return s->value;
    return std::nullopt;
  };
  RenderedOptions ro;
  ro.correspondences = correspondences;
  return run_loop(scn, truth, source, progress, {}, hooks, ro);
}

eval::RunRecord run_scenario(const RunConfig& scn, const RenderedOptions& ro,
                             const ProgressFn& progress, const StateObserver& observer) {
  return scn.closed_loop() ? run_closed_loop(scn, progress, observer, ro)
                           : run_open_loop(scn, progress, observer, ro);
}

eval::RunRecord run_synthetic(const RunConfig& scn, const ProgressFn& progress,
                              const StateObserver& observer) {
  return run_scenario(scn, RenderedOptions{}, progress, observer);
}

}  // namespace wingman::app
