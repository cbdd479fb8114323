// Feature detection, bucketing and description (see features.hpp).
#include "vision/features.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace wingman::vision {

DetectorKind parse_detector(std::string_view name) {
  if (name == "orb") return DetectorKind::Orb;
  if (name == "akaze") return DetectorKind::Akaze;
  if (name == "sift") return DetectorKind::Sift;
  if (name == "gftt_orb") return DetectorKind::GfttOrb;
  throw std::invalid_argument("unknown feature detector '" + std::string(name) +
                              "' (expected orb, akaze, sift or gftt_orb)");
}

std::string to_string(DetectorKind kind) {
  switch (kind) {
    case DetectorKind::Orb: return "orb";
    case DetectorKind::Akaze: return "akaze";
    case DetectorKind::Sift: return "sift";
    case DetectorKind::GfttOrb: return "gftt_orb";
  }
  return "?";
}

namespace {
void require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument("feature settings: " + what);
}
}  // namespace

void FeatureSettings::validate() const {
  require(max_features > 0, "max_features must be > 0, got " + std::to_string(max_features));
  require(grid_cols > 0 && grid_rows > 0, "grid must be at least 1 x 1, got " +
                                              std::to_string(grid_cols) + " x " + std::to_string(grid_rows));
  require(oversample >= 1.0, "oversample must be >= 1, got " + std::to_string(oversample));
  require(orb_levels >= 1, "orb_levels must be >= 1, got " + std::to_string(orb_levels));
  require(orb_scale_factor > 1.0f, "orb_scale_factor must be > 1, got " + std::to_string(orb_scale_factor));
  require(orb_fast_threshold > 0, "orb_fast_threshold must be > 0, got " + std::to_string(orb_fast_threshold));
  require(akaze_threshold > 0, "akaze_threshold must be > 0, got " + std::to_string(akaze_threshold));
  require(gftt_quality > 0 && gftt_quality < 1, "gftt_quality must be in (0, 1), got " + std::to_string(gftt_quality));
  require(gftt_min_distance >= 0, "gftt_min_distance must be >= 0, got " + std::to_string(gftt_min_distance));
  require(sift_contrast > 0, "sift_contrast must be > 0, got " + std::to_string(sift_contrast));
}

bool ExclusionBox::contains(const Eigen::Vector2d& uv) const {
  return std::abs(uv.x() - centre.x()) <= half_width && std::abs(uv.y() - centre.y()) <= half_height;
}

namespace {

std::vector<int> bucket_indices(const std::vector<cv::KeyPoint>& kps, int width, int height, int cols,
                                int rows, int budget) {
  std::vector<int> order(kps.size());
  std::iota(order.begin(), order.end(), 0);
  // Stable: detectors without a response (GFTT) already list their keypoints strongest first.
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return kps[a].response > kps[b].response; });
  if (static_cast<int>(order.size()) <= budget) return order;
  const int cells = cols * rows;
  const int per_cell = (budget + cells - 1) / cells;
  std::vector<int> count(cells, 0), kept, left;
  kept.reserve(budget);
  for (int i : order) {
    const int cx = std::clamp(static_cast<int>(kps[i].pt.x * cols / width), 0, cols - 1);
    const int cy = std::clamp(static_cast<int>(kps[i].pt.y * rows / height), 0, rows - 1);
    int& c = count[cy * cols + cx];
    if (c < per_cell && static_cast<int>(kept.size()) < budget) {
      ++c;
      kept.push_back(i);
    } else {
      left.push_back(i);
    }
  }
  for (std::size_t k = 0; k < left.size() && static_cast<int>(kept.size()) < budget; ++k)
    kept.push_back(left[k]);
  return kept;
}

// Orientation by intensity centroid over a disc of radius 15 (what ORB computes for its own
// keypoints), so GFTT corners get rotation-invariant ORB descriptors.
float intensity_centroid_angle(const cv::Mat& grey, cv::Point2f pt) {
  constexpr int r = 15;
  const int x0 = cvRound(pt.x), y0 = cvRound(pt.y);
  double m01 = 0, m10 = 0;
  for (int dy = -r; dy <= r; ++dy) {
    const int y = y0 + dy;
    if (y < 0 || y >= grey.rows) continue;
    const uchar* row = grey.ptr<uchar>(y);
    for (int dx = -r; dx <= r; ++dx) {
      const int x = x0 + dx;
      if (x < 0 || x >= grey.cols || dx * dx + dy * dy > r * r) continue;
      m10 += dx * row[x];
      m01 += dy * row[x];
    }
  }
  return cv::fastAtan2(static_cast<float>(m01), static_cast<float>(m10));
}

}  // namespace

void orb_keypoints_to_pixel_centres(std::vector<cv::KeyPoint>& keypoints, cv::Size image,
                                    float scale_factor) {
  for (auto& k : keypoints) {
    if (k.octave <= 0) continue;
    // OpenCV's ORB: level L is the image resized (pixel centres aligned) to
    // cvRound(size / s), s = (float) scale_factor^L, and a keypoint's level coordinates are
    // reported times s. Undo that and map them back exactly: x0 = (xL + 0.5) W / W_L - 0.5.
    const float s = static_cast<float>(std::pow(static_cast<double>(scale_factor), k.octave));
    const int wl = cvRound(image.width / s), hl = cvRound(image.height / s);
    const double xl = k.pt.x / s, yl = k.pt.y / s;
    k.pt.x = static_cast<float>((xl + 0.5) * image.width / wl - 0.5);
    k.pt.y = static_cast<float>((yl + 0.5) * image.height / hl - 0.5);
  }
}

