#include "app/rendered_frontend.hpp"
#include "app/timing.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <future>
#include <numeric>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "render/effects.hpp"
#include "render/scene.hpp"

namespace wingman::app {

namespace {


vision::LeadDetectorSettings lead_settings(const RunConfig& scn) {
  vision::LeadDetectorSettings s;
  switch (scn.world.lead.cue) {
    case sim::LeadModelSpec::Cue::Aruco:
      s.method = vision::LeadMethod::Marker;
      s.marker_id = scn.world.lead.aruco_id;
      break;
    case sim::LeadModelSpec::Cue::Panel:
      s.method = vision::LeadMethod::Colour;
      break;
    case sim::LeadModelSpec::Cue::None:
      throw std::invalid_argument(scn.source_path +
                                  ": world.lead.cue: none leaves the lead detector nothing to find "
                                  "(rendered measurements need aruco or panel)");
  }
  return s;
}

// Box kept free of map features around the lead: its detection, or else its predicted pixel,
// sized for the model's footprint at the camera's height (the model moves: features on it would
// make landmarks that drift).
vision::ExclusionBox predicted_lead_box(const Eigen::Vector2d& uv, double fx, double depth,
                                        const RunConfig& scn) {
  const double half = std::max(20.0, 0.5 * 2.0 * scn.world.lead.height * fx / std::max(depth, 1.0));
  return {uv, half, half};
}

std::string fmt_label(const std::string& name, double t) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%s  t = %.1f s", name.c_str(), t);
  return buf;
}

}  // namespace

vision::CrossMatchSettings cross_match_settings(const RunConfig& cfg) {
  vision::CrossMatchSettings c = cfg.frontend.cross_matching;
  // Unless it turns them into inverse-depth landmarks, the estimator rejects pairs under its
  // minimum parallax; filtering them before the spread selection then lets it pick among pairs
  // that can be initialised (with a 3 m baseline, most of the image's outer cells are under 8
  // degrees and would be chosen, and rejected, every step).
  const auto& init = cfg.estimator.initialisation;
  c.min_parallax_deg = init.low_parallax_inverse_depth ? 0.0 : init.min_parallax_deg;
  c.validate();
  return c;
}

RenderedFrontend::RenderedFrontend(const RunConfig& scn, std::vector<int> cam_uav,
                                   render::GlBackend backend)
    : scn_(scn),
      cam_uav_(std::move(cam_uav)),
      features_(scn.frontend.features),
      lead_(lead_settings(scn)) {
  render::Scene scene;
  try {
    scene = render::build_scene(scn);
  } catch (const std::runtime_error& e) {  // a missing or broken asset: the scenario's fault
    throw std::invalid_argument(scn.source_path + ": world: " + e.what());
  }
  ctx_ = render::create_gl_context(backend);
  renderer_ = std::make_unique<render::Renderer>(*ctx_, scene);
  init_cameras();
  for (int u : cam_uav_)
    effects_.push_back(
        std::make_unique<render::ImageEffects>(scn.world.image, scn.seed, scn.uavs[u].name));
}

RenderedFrontend::RenderedFrontend(const RunConfig& scn, std::vector<int> cam_uav,
                                   FrameSource frames,
                                   const std::optional<vision::FeatureSettings>& features)
    : scn_(scn),
      cam_uav_(std::move(cam_uav)),
      frames_(std::move(frames)),
      features_(features ? *features : scn.frontend.features),
      lead_(lead_settings(scn)) {
  init_cameras();
}

void RenderedFrontend::init_cameras() {
  colour_lead_ = lead_.settings().method != vision::LeadMethod::Marker;
  tracking_ = scn_.frontend.tracking;
  tracking_.validate();
  cross_ = cross_match_settings(scn_);
  for (int u : cam_uav_) {
    Cam c;
    c.model = scn_.uavs[u].camera.camera();
    cams_.push_back(std::move(c));
  }
}

RenderedFrontend::~RenderedFrontend() = default;

std::string RenderedFrontend::renderer_description() const {
  return ctx_ ? ctx_->description() : std::string("dataset replay");
}

render::LeadPose RenderedFrontend::true_lead_pose(const sim::Truth& truth, double t) const {
  render::LeadPose lead = render::lead_pose(scn_, t);
  lead.position = truth.lead(t).position;
  return lead;
}

void RenderedFrontend::render_camera(const sim::Truth& truth, int j, double t,
                                     const render::LeadPose& lead, render::Frame& frame,
                                     vision::CameraPose& pose) {
  const int u = cam_uav_[j];
  pose = {truth.camera_R_CW(u, t), truth.camera(u, t).position};
  frame = renderer_->render({cams_[j].model, pose.R_CW, pose.position}, lead);
  effects_[j]->apply(frame);
}

