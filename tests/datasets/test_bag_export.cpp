// The ROS 1 bag export (datasets/bag/bag_export.hpp, `wingman export`): a small dataset written
// with DatasetWriter (no GL needed) is exported and read back with Debian's python3-rosbag
// (tests/datasets/read_bag.py), and the bag's topics, stamps and values are checked against what
// was written; the command's refusals exit 2 and leave nothing behind.
#include <gtest/gtest.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include <chrono>
#include <cstdlib>
#include <thread>

#include "app/app_test_support.hpp"
#include "datasets/bag/bag_export.hpp"
#include "datasets/dataset.hpp"

namespace wingman::datasets {
namespace {

using app::test::read_file;
using app::test::run_wingman;
using app::test::TempDir;
using app::test::write_file;
using nlohmann::json;
namespace fs = std::filesystem;

const fs::path kReadBag = app::test::kSourceDir / "tests" / "datasets" / "read_bag.py";
constexpr int kW = 32, kH = 24;
const Eigen::Vector3d kOffset(1.0, 2.0, -0.5);
const double kYaw1 = M_PI / 2;  // uav1's body yaw: its body-frame velocity depends on it

Eigen::Vector4d xyzw(const Eigen::Quaterniond& q) { return {q.x(), q.y(), q.z(), q.w()}; }

// Colour pattern of frame k: R = 5 row, G = 7 col, B = 100 + k.
cv::Mat pattern(int k) {
  cv::Mat img(kH, kW, CV_8UC3);
  for (int r = 0; r < kH; ++r)
    for (int c = 0; c < kW; ++c) img.at<cv::Vec3b>(r, c) = cv::Vec3b(5 * r, 7 * c, 100 + k);
  return img;
}

// A nadir camera turned by 0.3 rad about its axis: R_CW is not symmetric, so R_CW and R_CW^T differ.
Eigen::Matrix3d R_CW() {
  return Eigen::Matrix3d(Eigen::Vector3d(1, -1, -1).asDiagonal()) *
         Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()).toRotationMatrix();
}

CameraInfo camera(int channels) {
  CameraInfo c;
  c.camera = geometry::PinholeCamera(30.5, 31.5, 15.5, 11.5, kW, kH, {0.01, -0.02, 0.001, 0.002, 0.003});
  c.R_CW = R_CW();
  c.offset = kOffset;
  c.channels = channels;
  return c;
}

// lead (no camera, GPS), uav1 (colour, yawed 90°, altimeter, range, AHRS), uav2 (grey); frames at
// 10 Hz, each UAV's IMU at 200 Hz.
void write_small_dataset(const fs::path& dir, int frames = 3) {
  fs::create_directories(dir);
  DatasetInfo info;
  info.scenario = "bagtest";
  info.frames = frames;
  DatasetWriter w(dir, info, 1);
  w.add_agent("lead", std::nullopt);
  w.add_agent("uav1", camera(3));
  w.add_agent("uav2", camera(1));
  for (const char* uav : {"uav1", "uav2"}) {
    w.imu_info(uav, ImuInfo{200, 0.01, 0.001, 0.1, 0.01});
    for (int i = 0; i <= 20 * (frames - 1); ++i) w.imu(uav, {step_ns(i, 200), {0.1, -0.2, 0.3 + i}, {0.5, 0.25, 9.81}});
  }
  const Eigen::Quaterniond yaw1(Eigen::AngleAxisd(kYaw1, Eigen::Vector3d::UnitZ()));
  for (int k = 0; k < frames; ++k) {
    const std::int64_t t = step_ns(k, 10);
    w.ground_truth("lead", {t, {0.5 * k, 0, 10}, {0, 0, 0, 1}, {5, 0, 0}});
    w.ground_truth("uav1", {t, {-1, 2, 15.0 + k}, xyzw(yaw1), {1, 0, 0}});
    w.ground_truth("uav2", {t, {1, -2, 17}, {0, 0, 0, 1}, {0, 0, 0}});
    for (const char* uav : {"uav1", "uav2"}) {
      cv::Mat depth(kH, kW, CV_32F, cv::Scalar(12.345f + k));
      depth.at<float>(0, 1) = 0;  // no surface
      w.write_frame(uav, t, pattern(k), depth);
      w.camera_pose(uav, {t, Eigen::Vector3d(0.1, 0.2, 14.5 + k), xyzw(Eigen::Quaterniond(R_CW()))});
    }
    w.gps("lead", {t, {0.5 * k + 0.01, -0.02, 10.03}});
    w.altimeter("uav1", {t, 15.25 + k});
    w.range("uav1", {t, 20.5 + k});
    w.ahrs("uav1", {t, 0.25});
  }
  w.finish();
}

// The bag as read_bag.py reports it.
json read_bag(const fs::path& bag, const fs::path& tmp) {
  const fs::path out = tmp / "bag.json";
  const std::string cmd = "/usr/bin/python3 " + app::test::quote(kReadBag.string()) + " " +
                          app::test::quote(bag.string()) + " > " + app::test::quote(out.string());
  EXPECT_EQ(std::system(cmd.c_str()), 0) << cmd;
  return json::parse(read_file(out));
}

std::vector<std::int64_t> steps(int n) {
  std::vector<std::int64_t> v;
  for (int k = 0; k < n; ++k) v.push_back(step_ns(k, 10));
  return v;
}

void expect_quaternion(const json& q, const Eigen::Quaterniond& want) {
  const Eigen::Quaterniond got(q["w"].get<double>(), q["x"].get<double>(), q["y"].get<double>(), q["z"].get<double>());
  EXPECT_NEAR(std::abs(got.dot(want)), 1.0, 1e-9) << q;  // q and -q are the same rotation
}

// The small dataset exported once by `wingman export` and read back by python3-rosbag.
class BagOfSmallDataset : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    tmp_ = new TempDir;
    write_small_dataset(*tmp_ / "ds");
    const fs::path bag = *tmp_ / "out.bag";
    const auto r = run_wingman({"export", (*tmp_ / "ds").string(), "--bag", bag.string(), "-q"}, tmp_->path());
    ASSERT_EQ(r.exit_code, 0) << r.output;
    topics_ = new json(read_bag(bag, tmp_->path())["topics"]);
  }
  static void TearDownTestSuite() {
    delete topics_;
    delete tmp_;
  }
  static bool has_topic(const std::string& name) {
    if (topics_ == nullptr) throw std::runtime_error("the export failed (the suite's set-up says why)");
    return topics_->contains(name);
  }
  static const json& topic(const std::string& name) {
    if (!has_topic(name)) throw std::runtime_error("no topic " + name);
    return (*topics_)[name];
  }
  static inline TempDir* tmp_ = nullptr;
  static inline json* topics_ = nullptr;
};

