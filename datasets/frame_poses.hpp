// The poses a dataset's frame was taken from (docs/datasets.md, shutter and exposure), rebuilt from
// what the dataset holds: cam0_pose0's pose of the frame under a global shutter; under a rolling
// shutter one per row, at the row's time, each row's position cam0_pose0's moved by the body's
// motion since the frame's time (state_groundtruth_estimate0 at the IMU's rate, the camera's
// offset T_BS turned with the body), its rotation the slerp between the neighbouring frames'
// cam0_pose0 rotations.
#pragma once

#include <cstddef>

#include "datasets/dataset.hpp"
#include "geometry/frame_poses.hpp"

namespace wingman::datasets {

// Seconds after the frame's time stamp at which row `row` of the camera was exposed: 0 under a
// global shutter, (row - (h - 1) / 2) * line_delay_s under a rolling one (reversed bottom to top).
double row_time(const CameraInfo& camera, double row);

// The true poses of frame `frame` of a UAV (one with a camera). Throws DatasetError for a frame
// index the agent lacks.
geometry::FramePoses frame_poses(const AgentData& agent, std::size_t frame);

}  // namespace wingman::datasets
