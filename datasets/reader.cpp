#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <Eigen/LU>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <sstream>

#include "datasets/dataset.hpp"

namespace fs = std::filesystem;

namespace wingman::datasets {

namespace {

[[noreturn]] void fail(const fs::path& file, const std::string& what) {
  throw DatasetError(fmt::format("{}: {}", file.string(), what));
}

// Files are size-checked before they are read: a YAML file is a few hundred bytes, a CSV at most
// one row per step of the longest run a scenario may describe.
constexpr std::uintmax_t kMaxYamlBytes = 1u << 20, kMaxCsvBytes = std::uintmax_t{2} << 30;
// Positions, sensor values: anything farther than this from the origin is corrupt.
constexpr double kMaxMagnitude = 1e7;

void check_size(const fs::path& p, std::uintmax_t limit) {
  std::error_code ec;
  const auto size = fs::file_size(p, ec);
  if (!ec && size > limit) fail(p, fmt::format("{} bytes; at most {} for this file", size, limit));
}

YAML::Node load_yaml(const fs::path& p) {
  std::error_code ec;
  if (!fs::is_regular_file(p, ec)) fail(p, "missing");
  check_size(p, kMaxYamlBytes);
  try {
    return YAML::LoadFile(p.string());
  } catch (const YAML::Exception& e) {
    fail(p, fmt::format("not valid YAML: {}", e.what()));
  }
}

template <typename T>
T get(const YAML::Node& n, const fs::path& file, const char* key) {
  const YAML::Node v = n[key];
  if (!v) fail(file, fmt::format("missing key '{}'", key));
  try {
    return v.as<T>();
  } catch (const YAML::Exception&) {
    fail(file, fmt::format("key '{}' has the wrong type", key));
  }
}

std::vector<double> numbers(const YAML::Node& n, const fs::path& file, const char* key, std::size_t size) {
  const auto v = get<std::vector<double>>(n, file, key);
  if (v.size() != size) fail(file, fmt::format("key '{}' must have {} numbers, has {}", key, size, v.size()));
  return v;
}

// CSV rows below the '#' header: each row's comma-separated fields, checked for their count.
std::vector<std::vector<std::string>> read_csv(const fs::path& p, std::size_t columns) {
  std::ifstream in(p);
  if (!in) fail(p, "missing");
  check_size(p, kMaxCsvBytes);
  std::vector<std::vector<std::string>> rows;
  std::string line;
  int n = 0;
  while (std::getline(in, line)) {
    ++n;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty() || line[0] == '#') continue;
    std::vector<std::string> f;
    std::stringstream ss(line);
    std::string x;
    while (std::getline(ss, x, ',')) f.push_back(x);
    if (f.size() != columns) fail(p, fmt::format("line {}: expected {} columns, got {}", n, columns, f.size()));
    rows.push_back(std::move(f));
  }
  return rows;
}

// A finite number of magnitude at most kMaxMagnitude: NaN, inf or 1e308 in a sensor row is a
// corrupt file, never a sample to drop silently.
double num(const std::string& s, const fs::path& p, std::size_t row) {
  double v = 0;
  try {
    std::size_t used = 0;
    v = std::stod(s, &used);
    if (used != s.size()) fail(p, fmt::format("data row {}: '{}' is not a number", row + 1, s));
  } catch (const std::exception&) {
    fail(p, fmt::format("data row {}: '{}' is not a number", row + 1, s));
  }
  if (!std::isfinite(v) || std::abs(v) > kMaxMagnitude)
    fail(p, fmt::format("data row {}: {} is not a finite value of magnitude at most {:g}", row + 1, s,
                        kMaxMagnitude));
  return v;
}

// Time stamps increase down every CSV.
void check_increasing(std::int64_t t, std::int64_t previous, bool first, const fs::path& p, std::size_t row) {
  if (!first && t <= previous) fail(p, fmt::format("data row {}: time stamps must increase", row + 1));
}

std::int64_t stamp(const std::string& s, const fs::path& p, std::size_t row) {
  try {
    std::size_t used = 0;
    const long long v = std::stoll(s, &used);
    if (used == s.size()) return v;
  } catch (const std::exception&) {
  }
  fail(p, fmt::format("data row {}: '{}' is not a time stamp in ns", row + 1, s));
}

// Width, height, bit depth and channels from a PNG's IHDR chunk.
struct PngHeader {
  int width = 0, height = 0, bit_depth = 0, channels = 0;
};

PngHeader png_header(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  if (!in) fail(p, "missing frame");
  unsigned char b[26];
  in.read(reinterpret_cast<char*>(b), sizeof b);
  static const unsigned char sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (!in || std::memcmp(b, sig, 8) != 0 || std::memcmp(b + 12, "IHDR", 4) != 0) fail(p, "not a PNG file");
  auto be32 = [&](int o) { return (b[o] << 24) | (b[o + 1] << 16) | (b[o + 2] << 8) | b[o + 3]; };
  PngHeader h;
  h.width = be32(16);
  h.height = be32(20);
  h.bit_depth = b[24];
  switch (b[25]) {
    case 0: h.channels = 1; break;
    case 2: h.channels = 3; break;
    case 4: h.channels = 2; break;
    case 6: h.channels = 4; break;
    default: h.channels = 0;
  }
  return h;
}

// T_BS of a version-2 sensor.yaml: EuRoC's {cols: 4, rows: 4, data: [16 numbers]}, a rigid
// transform (a rotation and a last row 0 0 0 1).
void read_T_BS(const YAML::Node& n, const fs::path& file, Eigen::Matrix3d& R_BS, Eigen::Vector3d& p_BS) {
  const YAML::Node t = n["T_BS"];
  if (!t || !t.IsMap()) fail(file, "missing key 'T_BS' (a map with cols, rows and data)");
  if (get<int>(t, file, "cols") != 4 || get<int>(t, file, "rows") != 4) fail(file, "T_BS: cols and rows must be 4");
  const auto d = numbers(t, file, "data", 16);
  for (double x : d)
    if (!std::isfinite(x) || std::abs(x) > kMaxMagnitude) fail(file, fmt::format("T_BS.data: {} is not finite", x));
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) R_BS(i, j) = d[4 * i + j];
    p_BS(i) = d[4 * i + 3];
  }
  if (d[12] != 0 || d[13] != 0 || d[14] != 0 || d[15] != 1) fail(file, "T_BS.data: the last row must be 0 0 0 1");
}

