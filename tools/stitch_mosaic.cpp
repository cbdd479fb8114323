// Joins overlapping nadir drone photos into one ground mosaic (the ground images of assets/aerial/):
// OpenCV's Stitcher in SCANS mode (an affine model: nadir photos of flat ground from one height)
// registering them, composing them at the mosaic's ground sampling distance and blending the seams
// with multi-band blending, and the largest rectangle the photos cover fully cut out, so
// the mosaic has no empty corner.
//   stitch_mosaic [--crop X,Y,W,H] OUT.(jpg|png) GSD_IN M_PER_PX PHOTO [PHOTO ...]
// GSD_IN: metres per pixel of the photos; M_PER_PX: of the mosaic. --crop keeps that rectangle
// (mosaic pixels, from the covered rectangle's top-left) of the result, to leave out a part the
// registration smeared. Prints the mosaic's size in pixels and metres. Exit 2 on bad arguments or
// an unreadable photo, 1 when the photos do not join.
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/stitching.hpp>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

namespace {

// The largest axis-aligned rectangle of non-zero mask pixels (the histogram method, O(w h)).
cv::Rect largest_filled_rect(const cv::Mat& mask) {
  std::vector<int> height(static_cast<std::size_t>(mask.cols), 0);
  cv::Rect best;
  for (int r = 0; r < mask.rows; ++r) {
    for (int c = 0; c < mask.cols; ++c) height[c] = mask.at<std::uint8_t>(r, c) ? height[c] + 1 : 0;
    std::vector<int> stack;
    for (int c = 0; c <= mask.cols; ++c) {
      const int h = c < mask.cols ? height[c] : 0;
      while (!stack.empty() && height[stack.back()] >= h) {
        const int top = height[stack.back()];
        stack.pop_back();
        const int left = stack.empty() ? 0 : stack.back() + 1;
        if (top * (c - left) > best.area()) best = cv::Rect(left, r - top + 1, c - left, top);
      }
      stack.push_back(c);
    }
  }
  return best;
}

}  // namespace

int main(int argc, char** argv) {
  cv::Rect crop;
  if (argc > 2 && std::string(argv[1]) == "--crop") {
    if (std::sscanf(argv[2], "%d,%d,%d,%d", &crop.x, &crop.y, &crop.width, &crop.height) != 4 || crop.x < 0 ||
        crop.y < 0 || crop.width <= 0 || crop.height <= 0) {
      std::fprintf(stderr, "stitch_mosaic: --crop %s: want X,Y,W,H in pixels, W and H above 0\n", argv[2]);
      return 2;
    }
    argv += 2;
    argc -= 2;
  }
  if (argc < 5) {
    std::fprintf(stderr, "usage: stitch_mosaic [--crop X,Y,W,H] OUT.(jpg|png) GSD_IN M_PER_PX PHOTO [PHOTO ...]\n");
    return 2;
  }
  const double gsd = std::atof(argv[2]), out_gsd = std::atof(argv[3]);
  if (!(gsd > 0) || !(out_gsd >= gsd)) {
    std::fprintf(stderr, "stitch_mosaic: GSD_IN (%s) must be above 0 and M_PER_PX (%s) at least GSD_IN\n", argv[2],
                 argv[3]);
    return 2;
  }
  std::vector<cv::Mat> photos;
  for (int i = 4; i < argc; ++i) {
    const cv::Mat img = cv::imread(argv[i], cv::IMREAD_COLOR);
    if (img.empty()) {
      std::fprintf(stderr, "stitch_mosaic: %s: cannot read\n", argv[i]);
      return 2;
    }
    photos.push_back(img);
  }
  cv::Ptr<cv::Stitcher> stitcher = cv::Stitcher::create(cv::Stitcher::SCANS);
  // Registered at 1 Mpx a photo (coarser loses the joins between flight lines), composed at the
  // mosaic's ground sampling distance.
  const double scale = gsd / out_gsd;
  stitcher->setRegistrationResol(1.0);
  stitcher->setCompositingResol(photos.front().total() * scale * scale / 1e6);
  stitcher->setPanoConfidenceThresh(0.5);
  cv::Mat pano;
  const cv::Stitcher::Status status = stitcher->stitch(photos, pano);
  if (status != cv::Stitcher::OK) {
    std::fprintf(stderr, "stitch_mosaic: the photos do not join (cv::Stitcher status %d)\n", static_cast<int>(status));
    return 1;
  }
  if (stitcher->component().size() != photos.size()) {
    std::fprintf(stderr, "stitch_mosaic: %zu of %zu photos joined; left out (too little overlap):",
                 stitcher->component().size(), photos.size());
    const std::vector<int>& joined = stitcher->component();
    for (int i = 0; i < static_cast<int>(photos.size()); ++i)
      if (std::find(joined.begin(), joined.end(), i) == joined.end()) std::fprintf(stderr, " %s", argv[4 + i]);
    std::fprintf(stderr, "\n");
  }
  cv::Mat grey, mask;
  cv::cvtColor(pano, grey, cv::COLOR_BGR2GRAY);
  cv::threshold(grey, mask, 0, 255, cv::THRESH_BINARY);
  cv::erode(mask, mask, cv::Mat(), cv::Point(-1, -1), 2);  // off the blended border
  cv::Rect keep = largest_filled_rect(mask);
  if (crop.area() > 0) {
    if ((crop & cv::Rect(0, 0, keep.width, keep.height)) != crop) {
      std::fprintf(stderr, "stitch_mosaic: --crop %d,%d,%d,%d lies outside the %d x %d px mosaic\n", crop.x, crop.y,
                   crop.width, crop.height, keep.width, keep.height);
      return 2;
    }
    keep = cv::Rect(keep.x + crop.x, keep.y + crop.y, crop.width, crop.height);
  }
  if (keep.area() == 0) {
    std::fprintf(stderr, "stitch_mosaic: the mosaic covers no rectangle\n");
    return 1;
  }
  const std::vector<int> params = {cv::IMWRITE_JPEG_QUALITY, 92};
  if (!cv::imwrite(argv[1], pano(keep), params)) {
    std::fprintf(stderr, "stitch_mosaic: %s: cannot write\n", argv[1]);
    return 2;
  }
  std::printf("%s: %d x %d px, %.1f x %.1f m at %.3f m/px, from %zu photos\n", argv[1], keep.width, keep.height,
              keep.width * out_gsd, keep.height * out_gsd, out_gsd, stitcher->component().size());
  return 0;
}