StageTimes RenderedFrontend::render_and_detect(const sim::Truth& truth, int k, double t,
                                               const slam::Estimator& est,
                                               eval::FrontendRecord& fr) {
  StageTimes st;
  const auto t_start = Clock::now();
  const render::LeadPose lead = true_lead_pose(truth, t);
  const int n = static_cast<int>(cams_.size());
  const bool ahead = prefetch_ && k < scn_.num_steps();
  const bool have = next_.k == k;  // rendered during the previous step
  if (have) {
    for (int j = 0; j < n; ++j) {
      cams_[j].frame = std::move(next_.frames[j]);
      cams_[j].true_pose = next_.poses[j];
    }
    next_.k = -1;
  } else if (ahead) {
    const auto t0 = Clock::now();
    for (int j = 0; j < n; ++j) render_camera(truth, j, t, lead, cams_[j].frame, cams_[j].true_pose);
    st.render_ms += ms_since(t0);
  }

  if (have && !ahead) {  // the last step: nothing left to render
    for (int j = 0; j < n; ++j) st.detect_ms += detect_camera(j, est);
  } else if (ahead) {
    // Step k's detection (both cameras, one after the other: the extractor is not shared) on a
    // second thread while this one, which holds the GL context, renders step k+1.
    auto detection = std::async(std::launch::async, [this, n, &est] {
      double ms = 0;
      for (int j = 0; j < n; ++j) ms += detect_camera(j, est);
      return ms;
    });
    const auto t0 = Clock::now();
    const double t1 = (k + 1) * scn_.dt();
    const render::LeadPose lead1 = true_lead_pose(truth, t1);
    next_.frames.resize(n);
    next_.poses.resize(n);
    for (int j = 0; j < n; ++j) render_camera(truth, j, t1, lead1, next_.frames[j], next_.poses[j]);
    next_.k = k + 1;
    st.render_ms += ms_since(t0);
    st.detect_ms += detection.get();
  } else {
    // Camera j's detection runs on a second thread while camera j+1 renders (the GL context
    // stays on this thread; two detections never run at once, so the extractor is never shared).
    std::future<double> pending;
    for (int j = 0; j < n; ++j) {
      Cam& c = cams_[j];
      const auto t0 = Clock::now();
      if (frames_) {
        c.true_pose = {truth.camera_R_CW(cam_uav_[j], t), truth.camera(cam_uav_[j], t).position};
        c.frame = frames_(j, k);
      } else {
        render_camera(truth, j, t, lead, c.frame, c.true_pose);
      }
      st.render_ms += ms_since(t0);
      if (pending.valid()) st.detect_ms += pending.get();
      pending = std::async(std::launch::async, [this, j, &est] { return detect_camera(j, est); });
    }
    if (pending.valid()) st.detect_ms += pending.get();
  }
  st.wall_ms = ms_since(t_start);

  // Tallies against the truth (evaluation only): in view when the reference point projects
  // inside the image with room for the marker and the rendered depth there is the lead's.
  for (auto& c : cams_) {
    ++fr.frames;
    const Eigen::Vector3d p_true = c.true_pose.to_camera(lead.position);
    const auto uv_true = c.model.project(p_true);
    bool in_view = false;
    if (uv_true && c.model.in_image(*uv_true, 15)) {
      const auto d = vision::sample_depth(c.frame.depth, *uv_true);
      in_view = d && std::abs(*d - p_true.z()) < 0.3;
    }
    if (in_view) ++fr.lead_in_view;
    if (c.lead) {
      const double err = in_view ? (*c.lead - *uv_true).norm() : INFINITY;
      if (err <= fr.lead_match_px) {
        ++fr.lead_detected;
        fr.lead_error_px.push_back(err);
        if (scn_.frontend.oracle_pixels) c.lead = *uv_true;
      } else {
        ++fr.lead_false;
      }
    }
  }
  return st;
}