void check_rotation(const Eigen::Matrix3d& R, const fs::path& file, const char* key) {
  const double orth = (R * R.transpose() - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (!(orth < 1e-6) || !(std::abs(R.determinant() - 1) < 1e-6))
    fail(file, fmt::format("{} is not a rotation matrix (R R^T = I and det R = 1, to 1e-6)", key));
}

// The lens: version 1 always five coefficients; version 2 four for radial-tangential (EuRoC) and
// five for plumb_bob (k1, k2, p1, p2, k3).
geometry::Distortion read_distortion(const YAML::Node& n, const fs::path& file, int version) {
  std::size_t count = 5;
  if (version >= 2) {
    const auto model = get<std::string>(n, file, "distortion_model");
    if (model == "radial-tangential") count = 4;
    else if (model != "plumb_bob")
      fail(file, fmt::format("distortion_model '{}': this reader knows radial-tangential and plumb_bob", model));
  }
  auto d = numbers(n, file, "distortion_coefficients", count);
  for (double x : d)
    if (!std::isfinite(x) || std::abs(x) > kMaxMagnitude)
      fail(file, fmt::format("distortion_coefficients: {} is not finite", x));
  d.resize(5, 0.0);
  return {d[0], d[1], d[2], d[3], d[4]};
}

// The mount: version 1 keeps R_CW and the offset; version 2 EuRoC's T_BS, the camera's pose in
// the body, at body yaw 0 (the open-loop UAVs' yaw), so R_CW = R_BS^T.
void read_mount(const YAML::Node& n, const fs::path& file, int version, CameraInfo& c) {
  if (version >= 2) {
    Eigen::Matrix3d R_BS;
    read_T_BS(n, file, R_BS, c.offset);
    check_rotation(R_BS, file, "T_BS's rotation");
    c.R_CW = R_BS.transpose();
    return;
  }
  const auto r = numbers(n, file, "R_CW", 9);
  const auto o = numbers(n, file, "offset", 3);
  for (double x : o)
    if (!std::isfinite(x) || std::abs(x) > kMaxMagnitude) fail(file, fmt::format("offset: {} is not finite", x));
  for (int i = 0; i < 9; ++i) c.R_CW(i / 3, i % 3) = r[i];
  check_rotation(c.R_CW, file, "R_CW");
  c.offset = {o[0], o[1], o[2]};
}

int read_channels(const YAML::Node& n, const fs::path& file, int version) {
  if (version < 2) {
    const int channels = n["channels"] ? get<int>(n, file, "channels") : 3;
    if (channels != 1 && channels != 3) fail(file, fmt::format("channels must be 1 or 3, got {}", channels));
    return channels;
  }
  const auto enc = get<std::string>(n, file, "encoding");
  if (enc == "mono8" || enc == "mono16") return 1;
  if (enc == "rgb8") return 3;
  fail(file, fmt::format("encoding '{}': expected mono8 or rgb8 (mono16 for depth)", enc));
}

// cam0's shutter (docs/datasets.md, shutter and exposure); a dataset without one was taken through
// a global shutter with no exposure time.
void read_shutter(const YAML::Node& n, const fs::path& file, CameraInfo& c) {
  const YAML::Node s = n["shutter"];
  if (!s) return;
  if (!s.IsMap()) fail(file, "shutter must be a map");
  const auto type = get<std::string>(s, file, "type");
  const auto readout = get<std::string>(s, file, "readout");
  if (type != "global" && type != "rolling") fail(file, fmt::format("shutter.type '{}': expected global or rolling", type));
  if (readout != "top_to_bottom" && readout != "bottom_to_top")
    fail(file, fmt::format("shutter.readout '{}': expected top_to_bottom or bottom_to_top", readout));
  c.exposure_s = get<double>(s, file, "exposure_s");
  c.line_delay_s = get<double>(s, file, "line_delay_s");
  if (!(c.exposure_s >= 0 && c.exposure_s <= 1)) fail(file, fmt::format("shutter.exposure_s {} must be in [0, 1]", c.exposure_s));
  if (!(c.line_delay_s >= 0 && c.line_delay_s <= 1e-3))
    fail(file, fmt::format("shutter.line_delay_s {} must be in [0, 0.001]", c.line_delay_s));
  c.rolling = type == "rolling";
  if (c.rolling && c.line_delay_s == 0) fail(file, "shutter.line_delay_s must be above 0 for a rolling shutter");
  c.top_to_bottom = readout == "top_to_bottom";
}

CameraInfo read_camera(const fs::path& file, double rate_fallback, int version) {
  const YAML::Node n = load_yaml(file);
  const auto res = numbers(n, file, "resolution", 2);
  const auto k = numbers(n, file, "intrinsics", 4);
  if (!(res[0] >= 1 && res[0] <= 16384 && res[1] >= 1 && res[1] <= 16384) || res[0] != std::floor(res[0]) ||
      res[1] != std::floor(res[1]))
    fail(file, fmt::format("resolution [{}, {}] must be whole numbers of pixels from 1 to 16384", res[0], res[1]));
  if (!(k[0] > 0 && k[1] > 0 && std::isfinite(k[0]) && std::isfinite(k[1]) && std::isfinite(k[2]) &&
        std::isfinite(k[3])))
    fail(file, fmt::format("intrinsics [{}, {}, {}, {}]: fx and fy must be positive, all finite", k[0], k[1],
                           k[2], k[3]));
  if (version >= 2 && get<std::string>(n, file, "camera_model") != "pinhole")
    fail(file, "camera_model: this reader knows pinhole");
  CameraInfo c;
  c.camera = geometry::PinholeCamera(k[0], k[1], k[2], k[3], static_cast<int>(res[0]), static_cast<int>(res[1]),
                                     read_distortion(n, file, version));
  read_mount(n, file, version, c);
  c.rate = n["rate_hz"] ? get<double>(n, file, "rate_hz") : rate_fallback;
  if (!(c.rate > 0 && c.rate <= 1000)) fail(file, fmt::format("rate_hz must be in (0, 1000], got {}", c.rate));
  c.channels = read_channels(n, file, version);
  read_shutter(n, file, c);
  return c;
}

std::vector<std::int64_t> read_frames(const fs::path& folder, const CameraInfo& cam, bool depth) {
  const fs::path csv = folder / "data.csv";
  std::vector<std::int64_t> out;
  const auto rows = read_csv(csv, 2);
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const std::int64_t t = stamp(rows[i][0], csv, i);
    if (!out.empty() && t <= out.back()) fail(csv, fmt::format("data row {}: time stamps must increase", i + 1));
    const fs::path img = folder / "data" / rows[i][1];
    std::error_code ec;
    if (!fs::is_regular_file(img, ec)) fail(img, fmt::format("missing frame (listed in {})", csv.string()));
    const PngHeader h = png_header(img);
    if (h.width != cam.camera.width() || h.height != cam.camera.height())
      fail(img, fmt::format("image is {}x{}, sensor.yaml says {}x{}", h.width, h.height,
                            cam.camera.width(), cam.camera.height()));
    if (depth && (h.bit_depth != 16 || h.channels != 1))
      fail(img, "depth frames must be 16-bit single-channel PNG");
    if (!depth && (h.bit_depth != 8 || h.channels != cam.channels))
      fail(img, fmt::format("expected an 8-bit image with {} channel(s), got {}-bit with {}",
                            cam.channels, h.bit_depth, h.channels));
    out.push_back(t);
  }
  return out;
}

