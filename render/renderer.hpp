// The off-screen renderer: draws a Scene from any number of pinhole cameras and reads back
// colour (RGB8) and metric depth (float metres along the optical axis, 0 where nothing was hit,
// converted from the hardware depth buffer).
// Pixels obey docs/design.md, frames and conventions exactly: the projection puts u = fx x/z + cx at the centre of pixel
// column u (OpenCV's convention), and GL's bottom row is rendered as image row 0, so readback
// needs no flip. Radial-tangential distortion, when the camera has it, is applied by cv::remap
// from a wider pinhole render with maps computed once per camera. Every GL object (buffers,
// textures, framebuffers per image size) is made once; a frame creates none.
#pragma once

#include <Eigen/Core>
#include <map>
#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include "geometry/camera.hpp"
#include "geometry/pose.hpp"
#include "render/gl_context.hpp"
#include "render/scene.hpp"

namespace wingman::render {

// One instant of a rolling shutter's readout (CameraView::rows): the camera, the lead and the
// team's bodies where they are then.
struct RowKnot {
  geometry::CameraPose pose;
  std::optional<LeadPose> lead{};  // nothing: the lead render() is given
  std::vector<LeadPose> bodies{};  // as CameraView::bodies, in the same order
};

struct CameraView {
  geometry::PinholeCamera camera;
  geometry::CameraPose pose;
  double time = 0;  // s: what moves with time but is no pose (the clouds' shadows)
  // Where the team's UAV bodies are (Scene::body_meshes; sim::uav_body_poses): drawn, and casting
  // shadows, at these poses. Empty when the scene has no bodies.
  std::vector<LeadPose> bodies{};
  // A rolling shutter in one draw: knots spread evenly over the image's rows (the first at row 0,
  // the last at the bottom row), a row between two knots at the pose interpolated linearly
  // between theirs; every vertex is drawn from the pose of the image row it lands on, found in the
  // vertex shader by a few fixed-point steps. `pose`, the lead and `bodies` stay the frame's
  // instant (shading, the sun's shadow map). Empty: every row at `pose`.
  std::vector<RowKnot> rows{};
  // With the sun's shadows: the views whose receivers bound the shadow map (the team's cameras at
  // this instant). Views that share them, the lead and the bodies find the same map, which the
  // renderer keeps and draws again only when its bounds or a caster's pose change
  // (Renderer::shadow_maps_drawn). Empty: this view's receivers alone.
  std::vector<std::pair<geometry::PinholeCamera, geometry::CameraPose>> shadow_views{};
};

// The lead drawn alone, depth only, over the window of the image plane its model's box projects
// to: what it would cover with nothing in front of it and no image border (ground truth of how much
// of it a frame shows). Pixels are the undistorted (pinhole) image's; the window may reach past the
// image's edges.
struct LeadSilhouette {
  cv::Rect window;  // pinhole pixels; depth's (0, 0) is pixel (window.x, window.y)
  cv::Mat depth;    // CV_32FC1, metres along the optical axis; 0 off the lead
};

struct Frame {
  cv::Mat rgb;    // CV_8UC3, RGB order
  cv::Mat depth;  // CV_32FC1, metres along the optical axis; 0: no surface
  cv::Mat gray() const;  // CV_8UC1
};

class Renderer {
 public:
  // Uploads the scene into the context (which must outlive the renderer).
  Renderer(GlContext& ctx, const Scene& scene);
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  Frame render(const CameraView& view, const std::optional<LeadPose>& lead = std::nullopt);
  // Rows [row0, row0 + rows) of that image, and only they are drawn (a rolling shutter's band):
  // the same pixels as render()'s rows; all of them is render() itself.
  Frame render_rows(const CameraView& view, const std::optional<LeadPose>& lead, int row0, int rows);
  // Only the pixels inside `regions` (clipped to the image) are read back, drawn with the whole
  // frame's viewport and projection under scissor rectangles that cover them (nearby regions
  // share one draw where that is cheaper), so that they equal render()'s pixels there; elsewhere
  // the frame is 0 (black, and depth 0: no surface). The frame has the image's size. A camera
  // with lens distortion gets render()'s whole frame.
  Frame render_regions(const CameraView& view, const std::optional<LeadPose>& lead,
                       const std::vector<cv::Rect>& regions);
  // Nothing when the scene has no lead model or the lead is wholly behind the camera. A window
  // wider or taller than max_side px is cut to the image and a margin of max_side / 4 around it.
  std::optional<LeadSilhouette> lead_silhouette(const CameraView& view, const LeadPose& lead,
                                                int max_side = 2048);
  const GlContext& context() const { return ctx_; }
  // Shadow maps drawn so far (a frame that found its map kept draws none).
  int shadow_maps_drawn() const;

  // The OpenGL projection matrix for an undistorted w x h image with these intrinsics
  // (camera frame: OpenCV's; exposed for tests). reversed_z: near maps to NDC z 1 and far to 0,
  // for glClipControl's [0, 1] depth range; otherwise GL's classic -1 to 1.
  static Eigen::Matrix4d projection(double fx, double fy, double cx, double cy, int w, int h,
                                    double near, double far, bool reversed_z = false);

 private:
  struct Impl;
  struct Undistort;
  const Undistort& undistort(const geometry::PinholeCamera& cam);
  // The clip spaces of the views a shadow map covers (CameraView::shadow_views).
  std::vector<Eigen::Matrix4f> shadow_clips(
      const std::vector<std::pair<geometry::PinholeCamera, geometry::CameraPose>>& views);
  // Part of a frame: the scissor rectangles drawn, and the rectangles read back (inside them).
  struct Regions {
    std::vector<cv::Rect> draw, read;
  };
  // regions: null for the whole image.
  Frame render_pinhole(double fx, double fy, double cx, double cy, int w, int h,
                       const CameraView& view, const std::optional<LeadPose>& lead,
                       const Regions* regions = nullptr);
  GlContext& ctx_;
  std::unique_ptr<Impl> impl_;
  std::map<std::tuple<double, double, double, double, int, int, double, double, double, double,
                      double>,
           std::shared_ptr<Undistort>>
      undistort_;
};

}  // namespace wingman::render