TEST_F(BagOfSmallDataset, EveryTopicHasItsTypeAndOneMessagePerSample) {
  const std::map<std::string, std::pair<std::string, int>> expected = {
      {"/tf", {"tf2_msgs/TFMessage", 9}},
      {"/tf_static", {"tf2_msgs/TFMessage", 1}},
      {"/lead/groundtruth/odometry", {"nav_msgs/Odometry", 3}},
      {"/uav1/groundtruth/odometry", {"nav_msgs/Odometry", 3}},
      {"/uav1/cam0/image_raw", {"sensor_msgs/Image", 3}},
      {"/uav1/cam0/camera_info", {"sensor_msgs/CameraInfo", 3}},
      {"/uav1/cam0/pose", {"geometry_msgs/PoseStamped", 3}},
      {"/uav1/depth0/image_raw", {"sensor_msgs/Image", 3}},
      {"/uav1/depth0/camera_info", {"sensor_msgs/CameraInfo", 3}},
      {"/uav2/cam0/image_raw", {"sensor_msgs/Image", 3}},
      {"/lead/gps", {"geometry_msgs/PointStamped", 3}},
      {"/uav1/altimeter", {"sensor_msgs/Range", 3}},
      {"/uav1/range", {"sensor_msgs/Range", 3}},
      {"/uav1/ahrs", {"sensor_msgs/Imu", 3}},
      {"/uav1/imu0", {"sensor_msgs/Imu", 41}},
  };
  for (const auto& [name, want] : expected) {
    EXPECT_EQ(topic(name)["type"], want.first) << name;
    EXPECT_EQ(topic(name)["count"], want.second) << name;
  }
  EXPECT_FALSE(has_topic("/uav2/range"));  // uav2 has no range samples
  EXPECT_FALSE(has_topic("/lead/cam0/image_raw"));
}