// A ground-truth file: a body's (version 1: 11 columns; version 2: EuRoC's 17, with the IMU's
// biases) or a camera's (8 columns: version 1 q_CW, version 2 q_WC; held in memory as R_CW).
enum class PoseFile { Body, Camera };

std::vector<PoseSample> read_poses(const fs::path& csv, PoseFile kind, int version) {
  const bool body = kind == PoseFile::Body;
  std::vector<PoseSample> out;
  const auto rows = read_csv(csv, body ? (version >= 2 ? 17 : 11) : 8);
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const auto& r = rows[i];
    const auto vec = [&](int c) { return Eigen::Vector3d(num(r[c], csv, i), num(r[c + 1], csv, i), num(r[c + 2], csv, i)); };
    PoseSample s;
    s.t_ns = stamp(r[0], csv, i);
    check_increasing(s.t_ns, out.empty() ? 0 : out.back().t_ns, out.empty(), csv, i);
    s.p = vec(1);
    s.q_xyzw = {num(r[5], csv, i), num(r[6], csv, i), num(r[7], csv, i), num(r[4], csv, i)};
    if (std::abs(s.q_xyzw.norm() - 1) > 1e-3)
      fail(csv, fmt::format("data row {}: the quaternion has norm {}, not 1", i + 1, s.q_xyzw.norm()));
    if (!body && version >= 2) s.q_xyzw.head<3>() = -s.q_xyzw.head<3>();  // q_WC to q_CW
    if (body) s.v = vec(8);
    if (body && version >= 2) {
      s.b_w = vec(11);
      s.b_a = vec(14);
    }
    out.push_back(s);
  }
  return out;
}

