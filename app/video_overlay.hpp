// --video: every camera side by side (half size) per step, with the frontend's work drawn on it:
// tracked landmarks (red, green once the filter accepted them), new landmarks' pixels (yellow)
// and the lead detection (magenta). MJPG in AVI.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/videoio.hpp>

#include "app/vision_frontend.hpp"
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
  void write(const std::vector<Tile>& tiles, double t);

 private:
  std::vector<geometry::PinholeCamera> models_;
  std::vector<std::string> names_;
  std::unique_ptr<cv::VideoWriter> video_;
};

}  // namespace wingman::app
