#include "app/frontend/video_overlay.hpp"

#include <cstdio>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace wingman::app {

namespace {

// The legend strip: each mark as drawn on the tiles, with what it means.
cv::Mat draw_legend(int width) {
  cv::Mat strip(kLegendHeight, width, CV_8UC3, cv::Scalar(32, 32, 32));
  const int y = kLegendHeight / 2;
  int x = 12;
  // Short words, so that one half-size camera (500 px for the paper's) holds the whole legend.
  auto text = [&](const std::string& s) {
    cv::putText(strip, s, {x + 10, y + 5}, cv::FONT_HERSHEY_SIMPLEX, 0.4, {255, 255, 255}, 1, cv::LINE_AA);
    int base = 0;
    x += 10 + cv::getTextSize(s, cv::FONT_HERSHEY_SIMPLEX, 0.4, 1, &base).width + 22;
  };
  cv::circle(strip, {x, y}, 4, {0, 0, 255}, 1, cv::LINE_AA);
  text("rejected");  // tracked, not accepted by the filter
  cv::circle(strip, {x, y}, 4, {0, 200, 0}, 2, cv::LINE_AA);
  text("accepted");
  cv::drawMarker(strip, {x, y}, {0, 230, 255}, cv::MARKER_CROSS, 9, 2);
  text("new landmark");
  cv::circle(strip, {x, y}, 8, {255, 0, 255}, 2, cv::LINE_AA);
  text("lead");
  return strip;
}

}  // namespace

std::string overlay_label(const std::string& name, double t, const std::string& phase) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%s  t = %.1f s", name.c_str(), t);
  return phase.empty() ? std::string(buf) : std::string(buf) + "  " + phase;
}

VideoOverlay::VideoOverlay(const std::string& path, std::vector<geometry::PinholeCamera> models,
                           std::vector<std::string> names, double rate)
    : models_(std::move(models)), names_(std::move(names)) {
  int w = 0, h = 0;
  for (const auto& m : models_) {
    w += m.width() / 2;
    h = std::max(h, m.height() / 2);
  }
  legend_ = draw_legend(w);
  size_ = cv::Size(w, h + kLegendHeight);
  video_ = std::make_unique<cv::VideoWriter>(path, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), rate, size_);
  if (!video_->isOpened()) throw std::invalid_argument(path + ": cannot write a video there (MJPG in AVI)");
}

cv::Mat VideoOverlay::compose(const std::vector<Tile>& tiles, double t, const std::string& phase) const {
  std::vector<cv::Mat> out_tiles;
  const int h = size_.height - kLegendHeight;
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
    cv::putText(bgr, overlay_label(names_[j], t, phase), {8, 22}, cv::FONT_HERSHEY_SIMPLEX, 0.6, {255, 255, 255}, 2,
                cv::LINE_AA);
    if (bgr.rows < h) cv::copyMakeBorder(bgr, bgr, 0, h - bgr.rows, 0, 0, cv::BORDER_CONSTANT);
    out_tiles.push_back(bgr);
  }
  cv::Mat row, out;
  cv::hconcat(out_tiles, row);
  cv::vconcat(row, legend_, out);
  return out;
}

void VideoOverlay::write(const std::vector<Tile>& tiles, double t, const std::string& phase) {
  video_->write(compose(tiles, t, phase));
}

}  // namespace wingman::app