ImuInfo read_imu_info(const fs::path& file) {
  const YAML::Node n = load_yaml(file);
  ImuInfo info;
  info.rate = get<double>(n, file, "rate_hz");
  if (!(info.rate > 0 && info.rate <= 100000)) fail(file, fmt::format("rate_hz must be in (0, 100000], got {}", info.rate));
  const std::pair<const char*, double*> keys[] = {
      {"gyroscope_noise_density", &info.gyroscope_noise_density},
      {"gyroscope_random_walk", &info.gyroscope_random_walk},
      {"accelerometer_noise_density", &info.accelerometer_noise_density},
      {"accelerometer_random_walk", &info.accelerometer_random_walk}};
  for (const auto& [key, value] : keys) {
    *value = get<double>(n, file, key);
    if (!(*value >= 0 && std::isfinite(*value))) fail(file, fmt::format("{} must be >= 0, got {}", key, *value));
  }
  return info;
}

std::vector<ImuSample> read_imu(const fs::path& csv) {
  std::vector<ImuSample> out;
  const auto rows = read_csv(csv, 7);
  out.reserve(rows.size());
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const auto& r = rows[i];
    ImuSample s;
    s.t_ns = stamp(r[0], csv, i);
    check_increasing(s.t_ns, out.empty() ? 0 : out.back().t_ns, out.empty(), csv, i);
    s.w_S = {num(r[1], csv, i), num(r[2], csv, i), num(r[3], csv, i)};
    s.a_S = {num(r[4], csv, i), num(r[5], csv, i), num(r[6], csv, i)};
    out.push_back(s);
  }
  return out;
}

