// Scores of a feature frontend's keypoints and matches against the true correspondences of a
// rendered dataset (frontend_bench/correspondence.hpp), as the image-matching literature scores them, with
// the depth in place of a homography (docs/frontend.md, benchmark of feature frontends):
// - repeatability(ε): of A's keypoints whose true correspondence is visible in B, the fraction
//   with a keypoint of B within ε of it;
// - precision(ε): of the matches, the fraction whose B keypoint lies within ε of the true
//   correspondence of their A keypoint (a match of a keypoint with none is wrong);
// - recall(ε): distinct A keypoints correctly matched, over the A keypoints that could have been
//   (the repeatable ones at ε);
// - localisation error: mean distance to the truth of the matches correct at localisation_px.
// Counts are pooled over the pairs of a group before the ratios are taken.
#pragma once

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "datasets/dataset.hpp"
#include "frontend_bench/correspondence.hpp"
#include "frontend_bench/match_files.hpp"

namespace wingman::frontend_bench {

struct ScoreOptions {
  std::vector<double> thresholds_px{1, 2, 3, 4, 5, 6, 7, 8, 9, 10};  // increasing
  double localisation_px = 3;
  // Baseline bins of each pair type, metres: [0, e0), [e0, e1), ..., [e_last, inf).
  std::vector<double> baseline_edges_m{0.5, 1.5, 3.0};
  CorrespondenceOptions correspondence;
  void validate() const;  // throws std::invalid_argument naming the bad value
};

struct MatchCounts {
  long pairs = 0, keypoints_a = 0, keypoints_b = 0, covisible = 0, matches = 0;
  std::vector<long> repeatable, correct, correct_a;  // one per threshold
  double localisation_sum_px = 0;
  long localised = 0;

  explicit MatchCounts(std::size_t thresholds = 0)
      : repeatable(thresholds, 0), correct(thresholds, 0), correct_a(thresholds, 0) {}
  void add(const MatchCounts& o);
  double repeatability(std::size_t i) const;
  double precision(std::size_t i) const;
  double recall(std::size_t i) const;
  double localisation_px() const;  // NaN without correct matches
};

// One pair's counts.
MatchCounts score_pair(const FrameTruth& a, const FrameTruth& b, const std::vector<Keypoint>& kp_a,
                       const std::vector<Keypoint>& kp_b, const std::vector<Match>& matches,
                       const ScoreOptions& options);

// The counts of every pair of a submission directory (keypoints/, conditions/, matches/), each
// file checked as it is read (MatchInputError naming file and line); frame B of a pair comes from
// its condition's dataset. `progress(done, total)` after each pair.
std::vector<MatchCounts> score_directory(const Conditions& sets,
                                         const std::vector<FramePair>& pairs,
                                         const std::filesystem::path& dir,
                                         const ScoreOptions& options,
                                         const std::function<void(int, int)>& progress = {});

// Pooled counts per group: per condition (the reference first, then the others in the order of
// their first pair) all its pairs, then per pair type all baselines and each baseline bin holding
// pairs. `type` is "all", "temporal", "cross" or "same-instant"; `baseline` "all" or a bin,
// "lo-hi m" ([lo, hi)) or ">=lo m".
struct GroupScore {
  std::string condition, type, baseline;
  MatchCounts counts;
};
std::vector<GroupScore> group_scores(const std::vector<FramePair>& pairs,
                                     const std::vector<MatchCounts>& counts,
                                     const ScoreOptions& options);

}  // namespace wingman::frontend_bench
