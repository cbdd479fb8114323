// Frontend timings on synthetic 1000 x 1000 aerial frames (the paper's camera, f = 200.1 px, at
// 15 m and 17 m over the assets/ aerial texture laid on the ground plane, rendered exactly with a
// homography): detect + describe per detector (1000 features, 8 x 8 bucketing) over the whole frame
// and, for ORB, with active search in a typical step's regions; gated tracking of
// 150 landmarks, cross-UAV matching of two frames' features, and the lead detector.
//
//   bench_frontend [--benchmark_filter=...] [--opencv_threads=N]   (default 1)
#include <benchmark/benchmark.h>

#include <Eigen/Dense>
#include <opencv2/aruco.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string>

#include "geometry/rotation.hpp"
#include "vision/active_search.hpp"
#include "vision/cross_match.hpp"
#include "vision/features.hpp"
#include "vision/lead_detector.hpp"
#include "vision/learned_lead_detector.hpp"
#include "vision/motion_lead_detector.hpp"
#include "vision/tracking.hpp"

namespace {

using namespace wingman;
using namespace wingman::vision;

const cv::Mat& texture() {
  static const cv::Mat t = [] {
    const std::string path = std::string(WINGMAN_SOURCE_DIR) + "/assets/aerial/freetown_drone_nadir.jpg";
    cv::Mat m = cv::imread(path, cv::IMREAD_COLOR);
    if (m.empty()) throw std::runtime_error("cannot read " + path);
    return m;
  }();
  return t;
}

CameraView view(const Eigen::Vector3d& position, double yaw) {
  CameraView v;  // the paper camera: 1000 x 1000, f = 200.1, c = 500
  v.pose.position = position;
  v.pose.R_CW = geometry::nadir_R_CW() * geometry::rot_z(yaw).transpose();
  return v;
}

// Texture pixel (s, t) at x = (s - (W-1)/2) m, y = -(t - (H-1)/2) m on z = 0; 7.5 cm per texture
// pixel, about one image pixel at 15 m. The plane beyond the texture repeats it mirrored.
cv::Mat render(const CameraView& v, double m = 0.075) {
  const cv::Mat& tex = texture();
  const Eigen::Vector3d c = v.pose.position;
  Eigen::Matrix3d M;
  M << m, 0, -m * (tex.cols - 1) / 2.0 - c.x(), 0, -m, m * (tex.rows - 1) / 2.0 - c.y(), 0, 0, -c.z();
  const Eigen::Matrix3d H = v.camera.K() * v.pose.R_CW * M;
  cv::Mat Hcv(3, 3, CV_64F);
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k) Hcv.at<double>(r, k) = H(r, k);
  cv::Mat img;
  cv::warpPerspective(tex, img, Hcv, cv::Size(v.camera.width(), v.camera.height()), cv::INTER_LINEAR,
                      cv::BORDER_REFLECT);
  return img;
}

const CameraView& view_a() {
  static const CameraView v = view({-1.5, 0, 15}, 0.0);
  return v;
}
const CameraView& view_b() {
  static const CameraView v = view({1.5, 0.5, 17}, 0.15);
  return v;
}
const cv::Mat& frame_a() {
  static const cv::Mat f = render(view_a());
  return f;
}
const cv::Mat& frame_b() {
  static const cv::Mat f = render(view_b());
  return f;
}

void BM_DetectDescribe(benchmark::State& state) {
  FeatureSettings s;
  s.kind = static_cast<DetectorKind>(state.range(0));
  s.max_features = 1000;
  const FeatureExtractor fx(s);
  const cv::Mat& img = frame_a();
  int n = 0;
  for (auto _ : state) {
    const Features f = fx.detect(img);
    n = f.size();
    benchmark::DoNotOptimize(f.descriptors.data);
  }
  state.SetLabel(to_string(s.kind));
  state.counters["keypoints"] = n;
}
BENCHMARK(BM_DetectDescribe)
    ->Arg(static_cast<int>(DetectorKind::Orb))
    ->Arg(static_cast<int>(DetectorKind::Akaze))
    ->Arg(static_cast<int>(DetectorKind::Sift))
    ->Arg(static_cast<int>(DetectorKind::GfttOrb))
    ->Unit(benchmark::kMillisecond);