TEST_F(BagOfSmallDataset, StampsAreTheSamplesTimesAndRecordTimesFollowThem) {
  EXPECT_EQ(topic("/uav1/cam0/image_raw")["stamps"].get<std::vector<std::int64_t>>(), steps(3));
  EXPECT_EQ(topic("/uav1/altimeter")["stamps"].get<std::vector<std::int64_t>>(), steps(3));
  // rosbag's earliest record time, 1 ns, stands in for 0.
  EXPECT_EQ(topic("/lead/gps")["record_ns"].get<std::vector<std::int64_t>>(),
            (std::vector<std::int64_t>{1, 100000000, 200000000}));
}

TEST_F(BagOfSmallDataset, ImagesAreRgb8OrMono8WithTheDatasetsPixels) {
  const json& img = topic("/uav1/cam0/image_raw")["last"];
  EXPECT_EQ(img["encoding"], "rgb8");
  EXPECT_EQ(img["width"], kW);
  EXPECT_EQ(img["height"], kH);
  EXPECT_EQ(img["step"], 3 * kW);
  EXPECT_EQ(img["header"]["frame_id"], "uav1/cam0_optical");
  EXPECT_EQ(img["data"]["len"], 3 * kW * kH);
  // Pixels (0,0) and (0,1) of frame 2: R = 5 row = 0, G = 7 col, B = 102.
  EXPECT_EQ(img["data"]["head"].get<std::vector<int>>().at(2), 102);
  EXPECT_EQ(img["data"]["head"].get<std::vector<int>>().at(4), 7);

  const json& grey = topic("/uav2/cam0/image_raw")["first"];
  EXPECT_EQ(grey["encoding"], "mono8");
  EXPECT_EQ(grey["step"], kW);
  EXPECT_EQ(grey["data"]["len"], kW * kH);
  const cv::Mat want = read_dataset(*tmp_ / "ds").load_image("uav2", 0);
  ASSERT_EQ(want.channels(), 1);
  for (int c = 0; c < 16; ++c) EXPECT_EQ(grey["data"]["head"][c], want.at<std::uint8_t>(0, c)) << c;
}

TEST_F(BagOfSmallDataset, DepthIs16UC1MillimetresWithZeroForNoSurface) {
  const json& depth = topic("/uav1/depth0/image_raw")["first"];
  EXPECT_EQ(depth["encoding"], "16UC1");
  EXPECT_EQ(depth["step"], 2 * kW);
  // 12.345 m = 12345 mm = 0x3039, little-endian; pixel (0,1) has no surface: 0.
  EXPECT_EQ(depth["data"]["head"].get<std::vector<int>>(),
            (std::vector<int>{0x39, 0x30, 0, 0, 0x39, 0x30, 0x39, 0x30, 0x39, 0x30, 0x39, 0x30, 0x39, 0x30, 0x39, 0x30}));
  EXPECT_EQ(topic("/uav1/depth0/camera_info")["first"]["header"]["frame_id"], "uav1/cam0_optical");
}

