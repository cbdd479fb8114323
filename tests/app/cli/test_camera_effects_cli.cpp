// A camera with every shutter and sensor effect through `wingman render` and `wingman run`: the
// dataset records the shutter, each row's time and every frame's exposure and gain; auto-exposure
// moves the exposure over a flight; a bad shutter or sensor key exits 2 naming file, line and key,
// with nothing written; the team's bodies appear in each other's frames.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "app/app_test_support.hpp"
#include "geometry/camera.hpp"
#include "geometry/rotation.hpp"

namespace wingman::app::test {
namespace {

std::string scenario(const std::string& camera_extra) {
  std::string cam = "camera: {fx: 40.02, fy: 40.02, cx: 99.5, cy: 99.5, width: 200, height: 200";
  cam += camera_extra;
  cam += "}";
  std::string s = "name: effects\nrate: 10\nduration: 0.5\nmeasurements: rendered\nuavs:\n";
  s += "  - {name: uav1, initial_position: [-1.5, 0, 15], sees_lead: true, altimeter: true, range: true,\n     ";
  s += cam;
  s += "}\n  - {name: uav2, initial_position: [1.5, 0, 17], range: false, ";
  s += cam;
  s += "}\n";
  return s;
}

const std::string kEffects =
    ",\n     shutter: {type: rolling, line_delay: 3.0e-5, exposure: 0.004, subframes: 3, rows_per_band: 8},"
    "\n     sensor: {model: physical, vignetting: 0.5, auto_exposure: {enabled: true, target: 0.6}}";

TEST(CameraEffectsCli, RenderRecordsTheShutterAndEveryFramesExposure) {
  TempDir tmp;
  write_file(tmp / "fx.yaml", scenario(kEffects));
  const fs::path ds = tmp / "ds";
  const auto r = run_wingman({"render", (tmp / "fx.yaml").string(), "--out", ds.string(), "--gl", "osmesa", "-q"},
                             tmp.path());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::string yaml = read_file(ds / "uav1" / "mav0" / "cam0" / "sensor.yaml");
  EXPECT_THAT(yaml, ::testing::HasSubstr("type: rolling"));
  EXPECT_THAT(yaml, ::testing::HasSubstr("line_delay_s: 3e-05"));
  EXPECT_THAT(yaml, ::testing::HasSubstr("exposure_per_frame: exposure.csv"));
  EXPECT_THAT(yaml, ::testing::HasSubstr("full_well_e: 10000"));
  std::istringstream csv(read_file(ds / "uav1" / "mav0" / "cam0" / "exposure.csv"));
  std::string line;
  std::getline(csv, line);
  EXPECT_EQ(line, "#timestamp [ns],exposure [s],gain");
  std::vector<double> exposure;
  while (std::getline(csv, line)) exposure.push_back(std::stod(line.substr(line.find(',') + 1)));
  ASSERT_EQ(exposure.size(), 6u);
  EXPECT_DOUBLE_EQ(exposure[0], 0.004);
  EXPECT_NE(exposure[5], exposure[0]);  // auto-exposure moved it

  // The SLAM loop runs on such frames too.
  const auto run = run_wingman({"run", (tmp / "fx.yaml").string(), "--gl", "osmesa",
                                "--no-plots", "-q", "--out", (tmp / "run").string()},
                               tmp.path());
  EXPECT_EQ(run.exit_code, 0) << run.output;
}

TEST(CameraEffectsCli, AnImpossibleShutterOrSensorExitsTwoNamingFileLineAndKey) {
  TempDir tmp;
  const struct {
    std::string extra, message;
  } cases[] = {
      {", shutter: {exposure: 0.2}",
       "fx.yaml:7:102: uavs[0].camera.shutter.exposure: exposure and readout take 0.2 s, longer than the frame "
       "interval 0.1 s"},
      {", shutter: {type: rolling, line_delay: -1e-5}", "uavs[0].camera.shutter.line_delay: must be in [0, 0.001]"},
      {", shutter: {type: rolling}", "uavs[0].camera.shutter.line_delay: must be above 0 for a rolling shutter"},
      {", shutter: {exposure: 0.01, subframes: 4}", "uavs[0].camera.shutter.subframes: must be odd"},
      {", sensor: {model: physical, read_noise: -3}", "uavs[0].camera.sensor.read_noise: must be in [0, 1000]"},
      {", sensor: {model: physical}", "uavs[0].camera.sensor: a physical sensor needs shutter.exposure above 0"},
  };
  for (const auto& c : cases) {
    write_file(tmp / "fx.yaml", scenario(c.extra));
    const auto r = run_wingman({"render", (tmp / "fx.yaml").string(), "--out", (tmp / "ds").string(), "-q"},
                               tmp.path());
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_THAT(r.output, ::testing::HasSubstr(c.message)) << c.extra;
    EXPECT_FALSE(fs::exists(tmp / "ds"));
  }
}

// world.uav_bodies: uav2's camera, 2 m above uav1 and 3 m east of it, sees uav1's body where its
// true pose projects (the only pixels that differ from the frame without bodies), while uav1's own
// body, above its camera, never enters its own frame; a missing body model exits 2 naming the key.
TEST(CameraEffectsCli, TheTeamsBodiesAreSeenWhereTheyAre) {
  TempDir tmp;
  const std::string flight = scenario("");
  write_file(tmp / "plain.yaml", flight);
  write_file(tmp / "bodies.yaml", flight + "world: {uav_bodies: {enabled: true}}\n");
  for (const char* name : {"plain", "bodies"}) {
    const auto r = run_wingman({"render", (tmp / (std::string(name) + ".yaml")).string(), "--frames", "1", "--out",
                                (tmp / name).string(), "--gl", "osmesa", "-q"},
                               tmp.path());
    ASSERT_EQ(r.exit_code, 0) << r.output;
  }
  auto frame = [&](const char* run, const char* uav) {
    return cv::imread((tmp / run / uav / "mav0" / "cam0" / "data" / "0.png").string(), cv::IMREAD_GRAYSCALE);
  };
  EXPECT_EQ(cv::countNonZero(frame("plain", "uav1") != frame("bodies", "uav1")), 0);
  const cv::Mat differ = frame("plain", "uav2") != frame("bodies", "uav2");
  ASSERT_GT(cv::countNonZero(differ), 30);
  // uav1's body, 0.05 to 0.33 m above its camera, seen from uav2's nadir camera (f = 40 px): the
  // pixels that change lie between where its top and its bottom centres project.
  const geometry::PinholeCamera cam(40.02, 40.02, 99.5, 99.5, 200, 200);
  const Eigen::Vector3d camera(1.5, 0, 17);
  const auto top = cam.project(geometry::nadir_R_CW() * (Eigen::Vector3d(-1.5, 0, 15.33) - camera));
  const auto bottom = cam.project(geometry::nadir_R_CW() * (Eigen::Vector3d(-1.5, 0, 15.05) - camera));
  ASSERT_TRUE(top && bottom);
  const cv::Moments m = cv::moments(differ, true);
  EXPECT_GT(m.m10 / m.m00, std::min(top->x(), bottom->x()) - 1);
  EXPECT_LT(m.m10 / m.m00, std::max(top->x(), bottom->x()) + 1);
  EXPECT_NEAR(m.m01 / m.m00, top->y(), 2);

  write_file(tmp / "nomodel.yaml", flight + "world: {uav_bodies: {enabled: true, model: nowhere.obj}}\n");
  const auto r = run_wingman({"render", (tmp / "nomodel.yaml").string(), "--out", (tmp / "ds").string(), "-q"},
                             tmp.path());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_THAT(r.output, ::testing::HasSubstr("nowhere.obj"));
  EXPECT_FALSE(fs::exists(tmp / "ds"));
}

}  // namespace
}  // namespace wingman::app::test
