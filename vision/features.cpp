// Feature detection, bucketing and description (see features.hpp).
#include "vision/features.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "geometry/bounds_check.hpp"

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
  geometry::check_bounds(*this, "feature settings");
  // The limit of the one field no scenario key sets:
  require(oversample >= 1.0, "oversample must be >= 1, got " + std::to_string(oversample));
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

cv::Mat to_grey(const cv::Mat& image) {
  if (image.empty()) throw std::invalid_argument("FeatureExtractor::detect: empty image");
  cv::Mat grey;
  if (image.channels() == 3) cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  else if (image.channels() == 4) cv::cvtColor(image, grey, cv::COLOR_BGRA2GRAY);
  else grey = image;
  if (grey.depth() != CV_8U)
    throw std::invalid_argument("FeatureExtractor::detect: expected an 8-bit image, got depth " +
                                std::to_string(grey.depth()));
  return grey;
}

// The detector's mask: zero inside the exclusion boxes (with a pixel to spare), empty without.
cv::Mat exclusion_mask(cv::Size size, const std::vector<ExclusionBox>& exclude) {
  cv::Mat mask;
  if (exclude.empty()) return mask;
  mask = cv::Mat(size, CV_8U, cv::Scalar(255));
  for (const auto& b : exclude) {
    const cv::Rect r(cvFloor(b.centre.x() - b.half_width), cvFloor(b.centre.y() - b.half_height),
                     cvCeil(2 * b.half_width) + 2, cvCeil(2 * b.half_height) + 2);
    mask(r & cv::Rect(0, 0, size.width, size.height)).setTo(0);
  }
  return mask;
}

bool outside_boxes(const cv::KeyPoint& k, const std::vector<ExclusionBox>& exclude) {
  const Eigen::Vector2d uv(k.pt.x, k.pt.y);
  return std::none_of(exclude.begin(), exclude.end(), [&](const ExclusionBox& b) { return b.contains(uv); });
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
  detector_ = make_detector(static_cast<int>(std::ceil(cfg_.max_features * cfg_.oversample)), kOrbEdge);
  if (cfg_.kind == DetectorKind::GfttOrb)
    describer_ = cv::ORB::create(static_cast<int>(std::ceil(cfg_.max_features * cfg_.oversample)),
                                 cfg_.orb_scale_factor, 1);
  else
    describer_ = detector_;  // ORB describes with its own pyramid; AKAZE and SIFT what they detect
}

cv::Ptr<cv::Feature2D> FeatureExtractor::make_detector(int n, int orb_edge) const {
  switch (cfg_.kind) {
    case DetectorKind::Orb:
      return cv::ORB::create(n, cfg_.orb_scale_factor, cfg_.orb_levels, orb_edge, 0, 2, cfg_.orb_score, 31,
                             cfg_.orb_fast_threshold);
    case DetectorKind::GfttOrb:
      return cv::GFTTDetector::create(n, cfg_.gftt_quality, cfg_.gftt_min_distance, 3, false);
    case DetectorKind::Akaze:
      return cv::AKAZE::create(cv::AKAZE::DESCRIPTOR_MLDB, 0, 3, static_cast<float>(cfg_.akaze_threshold));
    case DetectorKind::Sift:
      return cv::SIFT::create(n, 3, cfg_.sift_contrast);
  }
  throw std::logic_error("FeatureExtractor: unknown detector kind");
}

int FeatureExtractor::crop_margin() const {
  switch (cfg_.kind) {
    case DetectorKind::Orb:
      return static_cast<int>(std::ceil(kOrbCropEdge * std::pow(cfg_.orb_scale_factor, cfg_.orb_levels - 1))) + 1;
    case DetectorKind::GfttOrb:
      return 32;  // ORB's 31 px patch at one level
    case DetectorKind::Akaze:
    case DetectorKind::Sift:
      return 64;  // their coarse octaves see less context in a crop than in the frame
  }
  return 64;
}

int FeatureExtractor::norm() const {
  return cfg_.kind == DetectorKind::Sift ? cv::NORM_L2 : cv::NORM_HAMMING;
}

