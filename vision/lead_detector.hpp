// Lead-agent detector: finds the lead in an image and returns the pixel of its reference point
// (docs/design.md, frames and conventions: the centre of its roof marker), or nothing. Primary cue: an ArUco marker
// (dictionary and id configurable, DICT_4X4_50 id 0 by default); its centre is the intersection of
// the marker's diagonals, which is the exact image of the square's centre under perspective (the
// mean of the corners is not). Fallback: a distinctive colour panel (HSV range) whose largest blob
// centroid is returned.
#pragma once

#include <Eigen/Core>
#include <array>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <string_view>

#include "vision/features.hpp"

namespace wingman::vision {

enum class LeadMethod { Marker, Colour, MarkerThenColour };
// "marker" | "colour" | "marker_then_colour" (also "color", "marker_then_color").
LeadMethod parse_lead_method(std::string_view name);
std::string to_string(LeadMethod method);
// OpenCV's predefined dictionary names, e.g. "DICT_4X4_50", "DICT_APRILTAG_36h11"; returns the
// cv::aruco::PREDEFINED_DICTIONARY_NAME value.
int parse_aruco_dictionary(std::string_view name);

// HSV range in OpenCV units (H in [0, 180), S and V in [0, 255]); the hue wraps when h_lo > h_hi
// (for reds).
struct HsvRange {
  int h_lo = 140, h_hi = 170;  // magenta: rare on the ground
  int s_lo = 120, s_hi = 255;
  int v_lo = 80, v_hi = 255;
};

struct LeadDetectorSettings {
  LeadMethod method = LeadMethod::Marker;
  std::string dictionary = "DICT_4X4_50";
  int marker_id = 0;
  // Corner refinement by cv::cornerSubPix with a window that scales with the marker (a fixed
  // window would reach the next corner on a 20 px marker).
  bool subpixel = true;
  // With a prediction, the (2 roi_half_px + 1)^2 region around it is searched first, then the
  // same region upscaled by `upscale` (helps markers under ~20 px; 1 disables), then the whole
  // frame. A marker cut by the region's edge is found in the whole-frame pass.
  double upscale = 2.0;
  int roi_half_px = 64;
  // Colour panel.
  HsvRange colour{};
  double min_blob_area_px = 30;

  void validate() const;  // throws std::invalid_argument naming the bad value
};

enum class LeadSource { Marker, Colour, Learned, Motion };

struct LeadDetection {
  Eigen::Vector2d uv = Eigen::Vector2d::Zero();  // the reference point, docs/design.md, frames and conventions pixels
  // Heuristic in [0, 1]: markers min(1, side / 16 px), halved when several markers with the id
  // are seen; colour blobs 0.5 x their fill of the bounding box.
  double confidence = 0;
  LeadSource source = LeadSource::Marker;
  std::array<Eigen::Vector2d, 4> corners{};  // marker corners (clockwise from top-left of the
                                             // marker), zero for colour blobs
  double size_px = 0;  // mean side (marker) or sqrt(area) (colour); 0: not measured (learned)
};

// What finds the lead in a frame: a marker or a colour panel (LeadDetector), or the lead itself
// (LearnedLeadDetector, MotionLeadDetector). With a prediction, the detection nearest to it,
// searched near it first. A finder may keep state from frame to frame (the motion detector keeps
// earlier frames): one finder per camera, given its frames in order.
class LeadFinder {
 public:
  virtual ~LeadFinder() = default;
  virtual std::optional<LeadDetection> detect(const cv::Mat& image,
                                              const std::optional<Eigen::Vector2d>& predicted = std::nullopt) = 0;
  // The window detect() searches first around `predicted` in an image of `size`: no pixel outside
  // it is read unless the lead is not found there. Nothing: the finder reads the whole image.
  virtual std::optional<cv::Rect> window(cv::Size size, const Eigen::Vector2d& predicted) const;
  // detect() without the whole-image pass: the lead found in window(), or nothing. Only for a
  // finder with a window (a caller holding the window's pixels alone, as a region render).
  virtual std::optional<LeadDetection> detect_in_window(const cv::Mat& image, const Eigen::Vector2d& predicted);
};

class LeadDetector final : public LeadFinder {
 public:
  explicit LeadDetector(const LeadDetectorSettings& settings = {});
  const LeadDetectorSettings& settings() const { return cfg_; }
  // `image`: 8-bit BGR (as cv::imread) or grey (no colour fallback then). With a prediction,
  // the detection nearest to it is returned when several qualify.
  std::optional<LeadDetection> detect(const cv::Mat& image,
                                      const std::optional<Eigen::Vector2d>& predicted = std::nullopt) override;
  // The marker's region around the prediction; nothing for a colour panel (read over the image).
  std::optional<cv::Rect> window(cv::Size size, const Eigen::Vector2d& predicted) const override;
  std::optional<LeadDetection> detect_in_window(const cv::Mat& image, const Eigen::Vector2d& predicted) override;

 private:
  std::optional<LeadDetection> detect_marker(const cv::Mat& grey, const std::optional<Eigen::Vector2d>& predicted,
                                             bool whole_image = true) const;
  std::optional<LeadDetection> detect_colour(const cv::Mat& bgr,
                                             const std::optional<Eigen::Vector2d>& predicted) const;
  LeadDetectorSettings cfg_;
  int dictionary_ = 0;
};

// `image` (8-bit grey, or BGR) as grey; throws std::invalid_argument naming `who` for any other.
cv::Mat lead_search_grey(const cv::Mat& image, const std::string& who);

// A box around a detection to keep out of the map features (features.hpp), `scale` times the
// detection's size on each side of the centre, at least min_half_px.
ExclusionBox exclusion_box(const LeadDetection& d, double scale = 1.5, double min_half_px = 20);

// Intersection of the diagonals 0-2 and 1-3 of a quadrilateral; the corner mean if they are
// parallel.
Eigen::Vector2d diagonal_intersection(const std::array<Eigen::Vector2d, 4>& c);

}  // namespace wingman::vision
