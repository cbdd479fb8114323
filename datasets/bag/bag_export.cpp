#include "datasets/bag/bag_export.hpp"

#include <geometry_msgs/PointStamped.h>
#include <geometry_msgs/PoseStamped.h>
#include <geometry_msgs/TransformStamped.h>
#include <nav_msgs/Odometry.h>
#include <rosbag/bag.h>
#include <rosbag/exceptions.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/Range.h>
#include <sensor_msgs/distortion_models.h>
#include <sensor_msgs/image_encodings.h>
#include <tf2_msgs/TFMessage.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <numeric>
#include <opencv2/core.hpp>
#include <stdexcept>
#include <vector>

namespace wingman::datasets {

std::size_t BagExportSummary::total() const {
  std::size_t n = 0;
  for (const auto& [topic, count] : messages) n += count;
  return n;
}

std::string bag_body_frame(const std::string& agent) { return agent + "/base_link"; }
std::string bag_camera_frame(const std::string& agent) { return agent + "/cam0_optical"; }

namespace {

// What one message carries; events are written in time order so that a chunk holds one stretch
// of time (rosbag play and time-windowed reads touch few chunks).
enum class Stream { Tf, Odometry, Frame, CameraPose, Imu, Gps, Altimeter, Range, Ahrs };

struct Event {
  std::int64_t t_ns;
  Stream stream;
  std::size_t agent, index;
};

ros::Time stamp(std::int64_t t_ns) {
  ros::Time t;
  t.fromNSec(static_cast<std::uint64_t>(t_ns));
  return t;
}

// The bag's record time: the stamp, except that rosbag refuses 0, where the first samples sit.
ros::Time record_time(std::int64_t t_ns) { return std::max(stamp(t_ns), ros::TIME_MIN); }

std_msgs::Header header(std::int64_t t_ns, const std::string& frame) {
  std_msgs::Header h;
  h.stamp = stamp(t_ns);
  h.frame_id = frame;
  return h;
}

geometry_msgs::Quaternion quaternion(const Eigen::Quaterniond& q) {
  geometry_msgs::Quaternion m;
  m.x = q.x();
  m.y = q.y();
  m.z = q.z();
  m.w = q.w();
  return m;
}

Eigen::Quaterniond body_rotation(const PoseSample& s) {  // R_WB
  return Eigen::Quaterniond(s.q_xyzw.w(), s.q_xyzw.x(), s.q_xyzw.y(), s.q_xyzw.z()).normalized();
}

template <class Msg>
void set_xyz(Msg& m, const Eigen::Vector3d& v) {
  m.x = v.x();
  m.y = v.y();
  m.z = v.z();
}

sensor_msgs::CameraInfo camera_info(const CameraInfo& cam, std::int64_t t_ns, const std::string& frame) {
  const geometry::PinholeCamera& c = cam.camera;
  sensor_msgs::CameraInfo m;
  m.header = header(t_ns, frame);
  m.width = static_cast<std::uint32_t>(c.width());
  m.height = static_cast<std::uint32_t>(c.height());
  m.distortion_model = sensor_msgs::distortion_models::PLUMB_BOB;
  const geometry::Distortion& d = c.distortion();
  m.D = {d.k1, d.k2, d.p1, d.p2, d.k3};
  m.K = {c.fx(), 0, c.cx(), 0, c.fy(), c.cy(), 0, 0, 1};
  m.R = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  // A monocular camera: the rectified image keeps the same intrinsics.
  m.P = {c.fx(), 0, c.cx(), 0, 0, c.fy(), c.cy(), 0, 0, 0, 1, 0};
  return m;
}

sensor_msgs::Image image_message(const cv::Mat& img, const std::string& encoding, std::int64_t t_ns,
                                 const std::string& frame) {
  sensor_msgs::Image m;
  m.header = header(t_ns, frame);
  m.height = static_cast<std::uint32_t>(img.rows);
  m.width = static_cast<std::uint32_t>(img.cols);
  m.encoding = encoding;
  m.is_bigendian = 0;
  m.step = static_cast<std::uint32_t>(img.cols * img.elemSize());
  m.data.resize(static_cast<std::size_t>(m.step) * img.rows);
  for (int r = 0; r < img.rows; ++r) std::memcpy(&m.data[static_cast<std::size_t>(r) * m.step], img.ptr(r), m.step);
  return m;
}

// Depth as REP 118's 16UC1: millimetres, 0 = no reading, which depth_image_proc reads as it reads
// an OpenNI camera's. The dataset's depth is whole millimetres up to 65.535 m with 0 for none
// (Dataset::load_depth), so the conversion rounds back exactly and 0 stays 0.
cv::Mat depth_millimetres(const cv::Mat& metres) {
  cv::Mat mm;
  metres.convertTo(mm, CV_16UC1, 1000.0);
  return mm;
}

// Diagonal 3x3 covariance of a white noise sampled at `rate` from its continuous density.
boost::array<double, 9> sampled_covariance(double density, double rate) {
  const double var = density * density * rate;
  return {var, 0, 0, 0, var, 0, 0, 0, var};
}

class Writer {
 public:
  Writer(const Dataset& ds, const std::filesystem::path& path, const BagExportOptions& options)
      : ds_(ds), path_(path), options_(options) {}