// Where ORB's time goes, as FeatureExtractor configures it (2000 candidates for 1000 features,
// FAST threshold 12, 4 levels of 1.2): detection alone over the frame, describing 1000 kept
// keypoints alone, and detection restricted to a quarter of the frame (4 of 16 cells of 250 px,
// one per row) by a mask and by cropping each cell with a 48 px border (ORB's 31 px patch at
// level 3 needs 31 x 1.2^2 = 45). What active search would save depends on the last two.
cv::Ptr<cv::ORB> paper_orb() {
  const FeatureSettings s;
  return cv::ORB::create(static_cast<int>(s.max_features * s.oversample), s.orb_scale_factor, s.orb_levels, 31, 0,
                         2, cv::ORB::HARRIS_SCORE, 31, s.orb_fast_threshold);
}

const cv::Mat& grey_a() {
  static const cv::Mat g = [] {
    cv::Mat m;
    cv::cvtColor(frame_a(), m, cv::COLOR_BGR2GRAY);
    return m;
  }();
  return g;
}

// The quarter of the frame: cell (row r, column (r * 5) % 4) of a 4 x 4 grid, for r = 0..3.
std::vector<cv::Rect> quarter_cells() {
  std::vector<cv::Rect> cells;
  for (int r = 0; r < 4; ++r) cells.emplace_back(250 * ((r * 5) % 4), 250 * r, 250, 250);
  return cells;
}

void BM_OrbDetectOnly(benchmark::State& state) {
  const auto orb = paper_orb();
  std::vector<cv::KeyPoint> kps;
  for (auto _ : state) orb->detect(grey_a(), kps);
  state.counters["keypoints"] = static_cast<double>(kps.size());
}
BENCHMARK(BM_OrbDetectOnly)->Unit(benchmark::kMillisecond);

// FAST alone (threshold 12, non-maximum suppression) on level 0: what ORB's detection is made of.
void BM_FastLevel0(benchmark::State& state) {
  std::vector<cv::KeyPoint> kps;
  for (auto _ : state) {
    kps.clear();
    cv::FAST(grey_a(), kps, FeatureSettings{}.orb_fast_threshold, true);
  }
  state.counters["corners"] = static_cast<double>(kps.size());
}
BENCHMARK(BM_FastLevel0)->Unit(benchmark::kMillisecond);

void BM_OrbDescribeOnly(benchmark::State& state) {
  const auto orb = paper_orb();
  std::vector<cv::KeyPoint> all;
  orb->detect(grey_a(), all);
  const auto kept = bucket_keypoints(all, 1000, 1000, 8, 8, 1000);
  cv::Mat desc;
  for (auto _ : state) {
    std::vector<cv::KeyPoint> kps = kept;
    orb->compute(grey_a(), kps, desc);
  }
  state.counters["keypoints"] = desc.rows;
}
BENCHMARK(BM_OrbDescribeOnly)->Unit(benchmark::kMillisecond);

void BM_OrbDetectQuarterMasked(benchmark::State& state) {
  const auto orb = paper_orb();
  cv::Mat mask(grey_a().size(), CV_8U, cv::Scalar(0));
  for (const auto& c : quarter_cells()) mask(c).setTo(255);
  std::vector<cv::KeyPoint> kps;
  for (auto _ : state) orb->detect(grey_a(), kps, mask);
  state.counters["keypoints"] = static_cast<double>(kps.size());
}
BENCHMARK(BM_OrbDetectQuarterMasked)->Unit(benchmark::kMillisecond);

void BM_OrbDetectQuarterCropped(benchmark::State& state) {
  const auto orb = paper_orb();
  orb->setMaxFeatures(2000 / 4);  // each cell its share
  constexpr int kBorder = 48;
  const cv::Rect frame(0, 0, grey_a().cols, grey_a().rows);
  std::size_t n = 0;
  for (auto _ : state) {
    n = 0;
    for (const auto& c : quarter_cells()) {
      const cv::Rect crop = cv::Rect(c.x - kBorder, c.y - kBorder, c.width + 2 * kBorder, c.height + 2 * kBorder) & frame;
      std::vector<cv::KeyPoint> kps;
      orb->detect(grey_a()(crop), kps);
      n += kps.size();
    }
  }
  state.counters["keypoints"] = static_cast<double>(n);
}
BENCHMARK(BM_OrbDetectQuarterCropped)->Unit(benchmark::kMillisecond);

