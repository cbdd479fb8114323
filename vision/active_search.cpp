// Planning the regions of active search (see active_search.hpp).
#include "vision/active_search.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "geometry/bounds_check.hpp"

namespace wingman::vision {

void ActiveSearchSettings::validate() const { geometry::check_bounds(*this, "active search settings"); }

namespace {

cv::Rect grow(const cv::Rect& r, int m) { return {r.x - m, r.y - m, r.width + 2 * m, r.height + 2 * m}; }

}  // namespace

std::vector<cv::Rect> new_landmark_blocks(cv::Size image, const std::vector<LandmarkPrediction>& preds, int needed,
                                          const ActiveSearchSettings& settings) {
  settings.validate();
  if (needed <= 0) return {};
  const int block_px = settings.block_px;
  const int count = static_cast<int>(std::ceil(needed / settings.landmarks_per_block));
  const int cols = std::max(1, static_cast<int>(std::lround(static_cast<double>(image.width) / block_px)));
  const int rows = std::max(1, static_cast<int>(std::lround(static_cast<double>(image.height) / block_px)));
  struct Block {
    cv::Rect r;
    int inside = 0;
    double centre2 = 0;  // squared distance of its centre from the image's
  };
  std::vector<Block> blocks;
  for (int y = 0; y < rows; ++y)
    for (int x = 0; x < cols; ++x) {
      Block b;
      b.r = cv::Rect(x * image.width / cols, y * image.height / rows, (x + 1) * image.width / cols - x * image.width / cols,
                     (y + 1) * image.height / rows - y * image.height / rows);
      b.centre2 = Eigen::Vector2d(b.r.x + 0.5 * b.r.width - 0.5 * image.width,
                                  b.r.y + 0.5 * b.r.height - 0.5 * image.height).squaredNorm();
      for (const auto& p : preds)
        if (b.r.contains(cv::Point(static_cast<int>(std::floor(p.uv.x() + 0.5)), static_cast<int>(std::floor(p.uv.y() + 0.5)))))
          ++b.inside;
      blocks.push_back(b);
    }
  std::stable_sort(blocks.begin(), blocks.end(), [](const Block& a, const Block& b) {
    return a.inside != b.inside ? a.inside < b.inside : a.centre2 < b.centre2;
  });
  std::vector<cv::Rect> out;
  for (int i = 0; i < std::min(count, static_cast<int>(blocks.size())); ++i) out.push_back(blocks[i].r);
  return out;
}

namespace {

// A crop's fixed cost in pixels: ORB's pyramid set-up for each crop (bench_frontend's
// BM_DetectDescribeActive: 16 crops took 12.0 ms, merged into 12 with this 10.5 ms).
constexpr int kCropOverheadPx = 2000;

// Merges boxes that overlap (a keypoint must belong to one region) and boxes whose merged crop
// costs no more than the two crops apart.
void merge_boxes(std::vector<cv::Rect>& boxes, int margin, const cv::Rect& frame) {
  auto cost = [&](const cv::Rect& r) { return (grow(r, margin) & frame).area(); };
  for (bool merged = true; merged;) {
    merged = false;
    for (std::size_t i = 0; i < boxes.size() && !merged; ++i)
      for (std::size_t j = i + 1; j < boxes.size() && !merged; ++j) {
        const cv::Rect u = boxes[i] | boxes[j];
        if ((boxes[i] & boxes[j]).area() > 0 || cost(u) <= cost(boxes[i]) + cost(boxes[j]) + kCropOverheadPx) {
          boxes[i] = u;
          boxes.erase(boxes.begin() + static_cast<std::ptrdiff_t>(j));
          merged = true;
        }
      }
  }
}

}  // namespace

SearchPlan plan_search(cv::Size image, const std::vector<LandmarkPrediction>& predictions,
                       const std::vector<cv::Rect>& blocks, int margin, const TrackingSettings& tracking,
                       const ActiveSearchSettings& settings) {
  settings.validate();
  SearchPlan plan;
  if (!settings.enabled) return plan;
  const cv::Rect frame(0, 0, image.width, image.height);
  std::vector<cv::Rect> boxes;
  for (const auto& p : predictions) {
    if (!p.uv.allFinite() || !p.S.allFinite()) continue;
    // One pixel beyond the gate: a keypoint on its edge is still inside the region.
    const Eigen::Vector2d half = gate_half_extent(p.S, tracking).array() + 1.0;
    const int x0 = static_cast<int>(std::floor(p.uv.x() - half.x())), y0 = static_cast<int>(std::floor(p.uv.y() - half.y()));
    const int x1 = static_cast<int>(std::ceil(p.uv.x() + half.x())) + 1, y1 = static_cast<int>(std::ceil(p.uv.y() + half.y())) + 1;
    const cv::Rect r = cv::Rect(x0, y0, x1 - x0, y1 - y0) & frame;
    if (r.empty()) continue;
    boxes.push_back(r);
    ++plan.gates;
  }
  for (const auto& b : blocks) {
    const cv::Rect r = b & frame;
    if (r.empty()) continue;
    boxes.push_back(r);
    ++plan.blocks;
  }
  merge_boxes(boxes, margin, frame);
  double area = 0;
  for (const auto& b : boxes) area += (grow(b, margin) & frame).area();
  const double fraction = area / std::max(1, frame.area());
  if (fraction > settings.max_fraction) return plan;  // the whole frame is cheaper
  plan.whole_frame = false;
  plan.regions = std::move(boxes);
  plan.fraction = fraction;
  return plan;
}

}  // namespace wingman::vision