std::vector<ScalarSample> read_scalars(const fs::path& csv) {
  std::vector<ScalarSample> out;
  const auto rows = read_csv(csv, 2);
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const std::int64_t t = stamp(rows[i][0], csv, i);
    check_increasing(t, out.empty() ? 0 : out.back().t_ns, out.empty(), csv, i);
    out.push_back({t, num(rows[i][1], csv, i)});
  }
  return out;
}

// cam0_lead0/data.csv: one row per frame, at the frames' stamps; u, v may be nan (behind).
std::vector<LeadLabel> read_lead_labels(const fs::path& csv, const std::vector<std::int64_t>& frames) {
  std::vector<LeadLabel> out;
  const auto rows = read_csv(csv, 9);
  if (rows.size() != frames.size()) fail(csv, fmt::format("has {} rows for {} frames", rows.size(), frames.size()));
  auto pixel = [&](const std::string& x, std::size_t i) {
    return x == "nan" ? std::numeric_limits<double>::quiet_NaN() : num(x, csv, i);
  };
  auto column = [&](const std::string& x, std::size_t i) {
    const double v = num(x, csv, i);
    if (v != std::floor(v)) fail(csv, fmt::format("data row {}: box bound {} is not a whole pixel", i + 1, x));
    return static_cast<int>(v);
  };
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const auto& r = rows[i];
    LeadLabel label;
    label.t_ns = stamp(r[0], csv, i);
    geometry::LeadImage& l = label.lead;
    if (label.t_ns != frames[i]) fail(csv, fmt::format("data row {}: time stamp {} is not frame {}'s", i + 1, r[0], i + 1));
    l.uv = {pixel(r[1], i), pixel(r[2], i)};
    l.distance = num(r[3], csv, i);
    l.visible = num(r[4], csv, i);
    if (l.distance < 0 || l.visible < 0 || l.visible > 1)
      fail(csv, fmt::format("data row {}: distance must be >= 0 and visible in [0, 1]", i + 1));
    l.box_u0 = column(r[5], i), l.box_v0 = column(r[6], i), l.box_u1 = column(r[7], i), l.box_v1 = column(r[8], i);
    if (l.box_u1 < l.box_u0 || l.box_v1 < l.box_v0)
      fail(csv, fmt::format("data row {}: the box's far bounds lie before its near ones", i + 1));
    out.push_back(label);
  }
  return out;
}