// The frontend's detect + describe with active search, in a step shaped like the paper scene's
// (docs/studies/speed.md): 17 landmarks in view, spread over the frame, with gates of about 7 px
// (S = 5.4 I px^2 at d^2 = 9), and 9 new landmarks wanted (3 blocks). The landmarks are frame a's
// own whole-frame keypoints, so `tracked` says how many of them active search still finds.
void BM_DetectDescribeActive(benchmark::State& state) {
  const FeatureExtractor fx;
  const Features whole = fx.detect(frame_a());
  DescriptorStore store;
  std::vector<LandmarkPrediction> preds;
  for (int i = 0; i < whole.size() && preds.size() < 17; i += whole.size() / 17) {
    store.add(i, whole.descriptors.row(i), 0);
    preds.push_back({i, whole.pixel(i), 5.4 * Eigen::Matrix2d::Identity()});
  }
  const TrackingSettings tracking;
  const ActiveSearchSettings active;
  SearchPlan plan;
  Features f;
  for (auto _ : state) {
    plan = plan_search(frame_a().size(), preds, new_landmark_blocks(frame_a().size(), preds, 9, active),
                       fx.crop_margin(), tracking, active);
    f = fx.detect_in(frame_a(), plan.regions);
    benchmark::DoNotOptimize(f.descriptors.data);
  }
  state.counters["fraction"] = plan.fraction;
  state.counters["regions"] = static_cast<double>(plan.regions.size());
  state.counters["keypoints"] = f.size();
  state.counters["tracked"] = static_cast<double>(track_landmarks(preds, f, store, tracking).candidates.size());
  state.counters["landmarks"] = static_cast<double>(preds.size());
}
BENCHMARK(BM_DetectDescribeActive)->Unit(benchmark::kMillisecond);

// 150 landmarks from frame a's features (rays met with the ground), predicted exactly in frame b
// with S = 9 I, tracked among frame b's 1000 features.
void BM_Track(benchmark::State& state) {
  const FeatureExtractor fx;
  const Features fa = fx.detect(frame_a()), fb = fx.detect(frame_b());
  DescriptorStore store;
  std::vector<LandmarkPrediction> preds;
  for (int i = 0; i < fa.size() && preds.size() < 150; i += 3) {
    const Eigen::Vector2d xn = view_a().camera.unproject_normalised(fa.pixel(i));
    const Eigen::Vector3d d = view_a().pose.R_CW.transpose() * Eigen::Vector3d(xn.x(), xn.y(), 1);
    const Eigen::Vector3d p = view_a().pose.position - view_a().pose.position.z() / d.z() * d;
    const auto uv = view_b().camera.project(view_b().pose.to_camera(p));
    if (!uv || !view_b().camera.in_image(*uv, 10)) continue;
    store.add(i, fa.descriptors.row(i), 0);
    preds.push_back({i, *uv, 9 * Eigen::Matrix2d::Identity()});
  }
  std::size_t found = 0;
  for (auto _ : state) {
    const TrackingResult r = track_landmarks(preds, fb, store);
    found = r.candidates.size();
  }
  state.counters["landmarks"] = static_cast<double>(preds.size());
  state.counters["candidates"] = static_cast<double>(found);
}
BENCHMARK(BM_Track)->Unit(benchmark::kMillisecond);

// Two UAVs' 1000 ORB features each, mutual best + ratio, epipolar and triangulation checks.
void BM_CrossMatch(benchmark::State& state) {
  const FeatureExtractor fx;
  const Features fa = fx.detect(frame_a()), fb = fx.detect(frame_b());
  std::size_t n = 0;
  for (auto _ : state) {
    const CrossMatchResult r = match_across(fa, all_keypoints(fa), view_a(), fb, all_keypoints(fb), view_b());
    n = r.matches.size();
  }
  state.counters["matches"] = static_cast<double>(n);
}
BENCHMARK(BM_CrossMatch)->Unit(benchmark::kMillisecond);

// ArUco search over the whole 1000 x 1000 frame (no marker in it: the full cost).
void BM_LeadDetector(benchmark::State& state) {
  LeadDetector det;
  const cv::Mat& img = frame_a();
  for (auto _ : state) benchmark::DoNotOptimize(det.detect(img));
}
BENCHMARK(BM_LeadDetector)->Unit(benchmark::kMillisecond);

