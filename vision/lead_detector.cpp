// ArUco marker / colour-panel lead detector (see lead_detector.hpp).
#include "vision/lead_detector.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/aruco.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <vector>

namespace wingman::vision {

namespace {
// In the order of cv::aruco::PREDEFINED_DICTIONARY_NAME.
constexpr std::array<std::string_view, 21> kDictionaries = {
    "DICT_4X4_50",   "DICT_4X4_100",   "DICT_4X4_250",       "DICT_4X4_1000",      "DICT_5X5_50",
    "DICT_5X5_100",  "DICT_5X5_250",   "DICT_5X5_1000",      "DICT_6X6_50",        "DICT_6X6_100",
    "DICT_6X6_250",  "DICT_6X6_1000",  "DICT_7X7_50",        "DICT_7X7_100",       "DICT_7X7_250",
    "DICT_7X7_1000", "DICT_ARUCO_ORIGINAL", "DICT_APRILTAG_16h5", "DICT_APRILTAG_25h9",
    "DICT_APRILTAG_36h10", "DICT_APRILTAG_36h11"};

double distance_to(const std::optional<Eigen::Vector2d>& p, const Eigen::Vector2d& uv) {
  return p ? (*p - uv).norm() : 0.0;
}
}  // namespace

LeadMethod parse_lead_method(std::string_view name) {
  if (name == "marker") return LeadMethod::Marker;
  if (name == "colour" || name == "color") return LeadMethod::Colour;
  if (name == "marker_then_colour" || name == "marker_then_color") return LeadMethod::MarkerThenColour;
  throw std::invalid_argument("unknown lead detection method '" + std::string(name) +
                              "' (expected marker, colour or marker_then_colour)");
}

std::string to_string(LeadMethod m) {
  switch (m) {
    case LeadMethod::Marker: return "marker";
    case LeadMethod::Colour: return "colour";
    case LeadMethod::MarkerThenColour: return "marker_then_colour";
  }
  return "?";
}

int parse_aruco_dictionary(std::string_view name) {
  for (std::size_t i = 0; i < kDictionaries.size(); ++i)
    if (kDictionaries[i] == name) return static_cast<int>(i);
  throw std::invalid_argument("unknown ArUco dictionary '" + std::string(name) +
                              "' (expected an OpenCV name such as DICT_4X4_50)");
}

void LeadDetectorSettings::validate() const {
  auto bad = [](const std::string& what) { throw std::invalid_argument("lead detector settings: " + what); };
  const int dict = parse_aruco_dictionary(dictionary);
  const int size = cv::aruco::getPredefinedDictionary(dict)->bytesList.rows;
  if (marker_id < 0 || marker_id >= size)
    bad("marker_id " + std::to_string(marker_id) + " is not in " + dictionary + " (0.." +
        std::to_string(size - 1) + ")");
  if (!(upscale >= 1)) bad("upscale must be >= 1, got " + std::to_string(upscale));
  if (roi_half_px < 8) bad("roi_half_px must be >= 8, got " + std::to_string(roi_half_px));
  auto in = [](int v, int hi) { return v >= 0 && v <= hi; };
  if (!in(colour.h_lo, 179) || !in(colour.h_hi, 179)) bad("colour hue must be in [0, 179]");
  if (!in(colour.s_lo, 255) || !in(colour.s_hi, 255) || colour.s_lo > colour.s_hi)
    bad("colour saturation must be 0 <= s_lo <= s_hi <= 255");
  if (!in(colour.v_lo, 255) || !in(colour.v_hi, 255) || colour.v_lo > colour.v_hi)
    bad("colour value must be 0 <= v_lo <= v_hi <= 255");
  if (!(min_blob_area_px > 0)) bad("min_blob_area_px must be > 0, got " + std::to_string(min_blob_area_px));
}

Eigen::Vector2d diagonal_intersection(const std::array<Eigen::Vector2d, 4>& c) {
  // c0 + s (c2 - c0) = c1 + t (c3 - c1)
  Eigen::Matrix2d A;
  A.col(0) = c[2] - c[0];
  A.col(1) = -(c[3] - c[1]);
  const double det = A.determinant();
  if (std::abs(det) < 1e-9) return 0.25 * (c[0] + c[1] + c[2] + c[3]);
  const Eigen::Vector2d st = A.inverse() * (c[1] - c[0]);
  return c[0] + st(0) * (c[2] - c[0]);
}

cv::Mat lead_search_grey(const cv::Mat& image, const std::string& who) {
  if (image.empty() || image.depth() != CV_8U || (image.channels() != 1 && image.channels() != 3))
    throw std::invalid_argument(who + ": expected an 8-bit grey or BGR image");
  cv::Mat grey = image;
  if (image.channels() == 3) cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  return grey;
}

ExclusionBox exclusion_box(const LeadDetection& d, double scale, double min_half_px) {
  const double h = std::max(min_half_px, scale * d.size_px);
  return ExclusionBox{d.uv, h, h};
}

LeadDetector::LeadDetector(const LeadDetectorSettings& settings) : cfg_(settings) {
  cfg_.validate();
  dictionary_ = parse_aruco_dictionary(cfg_.dictionary);
}

std::optional<cv::Rect> LeadFinder::window(cv::Size, const Eigen::Vector2d&) const { return std::nullopt; }

std::optional<LeadDetection> LeadFinder::detect_in_window(const cv::Mat&, const Eigen::Vector2d&) {
  throw std::logic_error("LeadFinder::detect_in_window: this finder reads the whole image");
}

namespace {

// The marker's search region: (2 half + 1)^2 pixels around the prediction, cut to the image;
// nothing when too little of it is left.
std::optional<cv::Rect> marker_region(cv::Size size, const Eigen::Vector2d& predicted, int half) {
  const cv::Rect roi = cv::Rect(cvRound(predicted.x()) - half, cvRound(predicted.y()) - half, 2 * half + 1,
                                2 * half + 1) &
                       cv::Rect(0, 0, size.width, size.height);
  if (roi.width > 8 && roi.height > 8) return roi;
  return std::nullopt;
}

}  // namespace

std::optional<cv::Rect> LeadDetector::window(cv::Size size, const Eigen::Vector2d& predicted) const {
  if (cfg_.method != LeadMethod::Marker) return std::nullopt;
  return marker_region(size, predicted, cfg_.roi_half_px);
}

std::optional<LeadDetection> LeadDetector::detect_in_window(const cv::Mat& image, const Eigen::Vector2d& predicted) {
  if (!window(image.size(), predicted))
    throw std::logic_error("LeadDetector::detect_in_window: no window (a colour panel, or a prediction off the image)");
  return detect_marker(lead_search_grey(image, "LeadDetector::detect_in_window"), predicted, false);
}

std::optional<LeadDetection> LeadDetector::detect(const cv::Mat& image,
                                                  const std::optional<Eigen::Vector2d>& predicted) {
  if (image.empty()) throw std::invalid_argument("LeadDetector::detect: empty image");
  if (image.depth() != CV_8U)
    throw std::invalid_argument("LeadDetector::detect: expected an 8-bit image, got depth " +
                                std::to_string(image.depth()));
  cv::Mat bgr, grey;
  if (image.channels() == 1) {
    grey = image;
  } else if (image.channels() == 3) {
    bgr = image;
    cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  } else if (image.channels() == 4) {
    cv::cvtColor(image, bgr, cv::COLOR_BGRA2BGR);
    cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
  } else {
    throw std::invalid_argument("LeadDetector::detect: expected 1, 3 or 4 channels, got " +
                                std::to_string(image.channels()));
  }
  if (cfg_.method != LeadMethod::Colour) {
    if (auto d = detect_marker(grey, predicted)) return d;
  }
  if (cfg_.method != LeadMethod::Marker && !bgr.empty()) return detect_colour(bgr, predicted);
  return std::nullopt;
}

std::optional<LeadDetection> LeadDetector::detect_marker(const cv::Mat& grey,
                                                         const std::optional<Eigen::Vector2d>& predicted,
                                                         bool whole_image) const {
  const auto dict = cv::aruco::getPredefinedDictionary(dictionary_);
  auto params = cv::aruco::DetectorParameters::create();
  params->minMarkerPerimeterRate = 0.01;  // down to ~2.5 px per side on 1000 px: small markers
  params->adaptiveThreshWinSizeMin = 3;
  params->adaptiveThreshWinSizeMax = 23;
  params->adaptiveThreshWinSizeStep = 10;
  params->cornerRefinementMethod = cv::aruco::CORNER_REFINE_NONE;  // own refinement below

  struct Found {
    std::array<Eigen::Vector2d, 4> c;
  };
  auto run = [&](const cv::Mat& img, double scale, cv::Point2d offset) {
    std::vector<std::vector<cv::Point2f>> corners;
    std::vector<int> ids;
    cv::aruco::detectMarkers(img, dict, corners, ids, params);
    std::vector<Found> out;
    for (std::size_t m = 0; m < ids.size(); ++m) {
      if (ids[m] != cfg_.marker_id) continue;
      std::vector<cv::Point2f> pts = corners[m];
      if (cfg_.subpixel) {
        double side = 0;
        for (int k = 0; k < 4; ++k) side += cv::norm(pts[k] - pts[(k + 1) % 4]) / 4;
        const int win = std::clamp(static_cast<int>(std::lround(side / 12)), 2, 5);
        cv::cornerSubPix(img, pts, cv::Size(win, win), cv::Size(-1, -1),
                         cv::TermCriteria(cv::TermCriteria::EPS | cv::TermCriteria::COUNT, 30, 0.01));
      }
      Found f;
      // Back to full-image pixels: a pixel centre x' of the scaled crop is (x' + 0.5)/s - 0.5.
      for (int k = 0; k < 4; ++k)
        f.c[k] = Eigen::Vector2d((pts[k].x + 0.5) / scale - 0.5 + offset.x,
                                 (pts[k].y + 0.5) / scale - 0.5 + offset.y);
      out.push_back(f);
    }
    return out;
  };

  // With a prediction: its neighbourhood first (cheap), then that neighbourhood upscaled (small
  // markers), then the whole frame (a bad prediction).
  std::vector<Found> found;
  if (predicted) {
    if (const auto roi = marker_region(grey.size(), *predicted, cfg_.roi_half_px)) {
      const cv::Mat crop = grey(*roi).clone();  // nothing outside the region is read
      found = run(crop, 1.0, cv::Point2d(roi->x, roi->y));
      if (found.empty() && cfg_.upscale > 1.0) {
        cv::Mat up;
        cv::resize(crop, up, cv::Size(), cfg_.upscale, cfg_.upscale, cv::INTER_CUBIC);
        found = run(up, cfg_.upscale, cv::Point2d(roi->x, roi->y));
      }
    }
  }
  if (found.empty() && whole_image) found = run(grey, 1.0, {0, 0});
  if (found.empty()) return std::nullopt;

  const auto pick = std::min_element(found.begin(), found.end(), [&](const Found& a, const Found& b) {
    return distance_to(predicted, diagonal_intersection(a.c)) < distance_to(predicted, diagonal_intersection(b.c));
  });
  LeadDetection d;
  d.source = LeadSource::Marker;
  d.corners = pick->c;
  d.uv = diagonal_intersection(pick->c);
  for (int k = 0; k < 4; ++k) d.size_px += (pick->c[k] - pick->c[(k + 1) % 4]).norm() / 4;
  d.confidence = std::min(1.0, d.size_px / 16.0) * (found.size() > 1 ? 0.5 : 1.0);
  return d;
}

std::optional<LeadDetection> LeadDetector::detect_colour(const cv::Mat& bgr,
                                                         const std::optional<Eigen::Vector2d>& predicted) const {
  cv::Mat hsv, mask;
  cv::cvtColor(bgr, hsv, cv::COLOR_BGR2HSV);
  const auto& c = cfg_.colour;
  if (c.h_lo <= c.h_hi) {
    cv::inRange(hsv, cv::Scalar(c.h_lo, c.s_lo, c.v_lo), cv::Scalar(c.h_hi, c.s_hi, c.v_hi), mask);
  } else {  // hue wraps through 180
    cv::Mat m1, m2;
    cv::inRange(hsv, cv::Scalar(c.h_lo, c.s_lo, c.v_lo), cv::Scalar(179, c.s_hi, c.v_hi), m1);
    cv::inRange(hsv, cv::Scalar(0, c.s_lo, c.v_lo), cv::Scalar(c.h_hi, c.s_hi, c.v_hi), m2);
    mask = m1 | m2;
  }
  // Opening removes isolated pixels of the ground that happen to fall in the range.
  cv::morphologyEx(mask, mask, cv::MORPH_OPEN, cv::getStructuringElement(cv::MORPH_RECT, {3, 3}));
  cv::Mat labels, stats, centroids;
  const int n = cv::connectedComponentsWithStats(mask, labels, stats, centroids, 8, CV_32S);
  int best = -1;
  double best_key = std::numeric_limits<double>::infinity();
  for (int i = 1; i < n; ++i) {
    const int area = stats.at<int>(i, cv::CC_STAT_AREA);
    if (area < cfg_.min_blob_area_px) continue;
    const Eigen::Vector2d uv(centroids.at<double>(i, 0), centroids.at<double>(i, 1));
    const double key = predicted ? distance_to(predicted, uv) : -area;  // nearest, else largest
    if (key < best_key) {
      best_key = key;
      best = i;
    }
  }
  if (best < 0) return std::nullopt;
  LeadDetection d;
  d.source = LeadSource::Colour;
  d.uv = Eigen::Vector2d(centroids.at<double>(best, 0), centroids.at<double>(best, 1));
  const double area = stats.at<int>(best, cv::CC_STAT_AREA);
  const double box = static_cast<double>(stats.at<int>(best, cv::CC_STAT_WIDTH)) *
                     stats.at<int>(best, cv::CC_STAT_HEIGHT);
  d.size_px = std::sqrt(area);
  d.confidence = 0.5 * area / box;
  return d;
}

}  // namespace wingman::vision
