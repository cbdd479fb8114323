// The benchmark of lead detectors: each frame's detection (from a built-in detector, or anyone's in
// the lead detections file format) against the lead's ground truth in that frame (a dataset's
// cam0_lead0), scored over all frames and per lead, ground image, distance and visible share
// (docs/frontend.md, lead detectors).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "geometry/lead_image.hpp"

namespace wingman::frontend_bench {

// One camera frame: where the lead is, and what the detector found.
struct LeadFrame {
  std::string dataset, agent;
  std::int64_t t_ns = 0;
  std::string lead, ground;  // the dataset's lead model and ground image, by their files' stems
  int width = 0, height = 0;
  geometry::LeadImage truth;
  std::optional<Eigen::Vector2d> detected;
  double cpu_ms = std::numeric_limits<double>::quiet_NaN();  // the detector's, when it ran here
};

struct LeadScoreOptions {
  // A frame shows the lead when x_h projects inside the image and at least this share of the
  // lead is visible: the frames the detection rate counts.
  double min_visible = 0.8;
  // A detection within this many pixels of x_h's projection is the lead; any other is false.
  double match_px = 10;
  void validate() const;  // throws std::invalid_argument naming the bad value
};

struct LeadScore {
  std::string by, key;  // "all"/"all", "lead"/"truck", "distance"/"8-12 m", "visible"/"0.5-0.8", ...
  long frames = 0;
  long showing = 0;   // frames that show the lead (LeadScoreOptions::min_visible; for the
                      // visible-share rows: x_h in the image)
  long found = 0;     // of those, frames with a detection within match_px
  long false_detections = 0;  // detections farther than match_px (over every frame)
  double median_px = std::numeric_limits<double>::quiet_NaN(), p95_px = std::numeric_limits<double>::quiet_NaN();
  double cpu_ms = std::numeric_limits<double>::quiet_NaN();  // mean per frame
  double rate() const { return showing > 0 ? static_cast<double>(found) / showing : 0.0; }
  double false_per_frame() const { return frames > 0 ? static_cast<double>(false_detections) / frames : 0.0; }
};

// Rows: all; per lead; per ground; per distance (m, x_h from the camera); per visible share.
std::vector<LeadScore> score_leads(const std::vector<LeadFrame>& frames, const LeadScoreOptions& o);
std::string lead_scores_table(const std::vector<LeadScore>& scores, const std::string& detector);
std::string lead_scores_json(const std::vector<LeadScore>& scores, const std::string& detector, const LeadScoreOptions& o);

// The lead detections file: a CSV with the header line
//   #dataset,agent,timestamp [ns],u [px],v [px],score
// one row per detection (none for a frame without); of several for one frame, the highest score's
// is the detection. dataset: the dataset directory's name (empty when only one is scored).
inline constexpr const char* kLeadDetectionsHeader = "#dataset,agent,timestamp [ns],u [px],v [px],score";
struct LeadDetectionRow {
  std::string dataset, agent;
  std::int64_t t_ns = 0;
  Eigen::Vector2d uv = Eigen::Vector2d::Zero();
  double score = 1;
};
// Throws MatchInputError "<file>:<line>: what" for a malformed row.
std::vector<LeadDetectionRow> read_lead_detections(const std::filesystem::path& file);
std::string lead_detections_csv(const std::vector<LeadDetectionRow>& rows);
// Each frame's detection from the rows (the highest score of the frame's), by dataset, agent and
// time stamp; a row naming no frame of the datasets is an error naming the file.
void attach_detections(std::vector<LeadFrame>& frames, const std::vector<LeadDetectionRow>& rows,
                       const std::filesystem::path& file);

}  // namespace wingman::frontend_bench
