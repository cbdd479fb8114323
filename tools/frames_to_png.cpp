// Puts dataset frames side by side, downsized, into one PNG (the pictures in docs/img/):
//   g++ -O2 -std=c++17 tools/frames_to_png.cpp -o build/frames_to_png \
//       $(pkg-config --cflags --libs opencv4)
//   build/frames_to_png OUT.png WIDTH_PER_FRAME FRAME.png[@x,y,side] [FRAME.png ...]
// where @x,y,side takes a square crop (top-left x, y) before resizing (a close-up).
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

int main(int argc, char** argv) {
  if (argc < 4) {
    std::fprintf(stderr, "usage: %s OUT.png WIDTH FRAME.png [FRAME.png ...]\n", argv[0]);
    return 2;
  }
  const int width = std::atoi(argv[2]);
  std::vector<cv::Mat> tiles;
  for (int i = 3; i < argc; ++i) {
    std::string arg = argv[i];
    int x = 0, y = 0, side = 0;
    if (const auto at = arg.find('@'); at != std::string::npos) {
      std::sscanf(arg.c_str() + at + 1, "%d,%d,%d", &x, &y, &side);
      arg.resize(at);
    }
    cv::Mat img = cv::imread(arg, cv::IMREAD_COLOR);
    if (!img.empty() && side > 0) img = img(cv::Rect(x, y, side, side) & cv::Rect(0, 0, img.cols, img.rows)).clone();
    if (img.empty()) {
      std::fprintf(stderr, "%s: cannot read\n", argv[i]);
      return 1;
    }
    cv::Mat small;
    cv::resize(img, small, cv::Size(width, img.rows * width / img.cols), 0, 0,
               img.cols > width ? cv::INTER_AREA : cv::INTER_NEAREST);
    tiles.push_back(small);
    if (i + 1 < argc) tiles.push_back(cv::Mat(small.rows, 4, CV_8UC3, cv::Scalar(255, 255, 255)));
  }
  cv::Mat out;
  cv::hconcat(tiles, out);
  return cv::imwrite(argv[1], out) ? 0 : 1;
}