double RenderedFrontend::detect_camera(int j, const slam::Estimator& est) {
  Cam& c = cams_[j];
  // Where the estimate puts the lead in this image (estimated camera, commanded orientation).
  const Eigen::Vector3d p_est = est.camera(j).R_CW * (est.lead_position() - est.camera_position(j));
  std::optional<Eigen::Vector2d> predicted = c.model.project(p_est);
  if (predicted && !c.model.in_image(*predicted, -100)) predicted.reset();

  const auto t0 = Clock::now();
  const cv::Mat grey = c.frame.gray();
  cv::Mat bgr;
  if (colour_lead_) cv::cvtColor(c.frame.rgb, bgr, cv::COLOR_RGB2BGR);
  const auto det = lead_.detect(colour_lead_ ? bgr : grey, predicted);
  c.lead.reset();
  std::vector<vision::ExclusionBox> exclude;
  if (det) {
    c.lead = det->uv;
    exclude.push_back(vision::exclusion_box(*det));
  } else if (predicted) {
    exclude.push_back(predicted_lead_box(*predicted, c.model.fx(), p_est.z(), scn_));
  }
  c.features = features_.detect(grey, exclude);
  const double ms = ms_since(t0);
  c.tracked.clear();
  c.accepted.clear();
  c.fresh.clear();
  c.preds.clear();  // a camera whose landmarks are switched off tracks nothing this step
  c.used.assign(c.features.size(), false);
  return ms;
}

std::vector<LabelledCorrespondence> RenderedFrontend::track(
    int cam, const std::vector<slam::LandmarkPrediction>& preds) {
  Cam& c = cams_[cam];
  c.preds.clear();
  for (const auto& p : preds) c.preds.push_back({p.id, p.uv, p.S});
  const auto tr = vision::track_landmarks(c.preds, c.features, store_, tracking_);
  c.used = tr.keypoint_used;
  std::vector<LabelledCorrespondence> out;
  for (const auto& tc : tr.candidates) {
    LabelledCorrespondence lc;
    lc.c = {cam, tc.id, tc.uv};
    lc.keypoint = tc.keypoint;
    c.tracked.push_back(tc.uv);
    const auto it = truth_.find(tc.id);
    // No truth (no rendered surface where it was first seen): counted as an outlier.
    lc.outlier = true;
    if (it != truth_.end() && it->second) {
      const auto lr = vision::label_landmark_observation(*it->second, tc.uv, c.model, c.true_pose,
                                                         c.frame.depth);
      lc.outlier = lr.label != vision::Label::Inlier;
      lc.error_px = lr.reprojection_px;
      if (lr.true_uv) lc.true_uv = *lr.true_uv;
      if (scn_.frontend.oracle_pixels && !lc.outlier) {  // an inlier has a true projection
        lc.c.uv = *lr.true_uv;
        lc.error_px = 0;
      }
    }
    out.push_back(lc);
  }
  return out;
}

void RenderedFrontend::accepted(const LabelledCorrespondence& lc, std::int64_t frame) {
  Cam& c = cams_[lc.c.cam];
  c.accepted.push_back(lc.c.uv);
  store_.observe(lc.c.id, c.features.descriptors.row(lc.keypoint), frame);
}

std::vector<LabelledPair> RenderedFrontend::cross_match(int cam_a, int cam_b, int needed,
                                                        const slam::Estimator& est) {
  Cam& a = cams_[cam_a];
  Cam& b = cams_[cam_b];
  const auto free_a = vision::free_keypoints(a.features, a.used, a.preds);
  const auto free_b = vision::free_keypoints(b.features, b.used, b.preds);
  const vision::CameraView va{a.model, {est.camera(cam_a).R_CW, est.camera_position(cam_a)}};
  const vision::CameraView vb{b.model, {est.camera(cam_b).R_CW, est.camera_position(cam_b)}};
  const auto res = vision::match_across(a.features, free_a, va, b.features, free_b, vb, cross_);
  std::vector<Eigen::Vector2d> ex_a, ex_b;
  for (const auto& p : a.preds) ex_a.push_back(p.uv);
  for (const auto& p : b.preds) ex_b.push_back(p.uv);
  const auto chosen = vision::select_spread(res.matches, needed, a.model, ex_a, b.model, ex_b);
  std::vector<LabelledPair> out;
  for (const auto& m : chosen) {
    LabelledPair lp;
    lp.m = {cam_a, cam_b, m.uv_a, m.uv_b};
    lp.keypoint_a = m.keypoint_a;
    // Taken: a camera that then fills its own deficit (new_points) must not pick them again.
    a.used[m.keypoint_a] = true;
    b.used[m.keypoint_b] = true;
    a.fresh.push_back(m.uv_a);
    b.fresh.push_back(m.uv_b);
    const auto lr = vision::label_pixel_pair(m.uv_a, a.model, a.true_pose, a.frame.depth, m.uv_b,
                                             b.model, b.true_pose, b.frame.depth);
    lp.outlier = lr.label != vision::Label::Inlier;
    // Camera a's pixel defines the landmark's truth (added()), so only b's is replaced.
    if (scn_.frontend.oracle_pixels && !lp.outlier) lp.m.uv_b = *lr.true_uv;
    out.push_back(lp);
  }
  return out;
}

