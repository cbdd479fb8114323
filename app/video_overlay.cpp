#include "app/video_overlay.hpp"

#include <cstdio>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace wingman::app {

namespace {

std::string fmt_label(const std::string& name, double t) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%s  t = %.1f s", name.c_str(), t);
  return buf;
}

}  // namespace

VideoOverlay::VideoOverlay(const std::string& path, std::vector<geometry::PinholeCamera> models,
                           std::vector<std::string> names, double rate)
    : models_(std::move(models)), names_(std::move(names)) {
  int w = 0, h = 0;
  for (const auto& m : models_) {
    w += m.width() / 2;
    h = std::max(h, m.height() / 2);
  }
  video_ = std::make_unique<cv::VideoWriter>(path, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), rate,
                                             cv::Size(w, h));
  if (!video_->isOpened()) throw std::invalid_argument(path + ": cannot write a video there (MJPG in AVI)");
}

void VideoOverlay::write(const std::vector<Tile>& tiles, double t) {
  std::vector<cv::Mat> out_tiles;
  int h = 0;
  for (const auto& m : models_) h = std::max(h, m.height() / 2);
  for (std::size_t j = 0; j < tiles.size(); ++j) {
    const Tile& tile = tiles[j];
    const auto& model = models_[j];
    cv::Mat bgr;
    cv::cvtColor(tile.frame->rgb, bgr, cv::COLOR_RGB2BGR);
    cv::resize(bgr, bgr, cv::Size(model.width() / 2, model.height() / 2), 0, 0, cv::INTER_AREA);
    auto pt = [](const Eigen::Vector2d& uv) { return cv::Point2d(uv.x() / 2, uv.y() / 2); };
    for (const auto& uv : tile.marks->tracked) cv::circle(bgr, pt(uv), 4, {0, 0, 255}, 1, cv::LINE_AA);
    for (const auto& uv : tile.marks->accepted) cv::circle(bgr, pt(uv), 4, {0, 200, 0}, 2, cv::LINE_AA);
    for (const auto& uv : tile.marks->fresh) cv::drawMarker(bgr, pt(uv), {0, 230, 255}, cv::MARKER_CROSS, 9, 2);
    if (tile.lead) cv::circle(bgr, pt(*tile.lead), 12, {255, 0, 255}, 2, cv::LINE_AA);
    cv::putText(bgr, fmt_label(names_[j], t), {8, 22}, cv::FONT_HERSHEY_SIMPLEX, 0.6, {255, 255, 255}, 2,
                cv::LINE_AA);
    if (bgr.rows < h) cv::copyMakeBorder(bgr, bgr, 0, h - bgr.rows, 0, 0, cv::BORDER_CONSTANT);
    out_tiles.push_back(bgr);
  }
  cv::Mat out;
  cv::hconcat(out_tiles, out);
  video_->write(out);
}

}  // namespace wingman::app
