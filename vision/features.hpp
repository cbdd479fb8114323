// Feature detection and description for the frontend: ORB (default), AKAZE, SIFT, or GFTT corners
// described with ORB. Keypoints are spread over the image by grid bucketing, and image boxes (the
// lead agent's region, which moves and must not feed the map) are kept out.
#pragma once

#include "geometry/settings.hpp"

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>
#include <string>
#include <string_view>
#include <vector>

namespace wingman::vision {

enum class DetectorKind { Orb, Akaze, Sift, GfttOrb };

// "orb" | "akaze" | "sift" | "gftt_orb"; anything else throws std::invalid_argument naming it.
DetectorKind parse_detector(std::string_view name);
std::string to_string(DetectorKind kind);

struct FeatureSettings {
  DetectorKind kind = DetectorKind::Orb;
  int max_features = 1000;
  // Bucketing grid: each cell keeps at most ceil(max_features / cells) of its strongest keypoints
  // first, then the leftover budget goes to the strongest remaining ones anywhere. 1 x 1 disables.
  int grid_cols = 8, grid_rows = 8;
  // The detector is asked for this many times max_features before bucketing, so that weak cells
  // still have candidates.
  double oversample = 2.0;
  int orb_fast_threshold = 12;   // lower than OpenCV's 20: rendered ground is often low-contrast
  int orb_levels = 4;            // pyramid levels (scale changes between UAVs are small)
  float orb_scale_factor = 1.2f;
  // Which corner score ranks FAST's candidates: Harris's (OpenCV's default) or FAST's own, which
  // skips the Harris pass but was no faster on the paper scene (docs/studies/speed.md).
  cv::ORB::ScoreType orb_score = cv::ORB::HARRIS_SCORE;
  double akaze_threshold = 0.0005;
  double gftt_quality = 0.005, gftt_min_distance = 5.0;
  double sift_contrast = 0.02;

  void validate() const;  // throws std::invalid_argument naming the bad value

  // The keys of the scenario's frontend: section that choose and tune the detector.
  template <class V>
  void visit(V& v) {
    v.choice("detector", kind,
             {{"orb", DetectorKind::Orb}, {"akaze", DetectorKind::Akaze}, {"sift", DetectorKind::Sift},
              {"gftt_orb", DetectorKind::GfttOrb}});
    v("max_features", max_features, geometry::in(1, 100000));
    v.pair("grid", grid_cols, grid_rows, geometry::ge(1));  // [columns, rows]
    v.section("orb", [&](auto& o) {
      o("fast_threshold", orb_fast_threshold, geometry::ge(1));
      o("levels", orb_levels, geometry::in(1, 16));
      o("scale_factor", orb_scale_factor, geometry::in(1, 2, true, false));
      o.choice("score", orb_score, {{"harris", cv::ORB::HARRIS_SCORE}, {"fast", cv::ORB::FAST_SCORE}});
    });
    v.section("akaze", [&](auto& a) { a("threshold", akaze_threshold, geometry::gt(0)); });
    v.section("sift", [&](auto& a) { a("contrast_threshold", sift_contrast, geometry::gt(0)); });
    v.section("gftt", [&](auto& g) {
      g("quality", gftt_quality, geometry::in(0, 1, true, true));
      g("min_distance_px", gftt_min_distance, geometry::ge(0));
    });
  }
};

// An axis-aligned pixel box kept free of features, e.g. around the lead's detected or predicted
// pixel. Boxes are clipped to the image.
struct ExclusionBox {
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  double half_width = 0, half_height = 0;
  bool contains(const Eigen::Vector2d& uv) const;
};

// Keypoints of one image and one descriptor row per keypoint.
struct Features {
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;                 // CV_8U (binary, Hamming) or CV_32F (SIFT, L2)
  int norm = cv::NORM_HAMMING;         // cv::NORM_HAMMING or cv::NORM_L2
  int size() const { return static_cast<int>(keypoints.size()); }
  Eigen::Vector2d pixel(int i) const { return {keypoints[i].pt.x, keypoints[i].pt.y}; }
};

class FeatureExtractor {
 public:
  explicit FeatureExtractor(const FeatureSettings& settings = {});
  const FeatureSettings& settings() const { return cfg_; }
  // Detects and describes; colour images are converted to grey. Keypoint coordinates follow
  // docs/design.md, frames and conventions (pixel (0,0) is the centre of the top-left pixel; ORB's upper pyramid levels
  // are corrected to it, orb_keypoints_to_pixel_centres).
  Features detect(const cv::Mat& image, const std::vector<ExclusionBox>& exclude = {}) const;
  // Active search: detects and describes only inside `regions` (rectangles of the image, best
  // disjoint). Each is cropped with crop_margin() pixels of context, enough for a keypoint inside
  // it to be found and described at every pyramid level from the same pixels as in the whole
  // frame. The detector's candidates are scaled to the pixels of each crop and bucketing keeps the
  // whole frame's share per grid cell, so the keypoints' density matches the whole-frame path's.
  // Cost grows with the crops' area.
  Features detect_in(const cv::Mat& image, const std::vector<cv::Rect>& regions,
                     const std::vector<ExclusionBox>& exclude = {}) const;
  // Context around a region, in pixels. ORB: the 22 px its descriptor's rotated 31 px patch
  // reaches (ceil(15 sqrt 2)), at the top pyramid level, plus one; inside a crop ORB runs with that
  // edge threshold instead of the 31 px the whole frame keeps from its own edge.
  int crop_margin() const;
  int norm() const;

 private:
  struct Crop;
  static constexpr int kOrbEdge = 31, kOrbCropEdge = 22;
  cv::Ptr<cv::Feature2D> make_detector(int candidates, int orb_edge) const;
  bool near_frame_edge(const cv::KeyPoint& k, const cv::Rect& frame) const;
  void detect_crop(const cv::Mat& grey, const cv::Mat& mask, Crop& crop, int candidates) const;
  void describe_crop(const cv::Mat& grey, Crop& crop) const;

  FeatureSettings cfg_;
  cv::Ptr<cv::Feature2D> detector_, describer_;
};

// OpenCV's ORB reports a keypoint of pyramid level L at its level coordinates times
// scale_factor^L, which ignores cv::resize's half-pixel alignment and the level's rounded size:
// 0.1-0.7 px off in level 0's pixels, different per level, so a point seen at different levels
// by two cameras (Quad 1 at 15 m, Quad 2 at 17 m) gets a biased disparity. This re-expresses
// every keypoint of a level above 0 in level 0's pixel-centre coordinates (docs/design.md, frames and conventions).
void orb_keypoints_to_pixel_centres(std::vector<cv::KeyPoint>& keypoints, cv::Size image,
                                    float scale_factor);

// Keeps at most `budget` keypoints: per grid cell the strongest first, then the strongest left.
std::vector<cv::KeyPoint> bucket_keypoints(const std::vector<cv::KeyPoint>& keypoints, int width,
                                           int height, int grid_cols, int grid_rows, int budget);

// Default acceptance threshold on descriptor distance for a descriptor type: a quarter of the bits
// for binary descriptors (64 of ORB's 256), 250 for SIFT (descriptors have norm about 512).
double default_max_descriptor_distance(const cv::Mat& descriptors);

}  // namespace wingman::vision