// Agent names are folder names: plain, so that none reaches outside the dataset, and unique.
void check_agent_names(const std::vector<std::string>& names, const fs::path& yf) {
  if (names.empty()) fail(yf, "agents: the list is empty");
  for (std::size_t i = 0; i < names.size(); ++i) {
    const std::string& n = names[i];
    const bool plain = !n.empty() && n.size() <= 64 && std::all_of(n.begin(), n.end(), [](char c) {
      return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_';
    });
    if (!plain) fail(yf, fmt::format("agents[{}]: '{}' is not an agent name ([a-z0-9_]+, at most 64)", i, n));
    if (std::find(names.begin(), names.begin() + static_cast<long>(i), n) != names.begin() + static_cast<long>(i))
      fail(yf, fmt::format("agents[{}]: '{}' is listed twice", i, n));
  }
}

}  // namespace

const AgentData& Dataset::agent(const std::string& name) const {
  for (const auto& a : agents)
    if (a.name == name) return a;
  throw DatasetError(fmt::format("{}: no agent '{}'", (root / "dataset.yaml").string(), name));
}

fs::path Dataset::image_path(const std::string& a, std::int64_t t) const {
  return layout.sensor(root, a, "cam0") / "data" / fmt::format("{}.png", t);
}
fs::path Dataset::depth_path(const std::string& a, std::int64_t t) const {
  return layout.sensor(root, a, "depth0") / "data" / fmt::format("{}.png", t);
}

cv::Mat Dataset::load_image(const std::string& a, std::int64_t t) const {
  const fs::path p = image_path(a, t);
  cv::Mat img = cv::imread(p.string(), cv::IMREAD_UNCHANGED);
  if (img.empty()) fail(p, "cannot read image");
  if (img.channels() == 3) cv::cvtColor(img, img, cv::COLOR_BGR2RGB);
  return img;
}

cv::Mat Dataset::load_depth(const std::string& a, std::int64_t t) const {
  const fs::path p = depth_path(a, t);
  cv::Mat mm = cv::imread(p.string(), cv::IMREAD_UNCHANGED);
  if (mm.empty() || mm.type() != CV_16UC1) fail(p, "cannot read a 16-bit depth image");
  cv::Mat m;
  mm.convertTo(m, CV_32F, kDepthScale);
  return m;
}

namespace {

DatasetInfo read_info(const fs::path& dir) {
  const fs::path yf = dir / "dataset.yaml";
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) fail(dir, "not a directory");
  if (!fs::is_regular_file(yf, ec)) fail(yf, "missing: not a wingman dataset, or an unfinished one");
  const YAML::Node y = load_yaml(yf);
  if (!y.IsMap()) fail(yf, "expected a map");
  if (get<std::string>(y, yf, "format") != "wingman-dataset") fail(yf, "format is not 'wingman-dataset'");
  DatasetInfo info;
  info.format_version = get<int>(y, yf, "format_version");
  if (info.format_version != kFormatVersion && info.format_version != 1)
    fail(yf, fmt::format("unknown format_version {} (this wingman reads versions 1 and {})", info.format_version,
                         kFormatVersion));
  info.scenario = get<std::string>(y, yf, "scenario");
  info.variant = y["variant"] && !y["variant"].IsNull() ? get<std::string>(y, yf, "variant") : "";
  info.seed = get<std::uint64_t>(y, yf, "seed");
  info.software_version = get<std::string>(y, yf, "software_version");
  info.rate = get<double>(y, yf, "rate_hz");
  if (!(info.rate > 0 && info.rate <= 1000)) fail(yf, fmt::format("rate_hz must be in (0, 1000], got {}", info.rate));
  info.frames = get<int>(y, yf, "frames");
  if (info.frames < 0) fail(yf, fmt::format("frames must be >= 0, got {}", info.frames));
  info.renderer = y["renderer"] ? get<std::string>(y, yf, "renderer") : "";
  info.agents = get<std::vector<std::string>>(y, yf, "agents");
  check_agent_names(info.agents, yf);
  return info;
}

