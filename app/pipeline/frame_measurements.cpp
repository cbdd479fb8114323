#include "app/pipeline/frame_measurements.hpp"

#include <future>

#include "io/timing.hpp"

namespace wingman::app {

FrameMeasurements::FrameMeasurements(const RunConfig& cfg, const sim::Truth& truth,
                                     std::unique_ptr<FrameProducer> frames,
                                     std::unique_ptr<SensorSamples> samples, const FrameOptions& options)
    : cfg_(cfg),
      truth_(truth),
      cam_uav_(cfg.filter_uavs()),
      frames_(std::move(frames)),
      samples_(std::move(samples)),
      frontend_(cfg, cam_uav_, options.features),
      regions_(options.regions && options.video.empty() && cfg.frontend.active_search.enabled),
      partial_(cam_uav_.size(), 0),
      now_(cam_uav_.size()),
      lead_(cam_uav_.size()) {
  prefetch_ = options.prefetch && frames_->renders();
  record_.enabled = true;
  record_.detector = frontend_.detector_name();
  record_.renderer = frames_->description();
  record_.frames_rendered = frames_->renders();
  record_.oracle_pixels = cfg.frontend.oracle_pixels;
  record_.record_correspondences = options.correspondences;
  if (!options.video.empty()) {
    std::vector<geometry::PinholeCamera> models;
    std::vector<std::string> names;
    for (int j = 0; j < frontend_.num_cameras(); ++j) {
      models.push_back(frontend_.model(j));
      names.push_back(cfg.uavs[cam_uav_[j]].name);
    }
    video_ = std::make_unique<VideoOverlay>(options.video, models, names, cfg.rate);
  }
}

StageTimes FrameMeasurements::begin_step(int k, double t, const slam::Estimator& est) {
  k_ = k;
  t_ = t;
  const StageTimes st = produce_and_detect(k, t, est);
  record_.detect_busy_ms += st.detect_ms;
  // Tallies of the lead detector against the truth (evaluation only).
  const Eigen::Vector3d lead_W = truth_.lead(t).position;
  for (int j = 0; j < frontend_.num_cameras(); ++j) {
    lead_[j] = frontend_.lead(j);
    record_.searched_fraction_sum += frontend_.searched_fraction(j);
    const auto uv_true = labeller_.lead(lead_[j], frontend_.model(j), now_[j], lead_W, record_);
    eval::LeadFrameRecord row;
    row.k = k, row.t = t, row.cam = j;
    if (lead_[j]) row.detected = *lead_[j];
    row.has_truth = now_[j].lead_truth.has_value();
    if (row.has_truth) row.truth = *now_[j].lead_truth;
    record_.lead_frames.push_back(row);
    if (uv_true && cfg_.frontend.oracle_pixels) lead_[j] = *uv_true;
  }
  return st;
}

void FrameMeasurements::detect_all(StageTimes& st) {
  for (int j = 0; j < frontend_.num_cameras(); ++j) st.detect_ms += frontend_.detect(j, now_[j].frame, partial_[j]);
}

bool FrameMeasurements::produce(int j, int k, double t, const std::optional<std::vector<cv::Rect>>& regions,
                                CameraFrame& out) {
  if (regions_ && regions && frames_->produce_regions(j, k, t, *regions, out)) return true;
  frames_->produce(j, k, t, out);
  return false;
}

namespace {

// The rectangles of `wanted` (cut to the image) that `drawn` does not cover whole.
std::vector<cv::Rect> not_drawn(const std::vector<cv::Rect>& wanted, const std::vector<cv::Rect>& drawn,
                                cv::Size image) {
  cv::Mat mask = cv::Mat::zeros(image, CV_8U);
  const cv::Rect all(0, 0, image.width, image.height);
  for (const cv::Rect& d : drawn) mask(d & all).setTo(1);
  std::vector<cv::Rect> out;
  for (const cv::Rect& w : wanted)
    if (const cv::Rect c = w & all; !c.empty() && cv::countNonZero(mask(c)) < c.area()) out.push_back(c);
  return out;
}

}  // namespace

void FrameMeasurements::take_prefetched(int k, double t, StageTimes& st) {
  const auto t0 = io::Clock::now();
  for (int j = 0; j < frontend_.num_cameras(); ++j) {
    now_[j] = std::move(next_.frames[j]);
    partial_[j] = next_.drawn[j].has_value();
    if (!partial_[j]) continue;
    const auto wanted = frontend_.reads(j);
    if (!wanted) {
      frames_->produce_whole(j, k, t, now_[j]);
      partial_[j] = 0;
      ++record_.region_fills;
    } else if (const auto missing = not_drawn(*wanted, *next_.drawn[j], now_[j].frame.rgb.size()); !missing.empty()) {
      frames_->produce_more(j, k, t, missing, now_[j]);
      ++record_.region_fills;
    }
  }
  next_.k = -1;
  st.render_ms += io::ms_since(t0);
}

void FrameMeasurements::prefetch(int k, const slam::Estimator& est) {
  const int n = frontend_.num_cameras();
  std::vector<std::optional<std::vector<cv::Rect>>> wanted(n);
  if (regions_) {
    slam::Estimator ahead = est;
    ahead.predict(cfg_.dt());
    wanted = frontend_.reads_for(ahead);
  }
  next_.frames.resize(n);
  next_.drawn.assign(n, std::nullopt);
  for (int j = 0; j < n; ++j)
    if (produce(j, k + 1, (k + 1) * cfg_.dt(), wanted[j], next_.frames[j])) next_.drawn[j] = wanted[j];
  next_.k = k + 1;
}

void FrameMeasurements::redo_whole(int k, double t, StageTimes& st) {
  for (int j = 0; j < frontend_.num_cameras(); ++j) {
    if (!frontend_.needs_whole_frame(j)) continue;
    const auto t0 = io::Clock::now();
    frames_->produce_whole(j, k, t, now_[j]);
    partial_[j] = 0;
    st.render_ms += io::ms_since(t0);
    st.detect_ms += frontend_.detect(j, now_[j].frame);
    ++record_.whole_frame_retries;
  }
  for (int j = 0; j < frontend_.num_cameras(); ++j) record_.region_frames += partial_[j];
}

StageTimes FrameMeasurements::produce_and_detect(int k, double t, const slam::Estimator& est) {
  StageTimes st;
  const auto t_start = io::Clock::now();
  frontend_.plan_step(est);  // before any camera detects, on whichever thread
  const int n = frontend_.num_cameras();
  const bool ahead = prefetch_ && k < cfg_.num_steps();
  if (!prefetch_) {
    produce_and_detect_each(k, t, st);
  } else {
    if (next_.k == k) {  // produced during the previous step
      take_prefetched(k, t, st);
    } else {
      const auto t0 = io::Clock::now();
      for (int j = 0; j < n; ++j) partial_[j] = produce(j, k, t, frontend_.reads(j), now_[j]);
      st.render_ms += io::ms_since(t0);
    }
    if (ahead) {
      // Step k's detection (the cameras one after the other: the extractor is not shared) on a
      // second thread while this one, which holds the GL context, renders step k+1.
      auto detection = std::async(std::launch::async, [this] {
        StageTimes d;
        detect_all(d);
        return d.detect_ms;
      });
      const auto t0 = io::Clock::now();
      prefetch(k, est);
      st.render_ms += io::ms_since(t0);
      st.detect_ms += detection.get();
    } else {
      detect_all(st);
    }
    redo_whole(k, t, st);
  }
  st.wall_ms = io::ms_since(t_start);
  return st;
}

// Camera j's detection runs on a second thread while camera j+1 is produced (the GL context stays
// on this thread; two detections never run at once).
void FrameMeasurements::produce_and_detect_each(int k, double t, StageTimes& st) {
  std::future<double> pending;
  for (int j = 0; j < frontend_.num_cameras(); ++j) {
    const auto t0 = io::Clock::now();
    partial_[j] = produce(j, k, t, frontend_.reads(j), now_[j]);
    st.render_ms += io::ms_since(t0);
    if (pending.valid()) st.detect_ms += pending.get();
    pending = std::async(std::launch::async, [this, j] { return frontend_.detect(j, now_[j].frame, partial_[j]); });
  }
  if (pending.valid()) st.detect_ms += pending.get();
  redo_whole(k, t, st);
}

Labelled<LandmarkObservation> FrameMeasurements::landmarks(int cam,
                                                           const std::vector<slam::LandmarkPrediction>& preds) {
  Labelled<LandmarkObservation> out;
  for (const auto& f : frontend_.track(cam, preds)) {
    LandmarkObservation o{{cam, f.id, f.uv}, f.keypoint};
    const auto truth = labeller_.observation(f.id, f.uv, frontend_.model(cam), now_[cam]);
    TruthLabel label;
    label.outlier = truth.outlier;
    label.error_px = truth.error_px;
    if (truth.true_uv) label.true_uv = *truth.true_uv;
    if (cfg_.frontend.oracle_pixels && !label.outlier) {  // an inlier has a true projection
      o.c.uv = *truth.true_uv;
      label.error_px = 0;
    }
    out.add(o, label);
  }
  return out;
}

void FrameMeasurements::verdict(const LandmarkObservation& o, const TruthLabel& label, bool accepted) {
  if (record_.record_correspondences)
    record_.correspondences.push_back({k_, t_, o.c.cam, o.c.id, o.c.uv, label.true_uv, label.outlier, accepted});
  if (!accepted) return;
  frontend_.accepted(o.c.cam, {o.c.id, o.c.uv, static_cast<int>(o.handle)}, k_);
  record_.accepted_error_px.push_back(label.error_px);
}

Labelled<PairObservation> FrameMeasurements::pairs(int cam_a, int cam_b, int needed,
                                                   const slam::Estimator& est) {
  Labelled<PairObservation> out;
  for (const auto& p : frontend_.cross_match(cam_a, cam_b, needed, est)) {
    PairObservation o{{cam_a, cam_b, p.a.uv, p.b.uv}, p.a.keypoint};
    const auto truth = labeller_.pair(p.a.uv, frontend_.model(cam_a), now_[cam_a], p.b.uv,
                                      frontend_.model(cam_b), now_[cam_b]);
    TruthLabel label;
    label.outlier = truth.outlier;
    // Camera a's pixel defines the landmark's truth (added()), so only b's is replaced.
    if (cfg_.frontend.oracle_pixels && !label.outlier) o.m.uv_b = *truth.true_uv;
    out.add(o, label);
  }
  return out;
}

std::vector<PointObservation> FrameMeasurements::points(int cam, int needed) {
  std::vector<PointObservation> out;
  for (const auto& f : frontend_.new_points(cam, needed)) out.push_back({cam, f.uv, f.keypoint});
  return out;
}

std::optional<Eigen::Vector3d> FrameMeasurements::added(slam::LandmarkId id, int cam, std::int64_t handle,
                                                        const Eigen::Vector2d& uv) {
  frontend_.added(id, cam, static_cast<int>(handle), k_);
  return labeller_.landmark(id, uv, frontend_.model(cam), now_[cam]);
}

void FrameMeasurements::removed(slam::LandmarkId id) {
  frontend_.removed(id);
  labeller_.forget(id);
}

void FrameMeasurements::end_step(double t) {
  if (!video_) return;
  std::vector<VideoOverlay::Tile> tiles;
  for (int j = 0; j < frontend_.num_cameras(); ++j)
    tiles.push_back({&now_[j].frame, &frontend_.marks(j), lead_[j]});
  const int phase = cfg_.phase_at(t);
  video_->write(tiles, t, phase < 0 ? "" : cfg_.phases[static_cast<std::size_t>(phase)].name);
}

void FrameMeasurements::finish(eval::RunRecord& rec) {
  frames_->finish(record_);
  rec.frontend = std::move(record_);
}

}  // namespace wingman::app
