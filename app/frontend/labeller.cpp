#include "app/frontend/labeller.hpp"

#include <cmath>

#include "vision/labelling.hpp"

namespace wingman::app {

GroundTruthLabeller::Label GroundTruthLabeller::observation(geometry::LandmarkId id, const Eigen::Vector2d& uv,
                                                            const geometry::PinholeCamera& model,
                                                            const CameraFrame& f) const {
  Label out;
  const auto it = truth_.find(id);
  if (it == truth_.end() || !it->second) return out;  // no truth: counted as an outlier
  const auto lr = vision::label_landmark_observation(*it->second, uv, model, f.true_pose, f.frame.depth);
  out.outlier = lr.label != vision::Label::Inlier;
  out.error_px = lr.reprojection_px;
  out.true_uv = lr.true_uv;
  return out;
}

GroundTruthLabeller::Label GroundTruthLabeller::pair(const Eigen::Vector2d& uv_a,
                                                     const geometry::PinholeCamera& model_a,
                                                     const CameraFrame& a, const Eigen::Vector2d& uv_b,
                                                     const geometry::PinholeCamera& model_b,
                                                     const CameraFrame& b) const {
  const auto lr = vision::label_pixel_pair(uv_a, model_a, a.true_pose, a.frame.depth, uv_b, model_b,
                                           b.true_pose, b.frame.depth);
  Label out;
  out.outlier = lr.label != vision::Label::Inlier;
  out.error_px = lr.reprojection_px;
  out.true_uv = lr.true_uv;
  return out;
}

std::optional<Eigen::Vector3d> GroundTruthLabeller::landmark(geometry::LandmarkId id, const Eigen::Vector2d& uv,
                                                             const geometry::PinholeCamera& model,
                                                             const CameraFrame& f) {
  auto truth = vision::back_project(uv, model, f.true_pose, f.frame.depth);
  truth_[id] = truth;
  return truth;
}

std::optional<Eigen::Vector2d> GroundTruthLabeller::lead(const std::optional<Eigen::Vector2d>& detected,
                                                         const geometry::PinholeCamera& model,
                                                         const CameraFrame& f, const Eigen::Vector3d& lead_W,
                                                         eval::FrontendRecord& fr) const {
  // In view when the reference point projects inside the image with room for the marker and the
  // rendered depth there is the lead's.
  ++fr.frames;
  const Eigen::Vector3d p_true = f.true_pose.to_camera(model, lead_W);
  const auto uv_true = model.project(p_true);
  bool in_view = false;
  if (uv_true && model.in_image(*uv_true, 15)) {
    const auto d = vision::sample_depth(f.frame.depth, *uv_true);
    in_view = d && std::abs(*d - p_true.z()) < 0.3;
  }
  if (in_view) ++fr.lead_in_view;
  if (!detected) return std::nullopt;
  const double err = in_view ? (*detected - *uv_true).norm() : INFINITY;
  if (err > fr.lead_match_px) {
    ++fr.lead_false;
    return std::nullopt;
  }
  ++fr.lead_detected;
  fr.lead_error_px.push_back(err);
  return uv_true;
}

}  // namespace wingman::app