TEST_F(BagOfSmallDataset, CameraInfoIsPlumbBobWithTheIntrinsics) {
  const json& info = topic("/uav1/cam0/camera_info")["first"];
  EXPECT_EQ(info["distortion_model"], "plumb_bob");
  EXPECT_EQ(info["K"].get<std::vector<double>>(), (std::vector<double>{30.5, 0, 15.5, 0, 31.5, 11.5, 0, 0, 1}));
  EXPECT_EQ(info["D"].get<std::vector<double>>(), (std::vector<double>{0.01, -0.02, 0.001, 0.002, 0.003}));
  EXPECT_EQ(info["R"].get<std::vector<double>>(), (std::vector<double>{1, 0, 0, 0, 1, 0, 0, 0, 1}));
  EXPECT_EQ(info["P"].get<std::vector<double>>(), (std::vector<double>{30.5, 0, 15.5, 0, 0, 31.5, 11.5, 0, 0, 0, 1, 0}));
  EXPECT_EQ(info["width"], kW);
  EXPECT_EQ(info["height"], kH);
}

TEST_F(BagOfSmallDataset, TfCarriesEveryAgentsGroundTruthPoseFromTheWorld) {
  const Eigen::Quaterniond yaw1(Eigen::AngleAxisd(kYaw1, Eigen::Vector3d::UnitZ()));
  std::map<std::string, int> per_child;
  for (const json& m : topic("/tf")["messages"]) {
    const json& tf = m["transforms"][0];
    EXPECT_EQ(tf["header"]["frame_id"], "world");
    ++per_child[tf["child_frame_id"].get<std::string>()];
    if (tf["child_frame_id"] != "uav1/base_link" || tf["header"]["stamp"] != 200000000) continue;
    EXPECT_DOUBLE_EQ(tf["transform"]["translation"]["x"].get<double>(), -1.0);
    EXPECT_DOUBLE_EQ(tf["transform"]["translation"]["z"].get<double>(), 17.0);
    expect_quaternion(tf["transform"]["rotation"], yaw1);
  }
  EXPECT_EQ(per_child, (std::map<std::string, int>{{"lead/base_link", 3}, {"uav1/base_link", 3}, {"uav2/base_link", 3}}));
}

// uav1's mount: the dataset's nominal T_BS of cam0, the offset and R_CW^T, whatever the body's
// attitude (uav1 is yawed by 90°).
TEST_F(BagOfSmallDataset, TfStaticCarriesTheNominalMountLatched) {
  EXPECT_EQ(topic("/tf_static")["latching"], "1");
  const json& st = topic("/tf_static")["first"]["transforms"][0];
  EXPECT_EQ(topic("/tf_static")["first"]["transforms"].size(), 2u);
  EXPECT_EQ(st["header"]["frame_id"], "uav1/base_link");
  EXPECT_EQ(st["child_frame_id"], "uav1/cam0_optical");
  EXPECT_NEAR(st["transform"]["translation"]["x"].get<double>(), 1.0, 1e-12);
  EXPECT_NEAR(st["transform"]["translation"]["y"].get<double>(), 2.0, 1e-12);
  EXPECT_NEAR(st["transform"]["translation"]["z"].get<double>(), -0.5, 1e-12);
  expect_quaternion(st["transform"]["rotation"], Eigen::Quaterniond(Eigen::Matrix3d(R_CW().transpose())));
}

// uav1 moves along world +x, which is its body's -y after a 90° yaw.
TEST_F(BagOfSmallDataset, OdometryVelocityIsInTheBodyFrame) {
  const json& odo = topic("/uav1/groundtruth/odometry")["first"];
  EXPECT_EQ(odo["header"]["frame_id"], "world");
  EXPECT_EQ(odo["child_frame_id"], "uav1/base_link");
  EXPECT_NEAR(odo["twist"]["twist"]["linear"]["x"].get<double>(), 0.0, 1e-12);
  EXPECT_NEAR(odo["twist"]["twist"]["linear"]["y"].get<double>(), -1.0, 1e-12);
  EXPECT_EQ(odo["twist"]["covariance"][21], -1);  // angular rate not recorded
  EXPECT_DOUBLE_EQ(odo["pose"]["pose"]["position"]["y"].get<double>(), 2.0);
  EXPECT_DOUBLE_EQ(topic("/lead/groundtruth/odometry")["last"]["twist"]["twist"]["linear"]["x"].get<double>(), 5.0);
}

