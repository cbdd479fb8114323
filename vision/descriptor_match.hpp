// Plain descriptor matching between two images, without poses: brute force, Lowe's ratio test
// and a mutual (cross) check, as the image-matching benchmarks run a detector's own descriptors
// (`wingman bench-frontend`). The SLAM loop's matchers (tracking.hpp, cross_match.hpp) add
// prediction gates and geometry on top.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

#include "vision/features.hpp"

namespace wingman::vision {

struct DescriptorMatchSettings {
  double ratio = 0.8;   // best < ratio * second best (A to B); 1 drops only ties
  bool mutual = true;   // keep a match only if A's best in B has A's keypoint as its own best
  void validate() const;  // throws std::invalid_argument naming the bad value
};

// Matches of a's keypoints (queryIdx) to b's (trainIdx), best distance first. The features must
// share a descriptor type.
std::vector<cv::DMatch> match_descriptors(const Features& a, const Features& b,
                                          const DescriptorMatchSettings& settings = {});

}  // namespace wingman::vision
