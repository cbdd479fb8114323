// The pose a frame was taken from: one for a global shutter; for a rolling shutter, one per row
// (row r's pose is the camera's when that row was exposed), so ground truth follows the shutter
// exactly: a world point is drawn on the row whose own pose projects it onto that row.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "geometry/camera.hpp"
#include "geometry/pose.hpp"

namespace wingman::geometry {

// Seconds after the frame's time at which (fractional) row `row` of an image `height` rows high
// is exposed by a rolling shutter that reads a row every `line_delay` s, top to bottom or bottom to
// top: the middle row, (height - 1) / 2, is the frame's time.
double rolling_row_time(double row, int height, double line_delay, bool top_to_bottom);

class FramePoses {
 public:
  FramePoses() = default;
  FramePoses(const CameraPose& centre) : centre_(centre) {}  // NOLINT: a global shutter's frame
  // rows[r]: the pose of image row r (rows.size() is the image height); centre: the frame's time.
  FramePoses(const CameraPose& centre, std::vector<CameraPose> rows);

  const CameraPose& centre() const { return centre_; }
  bool rolling() const { return !rows_.empty(); }
  // The pose at (fractional) row v, interpolated between rows and clamped to the image; the
  // centre pose under a global shutter.
  CameraPose at_row(double v) const;
  // p_W in the camera frame of the row it is drawn on (solved by fixed-point iteration: the row
  // moves by the image speed times the line delay, far below a pixel per pixel).
  Eigen::Vector3d to_camera(const PinholeCamera& cam, const Eigen::Vector3d& p_W) const;

 private:
  CameraPose centre_;
  std::vector<CameraPose> rows_;
};

}  // namespace wingman::geometry
