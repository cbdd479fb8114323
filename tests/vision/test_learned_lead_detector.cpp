// The learned lead detector's weights are checked when loaded: a missing file, a file that is not
// ONNX and a network of the wrong output shape are each refused naming the file; the shipped
// network loads and finds nothing on an empty grey image.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

#include "vision/learned_lead_detector.hpp"

namespace wingman::vision {
namespace {

namespace fs = std::filesystem;
const fs::path kSource = WINGMAN_SOURCE_DIR;

std::string refusal(const std::string& path) {
  try {
    LearnedLeadDetector d(path);
  } catch (const LeadModelError& e) {
    return e.what();
  }
  return "loaded";
}

TEST(LearnedLeadDetector, AMissingWeightsFileIsRefusedNamingIt) {
  const std::string p = (fs::temp_directory_path() / "wingman-no-such-weights.onnx").string();
  EXPECT_EQ(refusal(p), p + ": weights file not found");
}

TEST(LearnedLeadDetector, AFileThatIsNotOnnxIsRefusedNamingIt) {
  const fs::path p = fs::temp_directory_path() / ("wingman-corrupt-" + std::to_string(::getpid()) + ".onnx");
  std::ofstream(p) << "this is not a network\n";
  const std::string why = refusal(p.string());
  fs::remove(p);
  EXPECT_EQ(why.rfind(p.string() + ": not an ONNX network OpenCV can read", 0), 0u) << why;
}

TEST(LearnedLeadDetector, ANetworkWithTheWrongOutputShapeIsRefusedNamingIt) {
  const std::string p = (kSource / "tests" / "data" / "lead_two_maps.onnx").string();
  EXPECT_EQ(refusal(p), p + ": expected an output of 1 x 3 x 16 x 24 for a 64 x 96 image, got 1 x 2 x 16 x 24");
}

TEST(LearnedLeadDetector, TheShippedNetworkLoadsAndFindsNothingOnAFlatImage) {
  LearnedLeadDetector d((kSource / "assets" / "lead" / "lead_detector.onnx").string());
  EXPECT_FALSE(d.detect(cv::Mat(480, 640, CV_8UC1, cv::Scalar(90))).has_value());
  EXPECT_FALSE(d.detect(cv::Mat(480, 640, CV_8UC1, cv::Scalar(90)), Eigen::Vector2d(300, 200)).has_value());
}

TEST(LearnedLeadDetector, SettingsOutOfRangeAreRefused) {
  LearnedLeadSettings s;
  s.threshold = 1.0;
  EXPECT_THROW(s.validate(), std::invalid_argument);
  s = {};
  s.window_half_px = 8;
  EXPECT_THROW(s.validate(), std::invalid_argument);
}

}  // namespace
}  // namespace wingman::vision