Features FeatureExtractor::detect(const cv::Mat& image, const std::vector<ExclusionBox>& exclude) const {
  const cv::Mat grey = to_grey(image);
  const cv::Mat mask = exclusion_mask(grey.size(), exclude);
  auto outside = [&](const cv::KeyPoint& k) { return outside_boxes(k, exclude); };

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

struct FeatureExtractor::Crop {
  cv::Rect core, outer;              // the region, and the region with its context
  std::vector<cv::KeyPoint> kps;     // in the crop's pixels, as the detector reports them
  cv::Mat desc;                      // one row per keypoint of kps (all but GFTT, described once kept)
  std::vector<int> kept;             // indices into kps that bucketing kept
};

void FeatureExtractor::detect_crop(const cv::Mat& grey, const cv::Mat& mask, Crop& c, int candidates) const {
  const auto det = make_detector(candidates, kOrbCropEdge);
  const cv::Mat roi = grey(c.outer), mroi = mask.empty() ? cv::Mat() : mask(c.outer);
  // ORB too in one pass: describing a small crop's every candidate costs less than building its
  // pyramid a second time for the kept ones.
  if (cfg_.kind == DetectorKind::GfttOrb)
    det->detect(roi, c.kps, mroi);
  else
    det->detectAndCompute(roi, mroi, c.kps, c.desc);
}

// Describes the kept keypoints of one crop and moves them to the frame's pixels.
void FeatureExtractor::describe_crop(const cv::Mat& grey, Crop& c) const {
  std::vector<cv::KeyPoint> kps;
  for (int i : c.kept) kps.push_back(c.kps[i]);
  cv::Mat desc;
  if (cfg_.kind != DetectorKind::GfttOrb) {
    desc.create(static_cast<int>(c.kept.size()), c.desc.cols, c.desc.type());
    for (int r = 0; r < desc.rows; ++r) c.desc.row(c.kept[r]).copyTo(desc.row(r));
    if (cfg_.kind == DetectorKind::Orb) orb_keypoints_to_pixel_centres(kps, c.outer.size(), cfg_.orb_scale_factor);
  } else {
    const cv::Mat roi = grey(c.outer);
    for (auto& k : kps) {
      k.size = 31;
      k.octave = 0;
      k.angle = intensity_centroid_angle(roi, k.pt);
    }
    describer_->compute(roi, kps, desc);
  }
  for (auto& k : kps) k.pt += cv::Point2f(static_cast<float>(c.outer.x), static_cast<float>(c.outer.y));
  c.kps = std::move(kps);
  c.desc = desc;
}

// The whole-frame path drops ORB keypoints within its edge threshold (31 px of their pyramid level)
// of the frame's edge; a crop's smaller edge threshold must not let them in there.
bool FeatureExtractor::near_frame_edge(const cv::KeyPoint& k, const cv::Rect& frame) const {
  if (cfg_.kind != DetectorKind::Orb) return false;
  const float e = static_cast<float>(kOrbEdge * std::pow(static_cast<double>(cfg_.orb_scale_factor), k.octave));
  return k.pt.x < e || k.pt.y < e || k.pt.x >= frame.width - e || k.pt.y >= frame.height - e;
}

Features FeatureExtractor::detect_in(const cv::Mat& image, const std::vector<cv::Rect>& regions,
                                     const std::vector<ExclusionBox>& exclude) const {
  const cv::Mat grey = to_grey(image);
  const cv::Mat mask = exclusion_mask(grey.size(), exclude);
  const cv::Rect frame(0, 0, grey.cols, grey.rows);
  const double frame_area = static_cast<double>(frame.area());
  const int margin = crop_margin();
  std::vector<Crop> crops;
  std::vector<cv::KeyPoint> all;             // candidates in the frame's pixels
  std::vector<std::pair<int, int>> origin;   // their crop and index there
  for (const cv::Rect& r : regions) {
    Crop c;
    c.core = r & frame;
    if (c.core.empty()) continue;
    c.outer = cv::Rect(c.core.x - margin, c.core.y - margin, c.core.width + 2 * margin,
                       c.core.height + 2 * margin) & frame;
    const int n = static_cast<int>(std::ceil(cfg_.max_features * cfg_.oversample * c.outer.area() / frame_area));
    detect_crop(grey, mask, c, std::max(n, 8));
    const cv::Point2f o(static_cast<float>(c.outer.x), static_cast<float>(c.outer.y));
    for (int i = 0; i < static_cast<int>(c.kps.size()); ++i) {
      cv::KeyPoint k = c.kps[i];
      k.pt += o;
      // Pixel (0,0)'s centre is at 0: pixel x covers [x - 0.5, x + 0.5).
      const bool in_core = k.pt.x >= c.core.x - 0.5f && k.pt.x < c.core.br().x - 0.5f &&
                           k.pt.y >= c.core.y - 0.5f && k.pt.y < c.core.br().y - 0.5f;
      if (!in_core || !outside_boxes(k, exclude) || near_frame_edge(k, frame)) continue;
      all.push_back(k);
      origin.emplace_back(static_cast<int>(crops.size()), i);
    }
    crops.push_back(std::move(c));
  }
  // The whole frame's budget and grid: each cell keeps at most its share of the strongest, as
  // there; a cell only partly searched keeps what its searched part has.
  for (int i : bucket_indices(all, grey.cols, grey.rows, cfg_.grid_cols, cfg_.grid_rows, cfg_.max_features))
    crops[origin[i].first].kept.push_back(origin[i].second);
  Features f;
  f.norm = norm();
  std::vector<cv::Mat> rows;
  for (auto& c : crops) {
    if (c.kept.empty()) continue;
    describe_crop(grey, c);
    f.keypoints.insert(f.keypoints.end(), c.kps.begin(), c.kps.end());
    if (!c.desc.empty()) rows.push_back(c.desc);
  }
  if (!rows.empty()) cv::vconcat(rows, f.descriptors);
  else f.descriptors = cv::Mat(0, describer_->descriptorSize(), describer_->descriptorType());
  return f;
}

}  // namespace wingman::vision