// A sensor folder an agent of this kind must have.
fs::path required(const fs::path& folder, const std::string& why) {
  std::error_code ec;
  if (!fs::is_directory(folder, ec)) fail(folder, fmt::format("missing sensor folder ({})", why));
  return folder;
}

void read_camera_sensors(const Dataset& ds, AgentData& a) {
  const Layout& l = ds.layout;
  const int v = l.version;
  const fs::path cam0 = l.sensor(ds.root, a.name, "cam0");
  const fs::path depth0 = required(l.sensor(ds.root, a.name, "depth0"), "a camera's depth0 goes with its cam0");
  a.camera = read_camera(cam0 / "sensor.yaml", ds.info.rate, v);
  // The depth frames are the colour frames' pixels: the same camera.
  const CameraInfo depth_cam = read_camera(depth0 / "sensor.yaml", ds.info.rate, v);
  const auto& c = a.camera->camera;
  const auto& d = depth_cam.camera;
  if (d.width() != c.width() || d.height() != c.height() || d.fx() != c.fx() || d.fy() != c.fy() ||
      d.cx() != c.cx() || d.cy() != c.cy())
    fail(depth0 / "sensor.yaml", "its resolution or intrinsics differ from cam0/sensor.yaml");
  a.frames = read_frames(cam0, *a.camera, false);
  if (read_frames(depth0, *a.camera, true) != a.frames)
    fail(depth0 / "data.csv", "its time stamps differ from cam0/data.csv");
  if (static_cast<int>(a.frames.size()) != ds.info.frames)
    fail(cam0 / "data.csv", fmt::format("lists {} frames, dataset.yaml says {}", a.frames.size(), ds.info.frames));
  const fs::path poses = l.camera_pose_csv(ds.root, a.name);
  if (v >= 2) required(poses.parent_path(), "the true camera poses of cam0's frames");
  a.camera_pose = read_poses(poses, PoseFile::Camera, v);
  if (a.camera_pose.size() != a.frames.size())
    fail(poses, fmt::format("has {} poses for {} frames", a.camera_pose.size(), a.frames.size()));
  std::error_code ec;
  if (const fs::path labels = l.sensor(ds.root, a.name, "cam0_lead0"); fs::exists(labels, ec))
    a.lead_labels = read_lead_labels(labels / "data.csv", a.frames);
  if (v >= 2) {
    const fs::path imu0 = required(l.sensor(ds.root, a.name, "imu0"), "every UAV carries an IMU");
    a.imu_info = read_imu_info(imu0 / "sensor.yaml");
    a.imu = read_imu(imu0 / "data.csv");
  }
}

AgentData read_agent(const Dataset& ds, const std::string& name) {
  AgentData a;
  a.name = name;
  const Layout& l = ds.layout;
  std::error_code ec;
  if (!fs::is_directory(l.agent(ds.root, name), ec))
    fail(l.agent(ds.root, name), "missing agent folder (listed in dataset.yaml)");
  const fs::path gt = l.groundtruth_csv(ds.root, name);
  required(gt.parent_path(), "every agent has its ground truth");
  a.groundtruth = read_poses(gt, PoseFile::Body, l.version);
  if (fs::exists(l.sensor(ds.root, name, "cam0"), ec)) read_camera_sensors(ds, a);
  if (fs::exists(l.sensor(ds.root, name, "gps0"), ec)) {
    const fs::path csv = l.sensor(ds.root, name, "gps0") / "data.csv";
    const auto rows = read_csv(csv, 4);
    for (std::size_t i = 0; i < rows.size(); ++i) {
      const std::int64_t t = stamp(rows[i][0], csv, i);
      check_increasing(t, a.gps.empty() ? 0 : a.gps.back().t_ns, a.gps.empty(), csv, i);
      a.gps.push_back({t, {num(rows[i][1], csv, i), num(rows[i][2], csv, i), num(rows[i][3], csv, i)}});
    }
  }
  for (auto [folder, samples] : {std::pair{"altimeter0", &a.altimeter}, std::pair{"range0", &a.range},
                                 std::pair{"ahrs0", &a.ahrs}})
    if (fs::exists(l.sensor(ds.root, name, folder), ec))
      *samples = read_scalars(l.sensor(ds.root, name, folder) / "data.csv");
  return a;
}

}  // namespace