// The same with a prediction: only its 129 x 129 neighbourhood (and that upscaled) is searched
// before the whole frame, so with the marker present the cost is the small region's.
void BM_LeadDetectorPredicted(benchmark::State& state) {
  LeadDetector det;
  cv::Mat img = frame_a().clone();
  cv::Mat marker;
  cv::aruco::drawMarker(cv::aruco::getPredefinedDictionary(cv::aruco::DICT_4X4_50), 0, 30, marker, 1);
  cv::Mat white(42, 42, CV_8U, cv::Scalar(255));
  marker.copyTo(white(cv::Rect(6, 6, 30, 30)));
  cv::cvtColor(white, white, cv::COLOR_GRAY2BGR);
  white.copyTo(img(cv::Rect(600, 400, 42, 42)));
  const Eigen::Vector2d predicted(625, 415);
  bool found = false;
  for (auto _ : state) {
    const auto d = det.detect(img, predicted);
    found = d.has_value();
    benchmark::DoNotOptimize(d);
  }
  if (!found) state.SkipWithError("marker not found");
}
BENCHMARK(BM_LeadDetectorPredicted)->Unit(benchmark::kMillisecond);

// The learned lead detector (assets/lead/lead_detector.onnx) on the window it searches around a
// prediction (192 x 192: the gated cost when the lead is in it) and on the whole 1000 x 1000 frame
// (no prediction, or none found near it).
LearnedLeadDetector& learned() {
  static LearnedLeadDetector d(std::string(WINGMAN_SOURCE_DIR) + "/assets/lead/lead_detector.onnx");
  return d;
}

void BM_LearnedLeadWindow(benchmark::State& state) {
  const cv::Mat window = frame_a()(cv::Rect(400, 400, 192, 192)).clone();
  for (auto _ : state) benchmark::DoNotOptimize(learned().detect(window));
}
BENCHMARK(BM_LearnedLeadWindow)->Unit(benchmark::kMillisecond);

void BM_LearnedLeadWholeFrame(benchmark::State& state) {
  const cv::Mat& img = frame_a();
  for (auto _ : state) benchmark::DoNotOptimize(learned().detect(img));
}
BENCHMARK(BM_LearnedLeadWholeFrame)->Unit(benchmark::kMillisecond);

// The motion detector on a 1000 x 1000 grey sequence whose ground slides 8 px a frame under a
// bright disc that keeps its place: each iteration is one frame (the ground's homography, the
// median of 5 earlier frames, the blobs), with the history already full.
void BM_MotionLead(benchmark::State& state) {
  cv::Mat grey;
  cv::cvtColor(frame_a(), grey, cv::COLOR_BGR2GRAY);
  std::vector<cv::Mat> seq;
  for (int k = 0; k < 64; ++k) {
    cv::Mat f;
    const cv::Mat A = (cv::Mat_<double>(2, 3) << 1, 0, -8.0 * k, 0, 1, 0);
    cv::warpAffine(grey, f, A, grey.size(), cv::INTER_LINEAR, cv::BORDER_REFLECT);
    cv::circle(f, {500, 500}, 20, cv::Scalar(250), cv::FILLED);
    seq.push_back(f);
  }
  MotionLeadDetector det;
  const Eigen::Vector2d predicted(505, 497);
  for (int k = 0; k < 20; ++k) det.detect(seq[k], predicted);
  int k = 20, found = 0, frames = 0;
  for (auto _ : state) {
    found += det.detect(seq[k], predicted).has_value();
    ++frames;
    if (++k == 64) {  // start the ground again: a fresh history, as after a lost track
      state.PauseTiming();
      det = MotionLeadDetector();
      for (k = 0; k < 20; ++k) det.detect(seq[k], predicted);
      state.ResumeTiming();
    }
  }
  state.counters["found"] = static_cast<double>(found) / frames;
}
BENCHMARK(BM_MotionLead)->Unit(benchmark::kMillisecond);

}  // namespace

// OpenCV runs single-threaded here (--opencv_threads=N to change): on the shared 2-core machines
// its thread pool makes wall times depend on the neighbours' load.
int main(int argc, char** argv) {
  int threads = 1;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a.rfind("--opencv_threads=", 0) == 0) threads = std::stoi(a.substr(17));
  }
  cv::setNumThreads(threads);
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
