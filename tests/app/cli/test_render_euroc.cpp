// The datasets `wingman render` writes, read by other people's code: a loader written from
// EuRoC's published description (tests/datasets/euroc_loader.py, Debian's python3) reads every
// UAV's mav0/ unchanged and its IMU, integrated over the ground truth's orientation, reaches the
// ground truth's velocity; the frames are 8-bit grey unless asked otherwise; and `wingman slam`
// still reads the former layout (format version 1) with identical results.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "app/app_test_support.hpp"
#include "datasets/dataset.hpp"
#include "gl_required.hpp"

namespace wingman::app::test {
namespace {

const fs::path kPython = "/usr/bin/python3";  // Debian's, with python3-yaml (setup.sh)
const fs::path kLoader = kSourceDir / "tests" / "datasets" / "euroc_loader.py";

std::string small_scenario(double duration) {
  const std::string cam = "camera: {fx: 160, fy: 160, cx: 99.5, cy: 99.5, width: 200, height: 200}";
  std::string s = "name: small\nrate: 10\nduration: ";
  s += std::to_string(duration);
  s += "\nnoise: {motion: {accel_sigma_lead: 0.1, accel_sigma_uav: 0.1}}\nuavs:\n";
  s += "  - {name: uav1, initial_position: [-1.5, 0, 15], " + cam + "}\n";
  s += "  - {name: uav2, initial_position: [1.5, 0, 17], " + cam + "}\n";
  return s;
}

// Renders the small scenario into dir/ds (extra arguments appended).
RunResult render_small(const fs::path& dir, double duration, const std::vector<std::string>& extra = {}) {
  write_file(dir / "small.yaml", small_scenario(duration));
  std::vector<std::string> args = {"render", (dir / "small.yaml").string(), "--out", (dir / "ds").string(), "-q"};
  args.insert(args.end(), extra.begin(), extra.end());
  return run_wingman(args, dir);
}

// One 4 s dataset for the suite (rendering costs most of these tests' time); each test works on
// its own copy.
class RenderEuroc : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    shared_ = new TempDir;
    const auto r = render_small(shared_->path(), 4.0);
    render_output_ = r.output;
    rendered_ = r.exit_code == 0;
  }
  static void TearDownTestSuite() {
    delete shared_;
    shared_ = nullptr;
  }
  void SetUp() override {
    if (!rendered_ && render_output_.find("GL") != std::string::npos) WINGMAN_NO_GL_CONTEXT(render_output_);
    ASSERT_TRUE(rendered_) << render_output_;
    fs::copy(shared_->path() / "ds", tmp_ / "ds", fs::copy_options::recursive);
  }
  static inline TempDir* shared_ = nullptr;
  static inline bool rendered_ = false;
  static inline std::string render_output_;
  TempDir tmp_;
};

RunResult run_script(const std::vector<std::string>& args, const fs::path& dir) {
  const fs::path log = dir / "script-output.txt";
  std::string cmd;
  for (const auto& a : args) cmd += quote(a) + " ";
  cmd += "> " + quote(log.string()) + " 2>&1";
  const int status = std::system(cmd.c_str());
  RunResult r;
  if (status != -1 && WIFEXITED(status)) r.exit_code = WEXITSTATUS(status);
  r.output = read_file(log);
  return r;
}

TEST_F(RenderEuroc, AnEurocLoaderReadsEveryUavAndItsImuReachesTheGroundTruthVelocity) {
  const TempDir& tmp = tmp_;
  for (const char* uav : {"uav1", "uav2"}) {
    const auto r = run_script({kPython.string(), kLoader.string(), (tmp / "ds" / uav / "mav0").string(),
                               "--integrate", "4"},
                              tmp.path());
    EXPECT_EQ(r.exit_code, 0) << r.output;
    EXPECT_THAT(r.output, ::testing::HasSubstr("cam0: 41 frames 200x200 at 10 Hz"));
    EXPECT_THAT(r.output, ::testing::HasSubstr("imu0: 801 samples at 200 Hz"));
    EXPECT_THAT(r.output, ::testing::HasSubstr("state_groundtruth_estimate0: 801 states"));
    EXPECT_THAT(r.output, ::testing::HasSubstr("velocity after 4.000 s"));
  }
}