std::vector<cv::KeyPoint> bucket_keypoints(const std::vector<cv::KeyPoint>& keypoints, int width,
                                           int height, int grid_cols, int grid_rows, int budget) {
  std::vector<cv::KeyPoint> out;
  for (int i : bucket_indices(keypoints, width, height, grid_cols, grid_rows, budget))
    out.push_back(keypoints[i]);
  return out;
}

double default_max_descriptor_distance(const cv::Mat& descriptors) {
  if (descriptors.type() == CV_8U) return 0.25 * 8.0 * descriptors.cols;
  return 250.0;
}

FeatureExtractor::FeatureExtractor(const FeatureSettings& settings) : cfg_(settings) {
  cfg_.validate();
  const int n = static_cast<int>(std::ceil(cfg_.max_features * cfg_.oversample));
  switch (cfg_.kind) {
    case DetectorKind::Orb:
      detector_ = cv::ORB::create(n, cfg_.orb_scale_factor, cfg_.orb_levels, 31, 0, 2,
                                  cv::ORB::HARRIS_SCORE, 31, cfg_.orb_fast_threshold);
      describer_ = detector_;
      break;
    case DetectorKind::GfttOrb:
      detector_ = cv::GFTTDetector::create(n, cfg_.gftt_quality, cfg_.gftt_min_distance, 3, false);
      describer_ = cv::ORB::create(n, cfg_.orb_scale_factor, 1);
      break;
    case DetectorKind::Akaze:
      detector_ = cv::AKAZE::create(cv::AKAZE::DESCRIPTOR_MLDB, 0, 3,
                                    static_cast<float>(cfg_.akaze_threshold));
      break;
    case DetectorKind::Sift:
      detector_ = cv::SIFT::create(n, 3, cfg_.sift_contrast);
      break;
  }
  if (!describer_) describer_ = detector_;  // AKAZE and SIFT describe what they detect
}

int FeatureExtractor::norm() const {
  return cfg_.kind == DetectorKind::Sift ? cv::NORM_L2 : cv::NORM_HAMMING;
}

Features FeatureExtractor::detect(const cv::Mat& image, const std::vector<ExclusionBox>& exclude) const {
  if (image.empty()) throw std::invalid_argument("FeatureExtractor::detect: empty image");
  cv::Mat grey;
  if (image.channels() == 3) cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  else if (image.channels() == 4) cv::cvtColor(image, grey, cv::COLOR_BGRA2GRAY);
  else grey = image;
  if (grey.depth() != CV_8U)
    throw std::invalid_argument("FeatureExtractor::detect: expected an 8-bit image, got depth " +
                                std::to_string(grey.depth()));

  cv::Mat mask;
  if (!exclude.empty()) {
    mask = cv::Mat(grey.size(), CV_8U, cv::Scalar(255));
    for (const auto& b : exclude) {
      const cv::Rect r(cvFloor(b.centre.x() - b.half_width), cvFloor(b.centre.y() - b.half_height),
                       cvCeil(2 * b.half_width) + 2, cvCeil(2 * b.half_height) + 2);
      mask(r & cv::Rect(0, 0, grey.cols, grey.rows)).setTo(0);
    }
  }
  auto outside = [&](const cv::KeyPoint& k) {
    const Eigen::Vector2d uv(k.pt.x, k.pt.y);
    return std::none_of(exclude.begin(), exclude.end(), [&](const ExclusionBox& b) { return b.contains(uv); });
  };

  Features f;
  f.norm = norm();
  std::vector<cv::KeyPoint> kps;
  if (cfg_.kind == DetectorKind::Orb || cfg_.kind == DetectorKind::GfttOrb) {
    // Cheap detection, bucket, then describe only the kept keypoints.
    detector_->detect(grey, kps, mask);
    std::erase_if(kps, [&](const cv::KeyPoint& k) { return !outside(k); });
    kps = bucket_keypoints(kps, grey.cols, grey.rows, cfg_.grid_cols, cfg_.grid_rows, cfg_.max_features);
    if (cfg_.kind == DetectorKind::GfttOrb) {
      for (auto& k : kps) {
        k.size = 31;
        k.octave = 0;
        k.angle = intensity_centroid_angle(grey, k.pt);
      }
    }
    describer_->compute(grey, kps, f.descriptors);  // drops keypoints too close to the border
    // After describing: ORB's compute locates the patch from its own (level-scaled) coordinates.
    if (cfg_.kind == DetectorKind::Orb)
      orb_keypoints_to_pixel_centres(kps, grey.size(), cfg_.orb_scale_factor);
    f.keypoints = std::move(kps);
  } else {
    // Scale-space detectors: describing the surplus is cheaper than building the pyramid twice.
    cv::Mat desc;
    detector_->detectAndCompute(grey, mask, kps, desc);
    std::vector<int> inside;
    for (int i = 0; i < static_cast<int>(kps.size()); ++i)
      if (outside(kps[i])) inside.push_back(i);
    std::vector<cv::KeyPoint> in_kps;
    for (int i : inside) in_kps.push_back(kps[i]);
    const auto keep = bucket_indices(in_kps, grey.cols, grey.rows, cfg_.grid_cols, cfg_.grid_rows,
                                     cfg_.max_features);
    f.descriptors.create(static_cast<int>(keep.size()), desc.cols, desc.type());
    for (int r = 0; r < static_cast<int>(keep.size()); ++r) {
      f.keypoints.push_back(in_kps[keep[r]]);
      desc.row(inside[keep[r]]).copyTo(f.descriptors.row(r));
    }
  }
  // No keypoint (a featureless view): OpenCV leaves the matrix without a type; give it the
  // descriptor's kind and width, so that it still compares as the same kind as another camera's.
  if (f.descriptors.empty()) {
    f.descriptors = cv::Mat(0, describer_->descriptorSize(), describer_->descriptorType());
  }
  return f;
}

}  // namespace wingman::vision