Dataset read_dataset(const fs::path& dir) {
  Dataset ds;
  ds.root = dir;
  ds.info = read_info(dir);
  ds.layout.version = ds.info.format_version;
  for (const auto& name : ds.info.agents) ds.agents.push_back(read_agent(ds, name));
  return ds;
}

}  // namespace wingman::datasets

namespace wingman::datasets {
namespace {

std::map<std::string, FrameChecksum> read_checksums(const fs::path& csv) {
  std::map<std::string, FrameChecksum> out;
  const auto rows = read_csv(csv, 3);
  for (std::size_t i = 0; i < rows.size(); ++i) {
    FrameChecksum c;
    try {
      std::size_t used = 0;
      c.bytes = std::stoull(rows[i][1], &used);
      if (used != rows[i][1].size()) throw std::invalid_argument("bytes");
      c.crc32 = static_cast<std::uint32_t>(std::stoul(rows[i][2], &used, 16));
      if (used != rows[i][2].size() || rows[i][2].size() > 8) throw std::invalid_argument("crc32");
    } catch (const std::exception&) {
      fail(csv, fmt::format("data row {}: expected file,bytes,crc32 (hex)", i + 1));
    }
    out[rows[i][0]] = c;
  }
  return out;
}

void verify_checksum(const fs::path& file, const FrameChecksum& want, std::vector<unsigned char>& buf) {
  std::error_code ec;
  const auto size = fs::file_size(file, ec);
  if (ec) fail(file, "missing frame");
  if (size != want.bytes)
    fail(file, fmt::format("{} bytes, checksums.csv says {}: the frame is damaged or was replaced", size, want.bytes));
  buf.resize(static_cast<std::size_t>(size));
  std::ifstream in(file, std::ios::binary);
  in.read(reinterpret_cast<char*>(buf.data()), static_cast<std::streamsize>(buf.size()));
  if (!in) fail(file, "cannot read the frame");
  const std::uint32_t crc = crc32_of(buf.data(), buf.size());
  if (crc != want.crc32)
    fail(file, fmt::format("CRC-32 {:08x}, checksums.csv says {:08x}: the frame is damaged", crc, want.crc32));
}

}  // namespace

void verify_frames(const Dataset& ds, const std::function<void(int, int)>& progress) {
  const fs::path csv = ds.root / kChecksumsFile;
  std::error_code ec;
  const bool sums = fs::is_regular_file(csv, ec);
  const auto checksums = sums ? read_checksums(csv) : std::map<std::string, FrameChecksum>{};
  int total = 0, done = 0;
  for (const auto& a : ds.agents) total += 2 * static_cast<int>(a.frames.size());
  std::vector<unsigned char> buf;
  for (const auto& a : ds.agents) {
    for (const std::int64_t t : a.frames) {
      for (const bool depth : {false, true}) {
        const fs::path file = depth ? ds.depth_path(a.name, t) : ds.image_path(a.name, t);
        if (sums) {
          const std::string rel = ds.layout.frame_relative(a.name, depth, t);
          const auto it = checksums.find(rel);
          if (it == checksums.end()) fail(file, fmt::format("not listed in {}", csv.string()));
          verify_checksum(file, it->second, buf);
        } else if (cv::imread(file.string(), cv::IMREAD_UNCHANGED).empty()) {
          fail(file, "cannot decode the frame (the dataset has no checksums.csv; every frame was decoded)");
        }
        if (progress) progress(++done, total);
      }
    }
  }
}

}  // namespace wingman::datasets
