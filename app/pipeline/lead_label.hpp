// The lead's ground truth in one camera's frame (geometry::LeadImage: a dataset's cam0_lead0, a run's
// lead.csv): what a lead detector should find there. For evaluation and training only; the frontend never sees it.
#pragma once

#include <Eigen/Core>
#include <optional>

#include "geometry/camera.hpp"
#include "geometry/frame_poses.hpp"
#include "geometry/lead_image.hpp"
#include "render/renderer.hpp"

namespace wingman::app {

// x_h's projection through the pose of the row it falls on, its distance from the camera's centre,
// and the silhouette's pixels the frame shows: inside the image, with the frame's rendered depth
// there not nearer than the lead's own by more than 5 cm + 1 % (the depth buffers' precision, and
// the lead's motion within an exposure or a rolling shutter's readout, which the silhouette drawn at
// the frame's time does not follow). No silhouette (no lead model): nothing visible.
geometry::LeadImage lead_label(const Eigen::Vector3d& x_h_W, const geometry::PinholeCamera& model,
                               const geometry::FramePoses& poses, const cv::Mat& depth,
                               const std::optional<render::LeadSilhouette>& silhouette);

}  // namespace wingman::app