// The true camera pose: the optical frame's orientation in the world, R_WC = R_CW^T.
TEST_F(BagOfSmallDataset, CameraPoseIsTheTrueOpticalFrameInTheWorld) {
  const json& cam = topic("/uav1/cam0/pose")["last"];
  EXPECT_EQ(cam["header"]["frame_id"], "world");
  EXPECT_DOUBLE_EQ(cam["pose"]["position"]["z"].get<double>(), 16.5);
  expect_quaternion(cam["pose"]["orientation"], Eigen::Quaterniond(Eigen::Matrix3d(R_CW().transpose())));
}

TEST_F(BagOfSmallDataset, GpsAltimeterRangeAndAhrsKeepTheirValues) {
  EXPECT_DOUBLE_EQ(topic("/lead/gps")["last"]["point"]["x"].get<double>(), 1.01);
  EXPECT_DOUBLE_EQ(topic("/lead/gps")["last"]["point"]["z"].get<double>(), 10.03);
  EXPECT_FLOAT_EQ(topic("/uav1/range")["last"]["range"].get<float>(), 22.5f);
  EXPECT_FLOAT_EQ(topic("/uav1/altimeter")["first"]["range"].get<float>(), 15.25f);
  EXPECT_EQ(topic("/uav1/altimeter")["first"]["max_range"], "inf");
  const json& ahrs = topic("/uav1/ahrs")["first"];
  expect_quaternion(ahrs["orientation"], Eigen::Quaterniond(Eigen::AngleAxisd(0.25, Eigen::Vector3d::UnitZ())));
  EXPECT_EQ(ahrs["angular_velocity_covariance"][0], -1);
  EXPECT_EQ(ahrs["linear_acceleration_covariance"][0], -1);
}

// Every IMU sample of the dataset, 200 Hz from 0 to the last frame, with the values written.
TEST_F(BagOfSmallDataset, ImuTopicHoldsTheDatasetsImuSamples) {
  EXPECT_EQ(read_dataset(*tmp_ / "ds").agent("uav1").imu.size(), 41u);
  const json& imu = topic("/uav1/imu0");
  EXPECT_EQ(imu["type"], "sensor_msgs/Imu");
  EXPECT_EQ(imu["count"], 41);
  EXPECT_EQ(imu["stamps"][1], 5000000);
  EXPECT_EQ(imu["last"]["header"]["stamp"], 200000000);
  EXPECT_EQ(imu["last"]["header"]["frame_id"], "uav1/base_link");
  EXPECT_DOUBLE_EQ(imu["last"]["angular_velocity"]["z"].get<double>(), 40.3);
  EXPECT_DOUBLE_EQ(imu["last"]["linear_acceleration"]["z"].get<double>(), 9.81);
  EXPECT_NEAR(imu["last"]["angular_velocity_covariance"][4].get<double>(), 0.01 * 0.01 * 200, 1e-15);
  EXPECT_EQ(topic("/uav2/imu0")["count"], 41);
}

