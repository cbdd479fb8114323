// The dataset format: a written dataset reads back equal (images exactly, depth to the mm), and
// the reader's errors name the file at fault (missing frame, wrong size, unknown version).
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <random>
#include <sstream>
#include <tuple>

#include "datasets/dataset.hpp"

namespace wingman::datasets {
namespace {

namespace fs = std::filesystem;

struct TempDir {
  fs::path path;
  TempDir() {
    static int n = 0;
    path = fs::temp_directory_path() /
           ("wingman-dataset-test-" + std::to_string(::getpid()) + "-" + std::to_string(n++));
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
};

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

struct Written {
  std::vector<cv::Mat> rgb, depth;
};

// Two agents: the lead (GPS) and one UAV with a 64 x 48 camera, three frames and an IMU.
Written write_small(const fs::path& dir, int channels = 3, double k3 = 0) {
  DatasetInfo info;
  info.scenario = "unit";
  info.seed = 42;
  info.software_version = "test";
  info.rate = 10;
  info.agents = {"lead", "uav1"};
  DatasetWriter w(dir, info);
  w.add_agent("lead", std::nullopt);
  CameraInfo cam;
  cam.camera = geometry::PinholeCamera(40, 41, 31.5, 23.5, 64, 48, {-0.1, 0.01, 0.001, 0, k3});
  cam.R_CW << 1, 0, 0, 0, -1, 0, 0, 0, -1;
  cam.offset = {0.1, 0, -0.05};
  cam.channels = channels;
  w.add_agent("uav1", cam);
  w.imu_info("uav1", {200, 1e-4, 2e-5, 2e-3, 3e-3});
  for (int i = 0; i <= 40; ++i) w.imu("uav1", {step_ns(i, 200), {0.001 * i, 0, -0.5}, {0.25, 0, 9.75}});
  Written out;
  cv::RNG rng(7);
  for (int k = 0; k < 3; ++k) {
    const auto t = step_ns(k, 10);
    cv::Mat rgb(48, 64, CV_8UC3), depth(48, 64, CV_32F);
    rng.fill(rgb, cv::RNG::UNIFORM, 0, 256);
    rng.fill(depth, cv::RNG::UNIFORM, 5.0, 30.0);
    depth.at<float>(0, 0) = 0;    // no surface
    depth.at<float>(1, 1) = 80;   // beyond 65.535 m: unknown
    w.write_frame("uav1", t, rgb, depth);
    out.rgb.push_back(rgb);
    out.depth.push_back(depth);
    w.ground_truth("lead", {t, {1.0 * k, 2, 0}, {0, 0, 0.3826834, 0.9238795}, {1, 0, 0}});
    w.ground_truth("uav1", {t, {1.0 * k, 2, 15}, {0, 0, 0, 1}, {1, 0, 0}, {0.001, 0.002, 0.003}, {0.125, 0, -0.25}});
    w.camera_pose("uav1", {t, {1.0 * k + 0.1, 2, 14.95}, {1, 0, 0, 0}, {}});
    w.gps("lead", {t, {1.0 * k + 0.5, 2.25, -0.125}});
    w.altimeter("uav1", {t, 15.25});
    w.range("uav1", {t, 15.5});
    w.ahrs("uav1", {t, 0.0625});
    geometry::LeadImage lead;
    if (k < 2) lead.uv = {30.25 + k, 20.5};  // frame 2: x_h behind the camera
    lead.distance = 15.5;
    lead.visible = k == 0 ? 1.0 : 0.375;
    if (k < 2) lead.box_u0 = 25, lead.box_v0 = 16, lead.box_u1 = 36, lead.box_v1 = 27;
    w.lead_label("uav1", {t, lead});
  }
  w.finish();
  return out;
}

TEST(Dataset, RoundTrip) {
  TempDir tmp;
  const Written w = write_small(tmp.path);
  const Dataset ds = read_dataset(tmp.path);
  EXPECT_EQ(ds.info.format_version, kFormatVersion);
  EXPECT_EQ(ds.info.scenario, "unit");
  EXPECT_EQ(ds.info.seed, 42u);
  EXPECT_EQ(ds.info.frames, 3);
  ASSERT_EQ(ds.agents.size(), 2u);
  const AgentData& u = ds.agent("uav1");
  ASSERT_TRUE(u.camera);
  EXPECT_EQ(u.camera->camera.width(), 64);
  EXPECT_DOUBLE_EQ(u.camera->camera.fy(), 41);
  EXPECT_DOUBLE_EQ(u.camera->camera.cx(), 31.5);
  EXPECT_DOUBLE_EQ(u.camera->camera.distortion().k1, -0.1);
  EXPECT_DOUBLE_EQ(u.camera->R_CW(1, 1), -1);
  EXPECT_DOUBLE_EQ(u.camera->offset.z(), -0.05);
  ASSERT_EQ(u.frames.size(), 3u);
  EXPECT_EQ(u.frames[2], 200000000);
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(cv::norm(ds.load_image("uav1", u.frames[k]), w.rgb[k], cv::NORM_INF), 0);
    const cv::Mat d = ds.load_depth("uav1", u.frames[k]);
    EXPECT_EQ(d.at<float>(0, 0), 0);
    EXPECT_EQ(d.at<float>(1, 1), 0);
    cv::Mat diff = cv::abs(d - w.depth[k]);
    diff.at<float>(1, 1) = 0;
    double worst = 0;
    cv::minMaxLoc(diff, nullptr, &worst);
    EXPECT_LE(worst, 0.0005 + 1e-5);  // rounded to the millimetre (plus float rounding at 30 m)
  }
  EXPECT_DOUBLE_EQ(ds.agent("lead").groundtruth[2].p.x(), 2.0);
  EXPECT_NEAR(ds.agent("lead").groundtruth[1].q_xyzw.z(), 0.3826834, 1e-9);
  EXPECT_DOUBLE_EQ(ds.agent("lead").gps[1].value.y(), 2.25);
  EXPECT_DOUBLE_EQ(u.altimeter[0].value, 15.25);
  EXPECT_DOUBLE_EQ(u.range[0].value, 15.5);
  EXPECT_DOUBLE_EQ(u.ahrs[0].value, 0.0625);
  EXPECT_DOUBLE_EQ(u.camera_pose[0].q_xyzw.x(), 1);
  ASSERT_TRUE(u.imu_info);
  EXPECT_DOUBLE_EQ(u.imu_info->rate, 200);
  EXPECT_DOUBLE_EQ(u.imu_info->accelerometer_random_walk, 3e-3);
  ASSERT_EQ(u.imu.size(), 41u);
  EXPECT_EQ(u.imu[40].t_ns, 200000000);
  EXPECT_DOUBLE_EQ(u.imu[40].w_S.x(), 0.04);
  EXPECT_DOUBLE_EQ(u.imu[3].a_S.z(), 9.75);
  EXPECT_DOUBLE_EQ(u.groundtruth[1].b_w.z(), 0.003);
  EXPECT_DOUBLE_EQ(u.groundtruth[1].b_a.z(), -0.25);
  EXPECT_FALSE(ds.agent("lead").imu_info);
}

// EuRoC's radial-tangential model takes k1, k2, p1, p2; a lens with k3 is written as plumb_bob.
TEST(Dataset, DistortionIsWrittenWithTheCountItsModelTakes) {
  TempDir a, b;
  write_small(a.path);
  write_small(b.path, 3, 0.002);
  const std::string radtan = slurp(a.path / "uav1" / "mav0" / "cam0" / "sensor.yaml");
  EXPECT_NE(radtan.find("distortion_model: radial-tangential\ndistortion_coefficients: [-0.1, 0.01, 0.001, 0]\n"),
            std::string::npos) << radtan;
  const std::string bob = slurp(b.path / "uav1" / "mav0" / "cam0" / "sensor.yaml");
  EXPECT_NE(bob.find("distortion_model: plumb_bob\ndistortion_coefficients: [-0.1, 0.01, 0.001, 0, 0.002]\n"),
            std::string::npos) << bob;
  EXPECT_DOUBLE_EQ(read_dataset(b.path).agent("uav1").camera->camera.distortion().k3, 0.002);
  EXPECT_DOUBLE_EQ(read_dataset(a.path).agent("uav1").camera->camera.distortion().k3, 0);
  // T_BS: the nominal mount, R_BS = R_CW^T and the offset.
  EXPECT_NE(radtan.find("data: [1, 0, 0, 0.1, 0, -1, 0, 0, 0, 0, -1, -0.05, 0, 0, 0, 1]"), std::string::npos) << radtan;
}

TEST(Dataset, TheShutterIsReadBackAndABadOneNamesTheFile) {
  TempDir a;
  write_small(a.path);
  EXPECT_FALSE(read_dataset(a.path).agent("uav1").camera->rolling);
  const fs::path yaml = a.path / "uav1" / "mav0" / "cam0" / "sensor.yaml";
  const std::string global = slurp(yaml);
  auto with = [&](const std::string& from, const std::string& to) {
    std::string s = global;
    const auto pos = s.find(from);
    EXPECT_NE(pos, std::string::npos) << from;
    std::ofstream(yaml) << s.replace(pos, from.size(), to);
  };
  with("  type: global\n  exposure_s: 0\n  line_delay_s: 0\n  readout: top_to_bottom",
       "  type: rolling\n  exposure_s: 0\n  line_delay_s: 3e-05\n  readout: bottom_to_top");
  const CameraInfo c = *read_dataset(a.path).agent("uav1").camera;
  EXPECT_TRUE(c.rolling);
  EXPECT_DOUBLE_EQ(c.line_delay_s, 3e-5);
  EXPECT_FALSE(c.top_to_bottom);
  for (const auto& [from, to, message] :
       {std::tuple{"  type: global", "  type: sideways", "shutter.type 'sideways': expected global or rolling"},
        std::tuple{"  type: global", "  type: rolling", "shutter.line_delay_s must be above 0 for a rolling shutter"},
        std::tuple{"  line_delay_s: 0", "  line_delay_s: 0.5", "shutter.line_delay_s 0.5 must be in [0, 0.001]"}}) {
    with(from, to);
    try {
      read_dataset(a.path);
      ADD_FAILURE() << to;
    } catch (const DatasetError& e) {
      EXPECT_EQ(std::string(e.what()), yaml.string() + ": " + message);
    }
  }
}

TEST(Dataset, TheLeadsLabelsAreReadBackAndAMalformedRowNamesTheFileAndLine) {
  TempDir a;
  write_small(a.path);
  const auto& labels = read_dataset(a.path).agent("uav1").lead_labels;
  ASSERT_EQ(labels.size(), 3u);
  EXPECT_EQ(labels[1].t_ns, step_ns(1, 10));
  EXPECT_DOUBLE_EQ(labels[1].lead.uv.x(), 31.25);
  EXPECT_DOUBLE_EQ(labels[1].lead.visible, 0.375);
  EXPECT_EQ(labels[1].lead.box_u1, 36);
  EXPECT_TRUE(std::isnan(labels[2].lead.uv.x()));
  EXPECT_TRUE(read_dataset(a.path).agent("lead").lead_labels.empty());
  const fs::path csv = a.path / "uav1" / "mav0" / "cam0_lead0" / "data.csv";
  const std::string good = slurp(csv);
  for (const auto& [from, to, message] :
       {std::tuple{",0.375,", ",1.5,", "data row 2: distance must be >= 0 and visible in [0, 1]"},
        std::tuple{",25,16,36,27\n100000000", ",25.5,16,36,27\n100000000", "data row 1: box bound 25.5 is not a whole pixel"},
        std::tuple{"100000000,", "100000001,", "data row 2: time stamp 100000001 is not frame 2's"}}) {
    std::string s = good;
    const auto pos = s.find(from);
    ASSERT_NE(pos, std::string::npos) << from;
    std::ofstream(csv) << s.replace(pos, std::string(from).size(), to);
    try {
      read_dataset(a.path);
      ADD_FAILURE() << to;
    } catch (const DatasetError& e) {
      EXPECT_EQ(std::string(e.what()), csv.string() + ": " + message);
    }
  }
}

TEST(Dataset, GrayFramesRoundTrip) {
  TempDir tmp;
  write_small(tmp.path, 1);
  const Dataset ds = read_dataset(tmp.path);
  EXPECT_EQ(ds.load_image("uav1", 0).channels(), 1);
}

std::string error_of(const fs::path& dir) {
  try {
    read_dataset(dir);
  } catch (const DatasetError& e) {
    return e.what();
  }
  return "no error";
}

TEST(Dataset, MissingFrameNamesTheFile) {
  TempDir tmp;
  write_small(tmp.path);
  const fs::path f = tmp.path / "uav1" / "mav0" / "cam0" / "data" / "100000000.png";
  fs::remove(f);
  const std::string e = error_of(tmp.path);
  EXPECT_NE(e.find(f.string()), std::string::npos) << e;
  EXPECT_NE(e.find("missing frame"), std::string::npos) << e;
}

TEST(Dataset, WrongImageSizeNamesTheFile) {
  TempDir tmp;
  write_small(tmp.path);
  const fs::path f = tmp.path / "uav1" / "mav0" / "depth0" / "data" / "0.png";
  cv::imwrite(f.string(), cv::Mat(10, 12, CV_16U, cv::Scalar(1000)));
  const std::string e = error_of(tmp.path);
  EXPECT_NE(e.find(f.string()), std::string::npos) << e;
  EXPECT_NE(e.find("12x10"), std::string::npos) << e;
}

TEST(Dataset, UnknownFormatVersionNamesTheFile) {
  TempDir tmp;
  write_small(tmp.path);
  const fs::path y = tmp.path / "dataset.yaml";
  std::ifstream in(y);
  std::stringstream s;
  s << in.rdbuf();
  std::string text = s.str();
  text.replace(text.find("format_version: 2"), 17, "format_version: 7");
  std::ofstream(y) << text;
  const std::string e = error_of(tmp.path);
  EXPECT_NE(e.find(y.string()), std::string::npos) << e;
  EXPECT_NE(e.find("unknown format_version 7"), std::string::npos) << e;
}

TEST(Dataset, UnfinishedDirectoryIsNotADataset) {
  TempDir tmp;
  write_small(tmp.path);
  fs::remove(tmp.path / "dataset.yaml");
  EXPECT_NE(error_of(tmp.path).find("dataset.yaml: missing"), std::string::npos);
  EXPECT_NE(error_of(tmp.path / "nope").find("not a directory"), std::string::npos);
}

TEST(Dataset, CorruptCsvRowNamesTheFileAndLine) {
  TempDir tmp;
  write_small(tmp.path);
  const fs::path csv = tmp.path / "uav1" / "mav0" / "altimeter0" / "data.csv";
  std::ofstream(csv, std::ios::app) << "300000000,abc\n";
  const std::string e = error_of(tmp.path);
  EXPECT_NE(e.find(csv.string()), std::string::npos) << e;
  EXPECT_NE(e.find("'abc' is not a number"), std::string::npos) << e;
}

TEST(Dataset, AnImageThatCannotBeWrittenFailsTheWriterNamingIt) {
  TempDir tmp;
  DatasetInfo info;
  info.agents = {"uav1"};
  DatasetWriter w(tmp.path, info, 2);
  CameraInfo cam;
  cam.camera = geometry::PinholeCamera(40, 40, 31.5, 23.5, 64, 48);
  w.add_agent("uav1", cam);
  fs::remove_all(tmp.path / "uav1" / "mav0" / "cam0" / "data");  // the encoder cannot write there
  try {
    for (int k = 0; k < 50; ++k)
      w.write_frame("uav1", step_ns(k, 10), cv::Mat(48, 64, CV_8UC3, cv::Scalar::all(9)),
                    cv::Mat(48, 64, CV_32F, cv::Scalar(3)));
    w.finish();
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("cannot write"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("cam0/data"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(tmp.path / "dataset.yaml"));
}

// A UAV of a version-2 dataset without one of its sensors: the reader names the missing folder.
TEST(Dataset, AMissingSensorFolderIsNamed) {
  for (const char* sensor : {"imu0", "depth0", "cam0_pose0", "state_groundtruth_estimate0"}) {
    TempDir tmp;
    write_small(tmp.path);
    fs::remove_all(tmp.path / "uav1" / "mav0" / sensor);
    const std::string e = error_of(tmp.path);
    EXPECT_NE(e.find((tmp.path / "uav1" / "mav0" / sensor).string() + ": missing sensor folder"), std::string::npos)
        << sensor << ": " << e;
  }
}

}  // namespace
}  // namespace wingman::datasets

namespace wingman::datasets {
namespace {

// Replaces the first `from` in the file by `to` (which must be there).
void patch(const fs::path& p, const std::string& from, const std::string& to) {
  std::string text = slurp(p);
  const auto at = text.find(from);
  ASSERT_NE(at, std::string::npos) << from << " not in " << p;
  text.replace(at, from.size(), to);
  std::ofstream(p, std::ios::binary | std::ios::trunc) << text;
}

std::string verify_error(const fs::path& dir) {
  try {
    verify_frames(read_dataset(dir));
  } catch (const DatasetError& e) {
    return e.what();
  }
  return "no error";
}

TEST(Dataset, WriterRecordsEveryFramesSizeAndChecksum) {
  TempDir tmp;
  write_small(tmp.path);
  const std::string sums = slurp(tmp.path / kChecksumsFile);
  EXPECT_EQ(sums.rfind("#file,bytes,crc32\n", 0), 0u);
  const std::string frame = slurp(tmp.path / "uav1" / "mav0" / "cam0" / "data" / "100000000.png");
  const auto crc = crc32_of(reinterpret_cast<const unsigned char*>(frame.data()), frame.size());
  char line[128];
  std::snprintf(line, sizeof line, "uav1/mav0/cam0/data/100000000.png,%zu,%08x\n", frame.size(), crc);
  EXPECT_NE(sums.find(line), std::string::npos) << sums;
  EXPECT_EQ(verify_error(tmp.path), "no error");
  int calls = 0;
  verify_frames(read_dataset(tmp.path), [&](int done, int total) {
    ++calls;
    EXPECT_EQ(total, 6);
    EXPECT_EQ(done, calls);
  });
  EXPECT_EQ(calls, 6);  // 3 colour and 3 depth frames
}

TEST(Dataset, AFrameWithAValidHeaderAndABrokenBodyIsFoundBeforeReplay) {
  TempDir tmp;
  write_small(tmp.path);
  const fs::path f = tmp.path / "uav1" / "mav0" / "cam0" / "data" / "0.png";  // frame 0 too
  std::string bytes = slurp(f);
  bytes[bytes.size() / 2] ^= 0x5a;
  std::ofstream(f, std::ios::binary | std::ios::trunc) << bytes;
  EXPECT_EQ(read_dataset(tmp.path).agents.size(), 2u);  // the header alone looks fine
  const std::string e = verify_error(tmp.path);
  EXPECT_NE(e.find(f.string() + ": CRC-32"), std::string::npos) << e;
  // Without checksums.csv (an older dataset) every frame is decoded instead.
  fs::remove(tmp.path / kChecksumsFile);
  std::ofstream(f, std::ios::binary | std::ios::trunc) << bytes.substr(0, 200);
  EXPECT_NE(verify_error(tmp.path).find(f.string() + ": cannot decode the frame"), std::string::npos);
}

TEST(Dataset, ValuesOutOfRangeAreRefusedNamingFileAndRow) {
  struct Case {
    const char* file;
    const char* from;
    const char* to;
    const char* says;
  };
  const std::vector<Case> cases = {
      {"uav1/mav0/cam0/sensor.yaml", "intrinsics: [40", "intrinsics: [0", "fx and fy must be positive"},
      {"uav1/mav0/cam0/sensor.yaml", "intrinsics: [40", "intrinsics: [.nan", "fx and fy must be positive"},
      {"uav1/mav0/cam0/sensor.yaml", "data: [1", "data: [0", "T_BS's rotation is not a rotation matrix"},
      {"uav1/mav0/cam0/sensor.yaml", "0, 0, 0, 1]", "0, 0, 1, 1]", "T_BS.data: the last row must be 0 0 0 1"},
      {"uav1/mav0/cam0/sensor.yaml", "rate_hz: 10", "rate_hz: -10", "rate_hz must be in (0, 1000]"},
      {"uav1/mav0/cam0/sensor.yaml", "0.001, 0]", "0.001, 0, 0]", "key 'distortion_coefficients' must have 4 numbers"},
      {"uav1/mav0/cam0/sensor.yaml", "encoding: rgb8", "encoding: bgr16", "encoding 'bgr16'"},
      {"uav1/mav0/imu0/sensor.yaml", "gyroscope_noise_density: 0.0001", "gyroscope_noise_density: -1",
       "gyroscope_noise_density must be >= 0"},
      {"uav1/mav0/imu0/data.csv", "5000000,", "5000000,x,", "line 3: expected 7 columns, got 8"},
      {"dataset.yaml", "rate_hz: 10", "rate_hz: -10", "rate_hz must be in (0, 1000]"},
      {"dataset.yaml", "agents: [lead, uav1]", "agents: [lead, ../uav1]", "is not an agent name"},
      {"dataset.yaml", "agents: [lead, uav1]", "agents: [lead, uav1, uav1]", "listed twice"},
      {"lead/mav0/gps0/data.csv", "100000000,1.5", "100000000,nan", "data row 2: nan is not a finite value"},
      {"lead/mav0/gps0/data.csv", "100000000,1.5", "100000000,1e308", "data row 2: 1e308 is not a finite value"},
      {"uav1/mav0/altimeter0/data.csv", "200000000,", "000000001,", "data row 3: time stamps must increase"},
      {"lead/mav0/state_groundtruth_estimate0/data.csv", "0.9238795", "0.5", "the quaternion has norm"},
      {"uav1/mav0/state_groundtruth_estimate0/data.csv", ",-0.25\n", "\n", "expected 17 columns, got 16"},
  };
  for (const Case& c : cases) {
    TempDir tmp;
    write_small(tmp.path);
    patch(tmp.path / c.file, c.from, c.to);
    const std::string e = error_of(tmp.path);
    EXPECT_NE(e.find((tmp.path / c.file).string()), std::string::npos) << c.to << ": " << e;
    EXPECT_NE(e.find(c.says), std::string::npos) << c.to << ": " << e;
  }
}

}  // namespace
}  // namespace wingman::datasets
