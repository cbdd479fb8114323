// Where the lead is in one camera's frame and how much of it the frame shows: the ground truth a
// lead detector is scored against (datasets' cam0_lead0, a run's lead.csv).
#pragma once

#include <Eigen/Core>
#include <limits>

namespace wingman::geometry {

struct LeadImage {
  // x_h's projection through the pose of the row it falls on; NaN when x_h is behind the camera.
  // It may lie outside the image.
  Eigen::Vector2d uv = Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN());
  double distance = 0;  // m, from the camera's centre to x_h
  // The share of the lead's silhouette (the lead drawn alone, as if nothing hid it and the image
  // had no border) that the frame shows: inside the image and not behind another surface.
  double visible = 0;
  // The visible pixels' bounds: columns [u0, u1), rows [v0, v1); all 0 when none is visible.
  int box_u0 = 0, box_v0 = 0, box_u1 = 0, box_v1 = 0;
};

}  // namespace wingman::geometry