// The IMU through the library on an in-memory dataset (no frames needed): the samples' values in
// the body frame, no orientation (-1), covariances σ² = density² · rate.
TEST(BagExport, ImuMessagesCarryTheSamplesAndCovariancesFromTheNoiseDensities) {
  TempDir tmp;
  Dataset ds;
  AgentData uav;
  uav.name = "uav1";
  uav.imu_info = ImuInfo{200, 0.01, 0.001, 0.1, 0.01};
  for (int i = 0; i < 5; ++i) uav.imu.push_back({1'000'000'000 + i * 5'000'000, {0.1 * i, -0.2, 0.3}, {0.5, 0.25 * i, 9.81}});
  ds.agents.push_back(uav);
  const fs::path bag = tmp / "imu.bag";
  std::size_t calls = 0;
  const BagExportSummary s = write_bag(ds, bag, {BagCompression::Lz4, [&](std::size_t, std::size_t) { ++calls; }});
  EXPECT_EQ(s.messages.at("/uav1/imu0"), 5u);
  EXPECT_EQ(calls, 5u);

  const json m = read_bag(bag, tmp.path())["topics"]["/uav1/imu0"];
  EXPECT_EQ(m["type"], "sensor_msgs/Imu");
  EXPECT_EQ(m["stamps"].get<std::vector<std::int64_t>>(),
            (std::vector<std::int64_t>{1000000000, 1005000000, 1010000000, 1015000000, 1020000000}));
  const json& last = m["last"];
  EXPECT_EQ(last["header"]["frame_id"], "uav1/base_link");
  EXPECT_DOUBLE_EQ(last["angular_velocity"]["x"].get<double>(), 0.4);
  EXPECT_DOUBLE_EQ(last["linear_acceleration"]["y"].get<double>(), 1.0);
  EXPECT_DOUBLE_EQ(last["linear_acceleration"]["z"].get<double>(), 9.81);
  EXPECT_EQ(last["orientation_covariance"][0], -1);
  EXPECT_NEAR(last["angular_velocity_covariance"][0].get<double>(), 0.01 * 0.01 * 200, 1e-15);
  EXPECT_NEAR(last["angular_velocity_covariance"][8].get<double>(), 0.01 * 0.01 * 200, 1e-15);
  EXPECT_EQ(last["angular_velocity_covariance"][1], 0);
  EXPECT_NEAR(last["linear_acceleration_covariance"][4].get<double>(), 0.1 * 0.1 * 200, 1e-15);
}

// A dataset of format version 1 (no IMU; tests/datasets/to_format_version_1.py) exports the same
// topics less the IMU's, with the same mount.
TEST(BagExport, FormatVersion1DatasetExportsWithoutImuTopics) {
  TempDir tmp;
  write_small_dataset(tmp / "ds");
  const fs::path convert = app::test::kSourceDir / "tests" / "datasets" / "to_format_version_1.py";
  const std::string cmd = "/usr/bin/python3 " + app::test::quote(convert.string()) + " " + app::test::quote((tmp / "ds").string());
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  ASSERT_EQ(read_dataset(tmp / "ds").info.format_version, 1);
  const auto r = run_wingman({"export", (tmp / "ds").string(), "--bag", (tmp / "v1.bag").string(), "-q"}, tmp.path());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const json b = read_bag(tmp / "v1.bag", tmp.path())["topics"];
  EXPECT_FALSE(b.contains("/uav1/imu0"));
  EXPECT_FALSE(b.contains("/uav2/imu0"));
  EXPECT_EQ(b["/uav1/cam0/image_raw"]["count"], 3);
  EXPECT_EQ(b["/tf"]["count"], 9);
  const json& st = b["/tf_static"]["first"]["transforms"][0];
  EXPECT_NEAR(st["transform"]["translation"]["y"].get<double>(), 2.0, 1e-9);
  expect_quaternion(st["transform"]["rotation"], Eigen::Quaterniond(Eigen::Matrix3d(R_CW().transpose())));
}

TEST(BagExport, RefusesToReplaceAnExistingFileWithoutForce) {
  TempDir tmp;
  write_small_dataset(tmp / "ds");
  const fs::path bag = tmp / "precious.bag";
  write_file(bag, "precious");
  auto r = run_wingman({"export", (tmp / "ds").string(), "--bag", bag.string(), "-q"}, tmp.path());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find(bag.string()), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("--force"), std::string::npos) << r.output;
  EXPECT_EQ(read_file(bag), "precious");

  r = run_wingman({"export", (tmp / "ds").string(), "--bag", bag.string(), "--force", "-q"}, tmp.path());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(read_file(bag).substr(0, 13), "#ROSBAG V2.0\n");
  EXPECT_EQ(std::distance(fs::directory_iterator(tmp.path()), fs::directory_iterator{}), 2);  // ds and the bag
}

// A SIGKILLed export's partial file (its pid gone) goes with the next export to the same file;
// a running export's stays.
TEST(BagExport, PartialFileOfAKilledExportIsRemovedByTheNext) {
  TempDir tmp;
  write_small_dataset(tmp / "ds");
  write_file(tmp / "out.bag.partial-999999999", "killed");  // above any pid_max
  const std::string running = "out.bag.partial-" + std::to_string(::getpid());
  write_file(tmp / running, "running");
  const auto r = run_wingman({"export", (tmp / "ds").string(), "--bag", (tmp / "out.bag").string(), "-q"}, tmp.path());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_FALSE(fs::exists(tmp / "out.bag.partial-999999999"));
  EXPECT_NE(r.output.find("out.bag.partial-999999999"), std::string::npos) << r.output;
  EXPECT_EQ(read_file(tmp / running), "running");
  EXPECT_TRUE(fs::exists(tmp / "out.bag"));
}

TEST(BagExport, UnwritablePathExitsTwoNamingItAndLeavesNothing) {
  TempDir tmp;
  write_small_dataset(tmp / "ds");
  write_file(tmp / "plain-file", "x");
  std::vector<fs::path> bad = {tmp / "no-such-dir" / "out.bag", tmp / "plain-file" / "out.bag", tmp / "ds"};
  fs::create_directories(tmp / "read-only");
  fs::permissions(tmp / "read-only", fs::perms::owner_read | fs::perms::owner_exec);
  if (::geteuid() != 0) bad.push_back(tmp / "read-only" / "out.bag");  // root writes anywhere
  for (const fs::path& p : bad) {
    const auto r = run_wingman({"export", (tmp / "ds").string(), "--bag", p.string(), "-q"}, tmp.path());
    EXPECT_EQ(r.exit_code, 2) << p << ": " << r.output;
    EXPECT_NE(r.output.find(p.string()), std::string::npos) << r.output;
  }
  EXPECT_FALSE(fs::exists(tmp / "no-such-dir"));
  EXPECT_TRUE(fs::is_empty(tmp / "read-only"));
  EXPECT_EQ(std::distance(fs::directory_iterator(tmp.path()), fs::directory_iterator{}), 3);
  fs::permissions(tmp / "read-only", fs::perms::owner_all);
}

// Ctrl-C during the export: exit 130 and neither the bag nor its temporary file remain.
TEST(BagExport, InterruptedExportLeavesNoFile) {
  TempDir tmp;
  write_small_dataset(tmp / "ds", 400);
  const fs::path bag = tmp / "out.bag";
  const pid_t pid = ::fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    const int null = ::open("/dev/null", O_WRONLY);
    ::dup2(null, STDOUT_FILENO);
    ::dup2(null, STDERR_FILENO);
    ::execl(app::test::kBinary.c_str(), "wingman", "export", (tmp / "ds").c_str(), "--bag", bag.c_str(), "-q",
            static_cast<char*>(nullptr));
    ::_exit(127);
  }
  // Wait until the export has begun writing, then interrupt it.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  const fs::path partial = tmp / ("out.bag.partial-" + std::to_string(pid));
  int status = 0;
  std::error_code ec;
  while (fs::file_size(partial, ec) == 0 || ec) {
    if (::waitpid(pid, &status, WNOHANG) == pid) FAIL() << "the export ended before it was interrupted: " << status;
    if (std::chrono::steady_clock::now() > deadline) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  ::kill(pid, SIGINT);
  ASSERT_EQ(::waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 130);
  EXPECT_FALSE(fs::exists(bag));
  EXPECT_FALSE(fs::exists(partial));
}

}  // namespace
}  // namespace wingman::datasets
