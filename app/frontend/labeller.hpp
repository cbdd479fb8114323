// Ground-truth labels of what the vision frontend produced, for evaluation only: whether a
// correspondence is within 3 px of the true projection and unoccluded (Table 3), the truth of a
// new landmark (the back-projection of its first pixel through the true pose and rendered depth,
// Table 5), and the lead detector's tallies. The frontend never sees them; the oracle-pixel
// diagnostic (frontend.oracle_pixels) takes their true pixels instead of the measured ones.
#pragma once

#include <Eigen/Core>
#include <limits>
#include <optional>
#include <unordered_map>

#include "eval/metrics/run_record.hpp"
#include "geometry/camera.hpp"
#include "geometry/frame_poses.hpp"
#include "geometry/lead_image.hpp"
#include "geometry/pose.hpp"
#include "render/renderer.hpp"

namespace wingman::app {

// A frame with the true pose it was taken from (one per row under a rolling shutter).
struct CameraFrame {
  render::Frame frame;
  geometry::FramePoses true_pose;
  std::optional<geometry::LeadImage> lead_truth;  // the lead in this frame, when known
};

class GroundTruthLabeller {
 public:
  struct Label {
    bool outlier = true;  // > 3 px from the true projection, occluded, or no truth
    double error_px = std::numeric_limits<double>::quiet_NaN();  // to the true projection
    std::optional<Eigen::Vector2d> true_uv;
  };

  // A tracked pixel of landmark `id`, seen by `model` in frame `f`.
  Label observation(geometry::LandmarkId id, const Eigen::Vector2d& uv, const geometry::PinholeCamera& model,
                    const CameraFrame& f) const;
  // A pixel pair of two cameras meant to be one point; the true pixel is camera b's.
  Label pair(const Eigen::Vector2d& uv_a, const geometry::PinholeCamera& model_a, const CameraFrame& a,
             const Eigen::Vector2d& uv_b, const geometry::PinholeCamera& model_b, const CameraFrame& b) const;
  // A new landmark first seen at uv: its truth (nothing when no surface was rendered there),
  // kept for labelling its later observations.
  std::optional<Eigen::Vector3d> landmark(geometry::LandmarkId id, const Eigen::Vector2d& uv,
                                          const geometry::PinholeCamera& model, const CameraFrame& f);
  void forget(geometry::LandmarkId id) { truth_.erase(id); }

  // Tallies a camera's lead detection against the lead's true position; returns the true pixel
  // when the detection is the lead (within the record's match radius).
  std::optional<Eigen::Vector2d> lead(const std::optional<Eigen::Vector2d>& detected,
                                      const geometry::PinholeCamera& model, const CameraFrame& f,
                                      const Eigen::Vector3d& lead_W, eval::FrontendRecord& fr) const;

 private:
  std::unordered_map<geometry::LandmarkId, std::optional<Eigen::Vector3d>> truth_;
};

}  // namespace wingman::app
