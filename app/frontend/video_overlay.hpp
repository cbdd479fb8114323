// --video: every camera side by side (half size) per step, with the frontend's work drawn on it:
// tracked landmarks (red, green once the filter accepted them), new landmarks' pixels (yellow)
// and the lead detection (magenta); each tile labelled with its UAV, the time and the phase, and a
// legend of the marks under the tiles. MJPG in AVI.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/videoio.hpp>

#include "app/frontend/vision_frontend.hpp"
#include "geometry/camera.hpp"
#include "render/renderer.hpp"

namespace wingman::app {

class VideoOverlay {
 public:
  // Throws std::invalid_argument naming the file if it cannot be opened.
  VideoOverlay(const std::string& path, std::vector<geometry::PinholeCamera> models,
               std::vector<std::string> names, double rate);
  struct Tile {
    const render::Frame* frame = nullptr;
    const VisionFrontend::Marks* marks = nullptr;
    std::optional<Eigen::Vector2d> lead;
  };
  // `phase`: the scenario's phase at t ("" outside every phase).
  void write(const std::vector<Tile>& tiles, double t, const std::string& phase);
  // The composed image of one step (what write() adds to the video).
  cv::Mat compose(const std::vector<Tile>& tiles, double t, const std::string& phase) const;
  cv::Size size() const { return size_; }

 private:
  std::vector<geometry::PinholeCamera> models_;
  std::vector<std::string> names_;
  std::unique_ptr<cv::VideoWriter> video_;
  cv::Mat legend_;  // the strip under the tiles, drawn once
  cv::Size size_;
};

// A tile's label: "<uav>  t = <s> s  <phase>".
std::string overlay_label(const std::string& name, double t, const std::string& phase);
// Height of the legend strip under the tiles, in pixels.
inline constexpr int kLegendHeight = 26;

}  // namespace wingman::app
