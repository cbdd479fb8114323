#include "app/frontend/vision_frontend.hpp"

#include <algorithm>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "io/timing.hpp"

namespace wingman::app {

namespace {

// Box kept free of map features around the lead: its detection, or else its predicted pixel,
// sized for the model's footprint at the camera's height (the model moves: features on it would
// make landmarks that drift).
vision::ExclusionBox predicted_lead_box(const Eigen::Vector2d& uv, double fx, double depth,
                                        const RunConfig& cfg) {
  const double half = std::max(20.0, 0.5 * 2.0 * cfg.world.lead.height * fx / std::max(depth, 1.0));
  return {uv, half, half};
}

}  // namespace

std::unique_ptr<vision::LeadFinder> make_lead_finder(const RunConfig& cfg, vision::LeadDetectorKind kind,
                                                     const std::string& weights,
                                                     const vision::LearnedLeadSettings& learned) {
  using K = vision::LeadDetectorKind;
  if (kind == K::Auto) kind = lead_detector(cfg);
  if (kind == K::Motion) return std::make_unique<vision::MotionLeadDetector>(cfg.frontend.motion_lead.search);
  if (kind == K::Learned) {
    if (weights.empty()) throw std::invalid_argument(cfg.source_path + ": the learned lead detector has no weights file");
    return std::make_unique<vision::LearnedLeadDetector>(weights, learned);
  }
  vision::LeadDetectorSettings s;
  s.method = kind == K::Panel ? vision::LeadMethod::Colour : vision::LeadMethod::Marker;
  s.marker_id = cfg.world.lead.aruco_id;
  return std::make_unique<vision::LeadDetector>(s);
}

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

VisionFrontend::VisionFrontend(const RunConfig& cfg, const std::vector<int>& cam_uav,
                               const std::optional<vision::FeatureSettings>& features)
    : cfg_(cfg),
      features_(features ? *features : cfg.frontend.features),
      tracking_(cfg.frontend.tracking),
      cross_(cross_match_settings(cfg)) {
  tracking_.validate();
  colour_lead_ = lead_detector(cfg) == vision::LeadDetectorKind::Panel;
  for (int u : cam_uav) {
    Cam c;
    c.model = cfg.uavs[u].camera.camera();
    c.lead_finder = make_lead_finder(cfg, lead_detector(cfg), cfg.lead_weights_path, cfg.frontend.learned_lead.search);
    cams_.push_back(std::move(c));
  }
}

std::optional<std::vector<cv::Rect>> VisionFrontend::reads(int cam, const CameraPlan& plan) const {
  const Cam& c = cams_[cam];
  if (!plan.search || plan.search->whole_frame || !plan.lead || colour_lead_) return std::nullopt;
  const auto window = c.lead_finder->window({c.model.width(), c.model.height()}, *plan.lead);
  if (!window) return std::nullopt;
  const int m = features_.crop_margin();
  std::vector<cv::Rect> out{*window};
  for (const cv::Rect& r : plan.search->regions) out.emplace_back(r.x - m, r.y - m, r.width + 2 * m, r.height + 2 * m);
  return out;
}

std::vector<std::optional<std::vector<cv::Rect>>> VisionFrontend::reads_for(const slam::Estimator& est) const {
  const auto plans = make_plans(est);
  std::vector<std::optional<std::vector<cv::Rect>>> out;
  for (int j = 0; j < num_cameras(); ++j) out.push_back(reads(j, plans[j]));
  return out;
}

double VisionFrontend::detect(int cam, const render::Frame& frame, bool partial) {
  Cam& c = cams_[cam];
  const auto t0 = io::Clock::now();
  const cv::Mat grey = frame.gray();
  cv::Mat bgr;
  if (colour_lead_) cv::cvtColor(frame.rgb, bgr, cv::COLOR_RGB2BGR);
  c.needs_whole_frame = false;
  std::optional<vision::LeadDetection> det;
  const CameraPlan& plan = c.plan;
  if (partial) {
    det = c.lead_finder->detect_in_window(grey, *plan.lead);
    c.needs_whole_frame = !det;
  } else {
    det = c.lead_finder->detect(colour_lead_ ? bgr : grey, plan.lead);
  }
  c.lead.reset();
  c.marks = {};
  c.preds.clear();  // a camera whose landmarks are switched off tracks nothing this step
  c.features = {};
  if (!c.needs_whole_frame) {
    std::vector<vision::ExclusionBox> exclude;
    if (det) {
      c.lead = det->uv;
      // A detection without a size (the learned detector's point) keeps the model's footprint free.
      exclude.push_back(det->size_px > 0 ? vision::exclusion_box(*det)
                                         : predicted_lead_box(det->uv, c.model.fx(), plan.lead_depth, cfg_));
    } else if (plan.lead) {
      exclude.push_back(predicted_lead_box(*plan.lead, c.model.fx(), plan.lead_depth, cfg_));
    }
    c.features = detect_features(cam, grey, exclude);
  }
  c.used.assign(c.features.size(), false);
  return io::ms_since(t0);
}

namespace {

std::vector<vision::LandmarkPrediction> predictions(const slam::Estimator& est, int cam) {
  std::vector<vision::LandmarkPrediction> out;
  for (const auto& p : est.predictions_in_view(cam)) out.push_back({p.id, p.uv, p.S});
  return out;
}

// The ground's height under the camera these predictions are of: the mean of their landmarks' estimates,
// else the lead's.
double ground_height(const slam::Estimator& est, const std::vector<vision::LandmarkPrediction>& preds) {
  double sum = 0;
  int n = 0;
  for (const auto& p : preds)
    if (auto x = est.landmark_position(p.id)) sum += x->z(), ++n;
  return n > 0 ? sum / n : est.lead_position().z();
}

}  // namespace

// Camera `from`'s blocks as camera `to` sees them: each block's corners and edge midpoints met
// with the ground's plane at the estimate, projected into `to`, boxed, and grown by a margin for
// the relief and the estimate's error (a 3 m baseline at 15 m moves a point 1 m off the plane by
// about 3 px).
std::vector<cv::Rect> VisionFrontend::carry_blocks(const std::vector<cv::Rect>& blocks, int from, int to,
                                                   double ground_z, const slam::Estimator& est) const {
  constexpr double kSlackPx = 20;
  const Eigen::Matrix3d& R_from = est.camera(from).R_CW;
  const Eigen::Vector3d p_from = est.camera_position(from), p_to = est.camera_position(to);
  std::vector<cv::Rect> out;
  for (const auto& b : blocks) {
    double u0 = 1e9, v0 = 1e9, u1 = -1e9, v1 = -1e9;
    int seen = 0;
    for (int i = 0; i < 9; ++i) {
      if (i == 4) continue;  // the centre adds nothing to the box
      const Eigen::Vector2d uv(b.x - 0.5 + 0.5 * b.width * (i % 3), b.y - 0.5 + 0.5 * b.height * (i / 3));
      const Eigen::Vector2d xn = cams_[from].model.unproject_normalised(uv);
      const Eigen::Vector3d d_W = R_from.transpose() * Eigen::Vector3d(xn.x(), xn.y(), 1.0);
      if (d_W.z() > -1e-6) continue;  // the ray never meets the ground below
      const Eigen::Vector3d X_W = p_from + (ground_z - p_from.z()) / d_W.z() * d_W;
      const auto q = cams_[to].model.project(est.camera(to).R_CW * (X_W - p_to));
      if (!q) continue;
      u0 = std::min(u0, q->x()), v0 = std::min(v0, q->y()), u1 = std::max(u1, q->x()), v1 = std::max(v1, q->y());
      ++seen;
    }
    if (seen < 4) continue;
    const int x0 = static_cast<int>(std::floor(u0 - kSlackPx)), y0 = static_cast<int>(std::floor(v0 - kSlackPx));
    out.emplace_back(x0, y0, static_cast<int>(std::ceil(u1 + kSlackPx)) - x0 + 1,
                     static_cast<int>(std::ceil(v1 + kSlackPx)) - y0 + 1);
  }
  return out;
}

// Every camera's predictions, and the blocks where the map needs new landmarks: chosen in camera
// 0's image and carried into the others, so that a cooperative pair finds both of its pixels; their
// number follows the largest deficit of the cameras (a pair asks for the larger of its two).
std::vector<VisionFrontend::CameraPlan> VisionFrontend::make_plans(const slam::Estimator& est) const {
  std::vector<CameraPlan> plans(cams_.size());
  for (int j = 0; j < num_cameras(); ++j) {
    // Where the estimate puts the lead in this image (estimated camera, commanded orientation).
    const Cam& c = cams_[j];
    const Eigen::Vector3d p_est = est.camera(j).R_CW * (est.lead_position() - est.camera_position(j));
    plans[j].lead = c.model.project(p_est);
    if (plans[j].lead && !c.model.in_image(*plans[j].lead, -100)) plans[j].lead.reset();
    plans[j].lead_depth = p_est.z();
  }
  const auto& active = cfg_.frontend.active_search;
  if (!active.enabled) return plans;
  const int target = cfg_.estimator.map.target_per_camera;
  int needed = 0;
  for (int j = 0; j < num_cameras(); ++j) {
    plans[j].in_view = predictions(est, j);
    needed = std::max(needed, target - static_cast<int>(plans[j].in_view.size()));
  }
  const Cam& ref = cams_[0];
  const auto blocks =
      vision::new_landmark_blocks({ref.model.width(), ref.model.height()}, plans[0].in_view, needed, active);
  const double ground_z = ground_height(est, plans[0].in_view);
  for (int j = 0; j < num_cameras(); ++j) {
    CameraPlan& p = plans[j];
    const Cam& c = cams_[j];
    p.blocks = j == 0 ? blocks : carry_blocks(blocks, 0, j, ground_z, est);
    p.search = vision::plan_search({c.model.width(), c.model.height()}, p.in_view, p.blocks, features_.crop_margin(),
                                   tracking_, active);
  }
  return plans;
}

void VisionFrontend::plan_step(const slam::Estimator& est) {
  auto plans = make_plans(est);
  for (int j = 0; j < num_cameras(); ++j) cams_[j].plan = std::move(plans[j]);
}

// The whole frame, or with active search the gates of the step's predictions in this camera and
// the blocks plan_step chose for it.
vision::Features VisionFrontend::detect_features(int cam, const cv::Mat& grey,
                                                 const std::vector<vision::ExclusionBox>& exclude) {
  Cam& c = cams_[cam];
  c.searched = 1.0;
  const auto& search = c.plan.search;
  if (!search) return features_.detect(grey, exclude);
  c.searched = search->fraction;
  return search->whole_frame ? features_.detect(grey, exclude) : features_.detect_in(grey, search->regions, exclude);
}

std::vector<VisionFrontend::Feature> VisionFrontend::track(int cam,
                                                           const std::vector<slam::LandmarkPrediction>& preds) {
  Cam& c = cams_[cam];
  c.preds.clear();
  for (const auto& p : preds) c.preds.push_back({p.id, p.uv, p.S});
  const auto tr = vision::track_landmarks(c.preds, c.features, store_, tracking_);
  c.used = tr.keypoint_used;
  std::vector<Feature> out;
  for (const auto& tc : tr.candidates) {
    out.push_back({tc.id, tc.uv, tc.keypoint});
    c.marks.tracked.push_back(tc.uv);
  }
  return out;
}

void VisionFrontend::accepted(int cam, const Feature& f, std::int64_t frame) {
  Cam& c = cams_[cam];
  c.marks.accepted.push_back(f.uv);
  store_.observe(f.id, c.features.descriptors.row(f.keypoint), frame);
}

std::vector<VisionFrontend::Pair> VisionFrontend::cross_match(int cam_a, int cam_b, int needed,
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
  std::vector<Pair> out;
  for (const auto& m : vision::select_spread(res.matches, needed, a.model, ex_a, b.model, ex_b)) {
    // Taken: a camera that then fills its own deficit (new_points) must not pick them again.
    a.used[m.keypoint_a] = true;
    b.used[m.keypoint_b] = true;
    a.marks.fresh.push_back(m.uv_a);
    b.marks.fresh.push_back(m.uv_b);
    out.push_back({{-1, m.uv_a, m.keypoint_a}, {-1, m.uv_b, m.keypoint_b}});
  }
  return out;
}

std::vector<VisionFrontend::Feature> VisionFrontend::new_points(int cam, int needed) {
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
  std::vector<Eigen::Vector2d> existing = c.marks.fresh;
  for (const auto& p : c.preds) existing.push_back(p.uv);
  std::vector<Feature> out;
  for (const auto& m : vision::select_spread(cand, needed, c.model, existing, c.model, existing)) {
    c.marks.fresh.push_back(m.uv_a);
    out.push_back({-1, m.uv_a, m.keypoint_a});
  }
  return out;
}

void VisionFrontend::added(slam::LandmarkId id, int cam, int keypoint, std::int64_t frame) {
  store_.add(id, cams_[cam].features.descriptors.row(keypoint), frame);
}

}  // namespace wingman::app