// The loader can fail: a ground truth short of EuRoC's 17 columns, and an IMU that disagrees
// with the truth (its accelerometer's x shifted by 0.5 m/s^2), are refused.
TEST_F(RenderEuroc, TheEurocLoaderRefusesAWrongGroundTruthOrImu) {
  const TempDir& tmp = tmp_;
  const fs::path mav0 = tmp / "ds" / "uav1" / "mav0";
  const fs::path imu = mav0 / "imu0" / "data.csv";
  std::string text = read_file(imu), shifted;
  for (const std::string& line : lines_of(text)) {
    if (line.empty() || line[0] == '#') {
      shifted += line + "\n";
      continue;
    }
    std::vector<std::string> f;
    std::stringstream ss(line);
    for (std::string x; std::getline(ss, x, ',');) f.push_back(x);
    f[4] = std::to_string(std::stod(f[4]) + 0.5);
    shifted += f[0] + "," + f[1] + "," + f[2] + "," + f[3] + "," + f[4] + "," + f[5] + "," + f[6] + "\n";
  }
  write_file(imu, shifted);
  auto r = run_script({kPython.string(), kLoader.string(), mav0.string(), "--integrate", "4"}, tmp.path());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_THAT(r.output, ::testing::HasSubstr("leaves the ground-truth velocity"));

  write_file(imu, text);
  const fs::path gt = mav0 / "state_groundtruth_estimate0" / "data.csv";
  std::string g = read_file(gt);
  replace_once(g, ",", ";", g.find('\n') + 1);  // the first state loses a column
  write_file(gt, g);
  r = run_script({kPython.string(), kLoader.string(), mav0.string()}, tmp.path());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_THAT(r.output, ::testing::HasSubstr("16 columns, EuRoC has 17"));
}

TEST_F(RenderEuroc, FramesAreGreyByDefaultAndRgbWhenAsked) {
  const TempDir& tmp = tmp_;
  datasets::Dataset ds = datasets::read_dataset(tmp / "ds");
  EXPECT_EQ(ds.agent("uav1").camera->channels, 1);
  EXPECT_EQ(ds.load_image("uav1", 0).channels(), 1);
  EXPECT_THAT(read_file(tmp / "ds" / "uav1" / "mav0" / "cam0" / "sensor.yaml"), ::testing::HasSubstr("encoding: mono8"));
  fs::remove_all(tmp / "ds");
  const auto rgb = render_small(tmp.path(), 0.2, {"--rgb"});
  ASSERT_EQ(rgb.exit_code, 0) << rgb.output;
  ds = datasets::read_dataset(tmp / "ds");
  EXPECT_EQ(ds.agent("uav1").camera->channels, 3);
  EXPECT_EQ(ds.load_image("uav1", 0).channels(), 3);
  const auto r = run_wingman({"render", (tmp / "small.yaml").string(), "--out", (tmp / "x").string(), "--gray", "--rgb"},
                             tmp.path());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_THAT(r.output, ::testing::HasSubstr("--gray and --rgb exclude each other"));
  EXPECT_FALSE(fs::exists(tmp / "x"));
}

TEST_F(RenderEuroc, SlamReadsTheFormerLayoutWithIdenticalResults) {
  const TempDir& tmp = tmp_;
  fs::copy(tmp / "ds", tmp / "v1", fs::copy_options::recursive);
  const fs::path convert = kSourceDir / "tests" / "datasets" / "to_format_version_1.py";
  auto r = run_script({kPython.string(), convert.string(), (tmp / "v1").string()}, tmp.path());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  ASSERT_TRUE(fs::exists(tmp / "v1" / "uav1" / "groundtruth" / "cam0.csv"));
  EXPECT_EQ(datasets::read_dataset(tmp / "v1").info.format_version, 1);
  for (const char* d : {"ds", "v1"}) {
    r = run_wingman({"slam", (tmp / d).string(), "--out", (tmp / (std::string(d) + "_res")).string(), "--no-plots", "-q"},
                    tmp.path());
    ASSERT_EQ(r.exit_code, 0) << r.output;
  }
  r = run_wingman({"check", (tmp / "v1_res").string(), "--against", (tmp / "ds_res").string()}, tmp.path());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_THAT(r.output, ::testing::HasSubstr("identical"));
}

}  // namespace
}  // namespace wingman::app::test