  BagExportSummary run();

 private:
  std::vector<Event> events() const;
  void write_static_mounts(std::int64_t t_ns);
  void write(const Event& e);
  void write_pose(const AgentData& a, const PoseSample& s);
  void write_frame(const AgentData& a, std::int64_t t_ns);
  void write_imu(const AgentData& a, const ImuSample& s);
  void write_scalar(const AgentData& a, const std::string& topic, const ScalarSample& s);
  void write_ahrs(const AgentData& a, const ScalarSample& s);

  template <class Msg>
  void put(const std::string& topic, std::int64_t t_ns, const Msg& msg,
           const boost::shared_ptr<ros::M_string>& connection = {}) {
    bag_.write(topic, record_time(t_ns), msg, connection);
    ++summary_.messages[topic];
  }

  const Dataset& ds_;
  std::filesystem::path path_;
  const BagExportOptions& options_;
  rosbag::Bag bag_;
  BagExportSummary summary_;
};

std::vector<Event> Writer::events() const {
  std::vector<Event> ev;
  auto add = [&ev](Stream s, std::size_t agent, const auto& samples, auto t_of) {
    for (std::size_t i = 0; i < samples.size(); ++i) ev.push_back({t_of(samples[i]), s, agent, i});
  };
  const auto t = [](const auto& s) { return s.t_ns; };
  for (std::size_t k = 0; k < ds_.agents.size(); ++k) {
    const AgentData& a = ds_.agents[k];
    add(Stream::Tf, k, a.groundtruth, t);
    add(Stream::Odometry, k, a.groundtruth, t);
    if (a.camera) add(Stream::Frame, k, a.frames, [](std::int64_t f) { return f; });
    add(Stream::CameraPose, k, a.camera_pose, t);
    add(Stream::Imu, k, a.imu, t);
    add(Stream::Gps, k, a.gps, t);
    add(Stream::Altimeter, k, a.altimeter, t);
    add(Stream::Range, k, a.range, t);
    add(Stream::Ahrs, k, a.ahrs, t);
  }
  std::stable_sort(ev.begin(), ev.end(), [](const Event& x, const Event& y) { return x.t_ns < y.t_ns; });
  return ev;
}

BagExportSummary Writer::run() {
  try {
    bag_.open(path_.string(), rosbag::bagmode::Write);
    switch (options_.compression) {
      case BagCompression::None: bag_.setCompression(rosbag::compression::Uncompressed); break;
      case BagCompression::Lz4: bag_.setCompression(rosbag::compression::LZ4); break;
      case BagCompression::Bz2: bag_.setCompression(rosbag::compression::BZ2); break;
    }
    const std::vector<Event> ev = events();
    write_static_mounts(ev.empty() ? 0 : ev.front().t_ns);
    for (std::size_t i = 0; i < ev.size(); ++i) {
      write(ev[i]);
      if (options_.progress) options_.progress(i + 1, ev.size());
    }
    bag_.close();
  } catch (const rosbag::BagException& e) {
    throw std::runtime_error("cannot write the bag '" + path_.string() + "': " + e.what());
  }
  return summary_;
}

// The nominal mounts, the dataset's T_BS of cam0 (docs/datasets.md, frames): the commanded
// attitude at body yaw 0, R_BC = R_CW^T, and the offset d. The gimbal holds the camera's world
// attitude, so this is the commanded camera pose while the body's yaw is 0 (open-loop UAVs), and
// never includes the gimbal error; the true camera pose is /<uav>/cam0/pose.
void Writer::write_static_mounts(std::int64_t t_ns) {
  tf2_msgs::TFMessage tf;
  for (const AgentData& a : ds_.agents) {
    if (!a.camera) continue;
    geometry_msgs::TransformStamped m;
    m.header = header(t_ns, bag_body_frame(a.name));
    m.child_frame_id = bag_camera_frame(a.name);
    set_xyz(m.transform.translation, a.camera->offset);
    m.transform.rotation = quaternion(Eigen::Quaterniond(a.camera->R_CW.transpose()).normalized());
    tf.transforms.push_back(m);
  }
  if (tf.transforms.empty()) return;
  // Latched, as tf2's static broadcaster publishes it, so that rosbag play latches it too.
  auto connection = boost::make_shared<ros::M_string>();
  (*connection)["type"] = ros::message_traits::datatype(tf);
  (*connection)["md5sum"] = ros::message_traits::md5sum(tf);
  (*connection)["message_definition"] = ros::message_traits::definition(tf);
  (*connection)["callerid"] = "/wingman_export";
  (*connection)["latching"] = "1";
  put("/tf_static", t_ns, tf, connection);
}

void Writer::write(const Event& e) {
  const AgentData& a = ds_.agents[e.agent];
  const std::string ns = "/" + a.name;
  switch (e.stream) {
    case Stream::Tf: {
      const PoseSample& s = a.groundtruth[e.index];
      tf2_msgs::TFMessage tf;
      geometry_msgs::TransformStamped m;
      m.header = header(s.t_ns, kBagWorldFrame);
      m.child_frame_id = bag_body_frame(a.name);
      set_xyz(m.transform.translation, s.p);
      m.transform.rotation = quaternion(body_rotation(s));
      tf.transforms.push_back(m);
      put("/tf", s.t_ns, tf);
      break;
    }
    case Stream::Odometry: write_pose(a, a.groundtruth[e.index]); break;
    case Stream::Frame: write_frame(a, a.frames[e.index]); break;
    case Stream::CameraPose: {
      const PoseSample& s = a.camera_pose[e.index];
      geometry_msgs::PoseStamped m;
      m.header = header(s.t_ns, kBagWorldFrame);
      set_xyz(m.pose.position, s.p);
      m.pose.orientation = quaternion(body_rotation(s).conjugate());  // R_WC = R_CW^T
      put(ns + "/cam0/pose", s.t_ns, m);
      break;
    }
    case Stream::Imu: write_imu(a, a.imu[e.index]); break;
    case Stream::Gps: {
      const Vec3Sample& s = a.gps[e.index];
      geometry_msgs::PointStamped m;
      m.header = header(s.t_ns, kBagWorldFrame);
      set_xyz(m.point, s.value);
      put(ns + "/gps", s.t_ns, m);
      break;
    }
    case Stream::Altimeter: write_scalar(a, ns + "/altimeter", a.altimeter[e.index]); break;
    case Stream::Range: write_scalar(a, ns + "/range", a.range[e.index]); break;
    case Stream::Ahrs: write_ahrs(a, a.ahrs[e.index]); break;
  }
}

// Ground truth as odometry: the twist, as ROS has it, in the child (body) frame; the dataset
// records no angular rate, so twist.angular is zero with -1 on its covariance diagonal.
void Writer::write_pose(const AgentData& a, const PoseSample& s) {
  nav_msgs::Odometry m;
  m.header = header(s.t_ns, kBagWorldFrame);
  m.child_frame_id = bag_body_frame(a.name);
  const Eigen::Quaterniond q = body_rotation(s);
  set_xyz(m.pose.pose.position, s.p);
  m.pose.pose.orientation = quaternion(q);
  set_xyz(m.twist.twist.linear, q.conjugate() * s.v);
  for (int i = 3; i < 6; ++i) m.twist.covariance[i * 6 + i] = -1;
  put("/" + a.name + "/groundtruth/odometry", s.t_ns, m);
}

void Writer::write_frame(const AgentData& a, std::int64_t t_ns) {
  const std::string ns = "/" + a.name;
  const std::string frame = bag_camera_frame(a.name);
  const cv::Mat img = ds_.load_image(a.name, t_ns);
  const std::string encoding = img.channels() == 1 ? sensor_msgs::image_encodings::MONO8
                                                   : sensor_msgs::image_encodings::RGB8;
  put(ns + "/cam0/image_raw", t_ns, image_message(img, encoding, t_ns, frame));
  put(ns + "/cam0/camera_info", t_ns, camera_info(*a.camera, t_ns, frame));
  const cv::Mat depth = ds_.load_depth(a.name, t_ns);
  put(ns + "/depth0/image_raw", t_ns,
      image_message(depth_millimetres(depth), sensor_msgs::image_encodings::TYPE_16UC1, t_ns, frame));
  put(ns + "/depth0/camera_info", t_ns, camera_info(*a.camera, t_ns, frame));
}

void Writer::write_imu(const AgentData& a, const ImuSample& s) {
  sensor_msgs::Imu m;
  m.header = header(s.t_ns, bag_body_frame(a.name));
  m.orientation_covariance[0] = -1;  // no orientation estimate
  set_xyz(m.angular_velocity, s.w_S);
  set_xyz(m.linear_acceleration, s.a_S);
  if (a.imu_info) {
    m.angular_velocity_covariance = sampled_covariance(a.imu_info->gyroscope_noise_density, a.imu_info->rate);
    m.linear_acceleration_covariance =
        sampled_covariance(a.imu_info->accelerometer_noise_density, a.imu_info->rate);
  }
  put("/" + a.name + "/imu0", s.t_ns, m);
}

// The altimeter (height above z = 0) and the range to the lead are scalars with a stamp; Range is
// ROS 1's message for one.
void Writer::write_scalar(const AgentData& a, const std::string& topic, const ScalarSample& s) {
  sensor_msgs::Range m;
  m.header = header(s.t_ns, bag_body_frame(a.name));
  m.radiation_type = sensor_msgs::Range::INFRARED;
  m.field_of_view = 0;
  m.min_range = 0;
  m.max_range = std::numeric_limits<float>::infinity();
  m.range = static_cast<float>(s.value);
  put(topic, s.t_ns, m);
}

// The AHRS's yaw as an orientation-only IMU message (rotation about world z).
void Writer::write_ahrs(const AgentData& a, const ScalarSample& s) {
  sensor_msgs::Imu m;
  m.header = header(s.t_ns, bag_body_frame(a.name));
  m.orientation = quaternion(Eigen::Quaterniond(Eigen::AngleAxisd(s.value, Eigen::Vector3d::UnitZ())));
  m.angular_velocity_covariance[0] = -1;
  m.linear_acceleration_covariance[0] = -1;
  put("/" + a.name + "/ahrs", s.t_ns, m);
}

}  // namespace

BagExportSummary write_bag(const Dataset& ds, const std::filesystem::path& path, const BagExportOptions& options) {
  Writer w(ds, path, options);
  return w.run();
}

}  // namespace wingman::datasets