std::vector<LabelledCorrespondence> RenderedFrontend::new_points(int cam, int needed) {
  Cam& c = cams_[cam];
  auto free = vision::free_keypoints(c.features, c.used, c.preds);
  // Strongest corners first; select_spread with the same camera twice spreads single pixels.
  std::stable_sort(free.begin(), free.end(), [&](int x, int y) {
    return c.features.keypoints[x].response > c.features.keypoints[y].response;
  });
  std::vector<vision::CrossMatchCandidate> cand;
  for (int i : free) {
    vision::CrossMatchCandidate m;
    m.keypoint_a = m.keypoint_b = i;
    m.uv_a = m.uv_b = c.features.pixel(i);
    cand.push_back(m);
  }
  // Spread away from the landmarks in view and from this step's cooperative ones.
  std::vector<Eigen::Vector2d> existing = c.fresh;
  for (const auto& p : c.preds) existing.push_back(p.uv);
  std::vector<LabelledCorrespondence> out;
  for (const auto& m : vision::select_spread(cand, needed, c.model, existing, c.model, existing)) {
    LabelledCorrespondence lc;
    lc.c = {cam, -1, m.uv_a};
    lc.keypoint = m.keypoint_a;
    c.fresh.push_back(m.uv_a);
    out.push_back(lc);
  }
  return out;
}

std::optional<Eigen::Vector3d> RenderedFrontend::added(slam::LandmarkId id, int cam, int keypoint,
                                                       const Eigen::Vector2d& uv,
                                                       std::int64_t frame) {
  const Cam& c = cams_[cam];
  store_.add(id, c.features.descriptors.row(keypoint), frame);
  auto truth = vision::back_project(uv, c.model, c.true_pose, c.frame.depth);
  truth_[id] = truth;
  return truth;
}

void RenderedFrontend::open_video(const std::string& path) {
  video_path_ = path;
  int w = 0, h = 0;
  for (const auto& c : cams_) {
    w += c.model.width() / 2;
    h = std::max(h, c.model.height() / 2);
  }
  video_ = std::make_unique<cv::VideoWriter>(path, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'),
                                             scn_.rate, cv::Size(w, h));
  if (!video_->isOpened())
    throw std::invalid_argument(path + ": cannot write a video there (MJPG in AVI)");
}

void RenderedFrontend::write_video_frame(double t) {
  if (!video_) return;
  std::vector<cv::Mat> tiles;
  int h = 0;
  for (const auto& c : cams_) h = std::max(h, c.model.height() / 2);
  for (std::size_t j = 0; j < cams_.size(); ++j) {
    const Cam& c = cams_[j];
    cv::Mat bgr;
    cv::cvtColor(c.frame.rgb, bgr, cv::COLOR_RGB2BGR);
    cv::resize(bgr, bgr, cv::Size(c.model.width() / 2, c.model.height() / 2), 0, 0, cv::INTER_AREA);
    auto pt = [](const Eigen::Vector2d& uv) { return cv::Point2d(uv.x() / 2, uv.y() / 2); };
    for (const auto& uv : c.tracked) cv::circle(bgr, pt(uv), 4, {0, 0, 255}, 1, cv::LINE_AA);
    for (const auto& uv : c.accepted) cv::circle(bgr, pt(uv), 4, {0, 200, 0}, 2, cv::LINE_AA);
    for (const auto& uv : c.fresh) cv::drawMarker(bgr, pt(uv), {0, 230, 255}, cv::MARKER_CROSS, 9, 2);
    if (c.lead) cv::circle(bgr, pt(*c.lead), 12, {255, 0, 255}, 2, cv::LINE_AA);
    cv::putText(bgr, fmt_label(scn_.uavs[cam_uav_[j]].name, t), {8, 22}, cv::FONT_HERSHEY_SIMPLEX,
                0.6, {255, 255, 255}, 2, cv::LINE_AA);
    if (bgr.rows < h) cv::copyMakeBorder(bgr, bgr, 0, h - bgr.rows, 0, 0, cv::BORDER_CONSTANT);
    tiles.push_back(bgr);
  }
  cv::Mat out;
  cv::hconcat(tiles, out);
  video_->write(out);
}

void RenderedFrontend::removed(slam::LandmarkId id) {
  store_.remove(id);
  truth_.erase(id);
}

}  // namespace wingman::app
