// One built-in detector outside the SLAM loop, run into the matching benchmark's file format
// (frontend_bench/match_files.hpp, docs/frontend.md): what `wingman bench-frontend` scores.
#pragma once

#include <filesystem>
#include <functional>
#include <vector>

#include "datasets/dataset.hpp"
#include "frontend_bench/match_files.hpp"
#include "vision/descriptor_match.hpp"
#include "vision/features.hpp"

namespace wingman::frontend_bench {

// One built-in detector outside the SLAM loop: each frame of the pairs detected and described
// once (timed), each pair matched by descriptor, keypoints and matches written under dir in the
// benchmark's file format (a condition's frames under dir/conditions/<condition>/).
struct BuiltinFrontendOptions {
  vision::FeatureSettings features;
  vision::DescriptorMatchSettings matching;
};
struct BuiltinFrontendRun {
  int frames = 0;
  double detect_ms = 0;      // detection + description, all frames, wall time
  double detect_cpu_ms = 0;  // the same in CPU time of the process (all of OpenCV's threads)
  long keypoints = 0;
};
BuiltinFrontendRun run_builtin_frontend(const Conditions& sets,
                                        const std::vector<FramePair>& pairs,
                                        const BuiltinFrontendOptions& options,
                                        const std::filesystem::path& dir,
                                        const std::function<void(int, int)>& progress = {});

}  // namespace wingman::frontend_bench
