// The frame pairs of the matching benchmark and the files in which any feature frontend hands in
// its keypoints and matches (docs/frontend.md, benchmark of feature frontends):
//   pairs.csv                      pair_id,agent_a,t_ns_a,agent_b,t_ns_b,type,baseline_m,condition
//   <dir>/keypoints/<agent>/<t_ns>.csv   x,y[,score]         row k (from 0) is keypoint k
//   <dir>/conditions/<condition>/keypoints/<agent>/<t_ns>.csv   a condition's frames (B)
//   <dir>/matches/<pair_id>.csv          index_a,index_b[,score]
// Pixels follow OpenCV's convention ((0,0) is the centre of the top-left pixel). Every reader
// error names the file and line (MatchInputError), so a wrong submission is bad input.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "datasets/dataset.hpp"
#include "frontend_bench/conditions.hpp"
#include "frontend_bench/correspondence.hpp"

namespace wingman::frontend_bench {

// A pairs, keypoints, matches or lead detections file that cannot be used: "<file>:<line>: what".
class MatchInputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// One UAV at two times; two UAVs at one time; one UAV at one instant under another condition
// (HPatches' illumination split: the pose is the same, only the imaging differs).
enum class PairType { Temporal, Cross, SameInstant };
inline constexpr PairType kPairTypes[] = {PairType::Temporal, PairType::Cross, PairType::SameInstant};
const char* to_string(PairType t);  // temporal, cross, same-instant

struct FramePair {
  int id = 0;
  std::string agent_a;  // frame A: always the reference dataset's
  std::int64_t t_a = 0;
  std::string agent_b;  // frame B: the condition's
  std::int64_t t_b = 0;
  PairType type = PairType::Temporal;
  double baseline_m = 0;  // distance between the true camera centres
  std::string condition = kReference;
};

struct PairOptions {
  int stride = 10;                 // a pair starts at every stride-th frame
  std::vector<int> gaps{1, 5, 10}; // temporal pairs: frame k with frame k + gap, per gap
  bool cross = true;               // cross pairs: every two UAVs at frame k
  void validate() const;           // throws std::invalid_argument naming the bad value
};

// The benchmark's pairs, in a fixed order, ids 0, 1, ...: the reference's own (per start frame: the
// temporal pairs of each UAV and gap, then the cross pairs), then per condition the same list
// with B from the condition, each start frame led by its same-instant pairs (gap 0).
std::vector<FramePair> make_pairs(const Conditions& sets, const PairOptions& options = {});
std::vector<FramePair> make_pairs(const datasets::Dataset& ds, const PairOptions& options = {});

std::string pairs_csv(const std::vector<FramePair>& pairs);
// Reads a pairs file (with the condition column, or the 7 columns before it: all reference) and
// checks every pair against the datasets: a known condition, agents with a camera, frames the
// datasets have, unique ids, a same-instant pair one frame under a condition; the baseline is
// recomputed from the truth. Throws MatchInputError.
std::vector<FramePair> read_pairs(const std::filesystem::path& file, const Conditions& sets);
std::vector<FramePair> read_pairs(const std::filesystem::path& file, const datasets::Dataset& ds);

// The truth of one frame of a dataset (its depth loaded). Throws datasets::DatasetError for a
// frame the dataset lacks.
FrameTruth frame_truth(const datasets::Dataset& ds, const std::string& agent, std::int64_t t_ns);

struct Keypoint {
  Eigen::Vector2d uv = Eigen::Vector2d::Zero();
  double score = 0;
};
struct Match {
  int a = 0, b = 0;  // keypoint indices in A and in B
};

std::filesystem::path keypoints_file(const std::filesystem::path& dir, const std::string& agent,
                                     std::int64_t t_ns);  // a reference frame
std::filesystem::path keypoints_file(const std::filesystem::path& dir, const std::string& condition,
                                     const std::string& agent, std::int64_t t_ns);
std::filesystem::path matches_file(const std::filesystem::path& dir, int pair_id);

// Keypoints inside a width x height image ([-0.5, width - 0.5]); throws MatchInputError for a
// missing file, a bad header, a malformed row or a keypoint outside the image.
std::vector<Keypoint> read_keypoints(const std::filesystem::path& file, int width, int height);
// Matches whose indices lie in [0, n_a) and [0, n_b); throws MatchInputError otherwise.
std::vector<Match> read_matches(const std::filesystem::path& file, int n_a, int n_b);

// DIR/timings.csv, optional: `agent,t_ns,ms` (reference frames) or `condition,agent,t_ns,ms`, a
// frontend's detection + description wall time per frame. The mean over the frames the pairs use;
// nothing when DIR has no timings file. A frame of the pairs missing from it, or a malformed row,
// throws MatchInputError naming the file and line.
std::optional<double> mean_frame_ms(const std::filesystem::path& dir, const std::vector<FramePair>& pairs);

// Writers (the built-in detectors of `wingman bench-frontend` use them).
void write_keypoints(const std::filesystem::path& file, const std::vector<Keypoint>& keypoints);
void write_matches(const std::filesystem::path& file, const std::vector<Match>& matches);

}  // namespace wingman::frontend_bench
