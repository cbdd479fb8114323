// Strict YAML input shared by every reader of a scenario file: unknown keys, duplicate keys,
// wrong types and values out of range are errors of the form
//   <file>:<line>:<col>: <key.path>: <what is wrong>
// with the 1-based position of the offending node (the key for unknown or duplicate keys, the
// value otherwise). sim's scenario reader and the settings reader (sim/settings_yaml.hpp) use it.
#pragma once

#include <yaml-cpp/yaml.h>

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "geometry/bounds_check.hpp"
#include "geometry/camera.hpp"
#include "sim/sensors.hpp"
#include "geometry/settings.hpp"
#include "sim/trajectory.hpp"

namespace wingman::sim {

using geometry::Bounds;

// Where something was written: the node's position and its key path.
struct Loc {
  YAML::Mark mark = YAML::Mark::null_mark();
  std::string path;
  bool valid() const { return !path.empty(); }
};

// Text as a message may print it: control characters and bytes outside well-formed UTF-8 as \xNN.
std::string printable(const std::string& s);

// The file being read; its fail() throws ScenarioError (sim/scenario.hpp) with the position.
class Ctx {
 public:
  explicit Ctx(std::string origin) : origin_(std::move(origin)) {}
  const std::string& origin() const { return origin_; }
  [[noreturn]] void fail(const YAML::Mark& m, const std::string& path, const std::string& what) const;
  [[noreturn]] void fail(const Loc& l, const std::string& what) const { fail(l.mark, l.path, what); }
  // "<file>:<line>: <path>: <what>" without throwing, for warnings.
  std::string where(const Loc& l) const;

 private:
  std::string origin_;
};

// One value in the document: the node, the key that introduced it and its key path.
struct Field {
  YAML::Node node;
  YAML::Mark key_mark = YAML::Mark::null_mark();
  std::string path;
  Loc loc() const;
  Loc key_loc() const { return {key_mark.is_null() ? loc().mark : key_mark, path}; }
};

// The YAML of a section another module defines, with the file it came from.
struct SettingsLayer {
  std::string section;  // "estimator", "frontend" or "control"
  Ctx ctx;
  Field field;
};

std::string describe(const YAML::Node& n);
// " (did you mean 'x'?)" for the closest candidate within edit distance 2, or "".
std::string suggestion(const std::string& word, const std::vector<std::string_view>& candidates);
std::string join(const std::vector<std::string_view>& v, std::string_view sep = ", ");
std::string child_path(const std::string& parent, std::string_view key);
std::string index_path(const std::string& parent, std::size_t i);

// A map whose keys have been checked: all known, none repeated.
class MapView {
 public:
  using UnknownNote = std::function<std::string(const std::string&)>;
  MapView(const Ctx& ctx, const Field& f, std::vector<std::string_view> allowed,
          const UnknownNote& note = {});
  // Any key but a duplicate: a map whose other keys another reader checks.
  static MapView open(const Ctx& ctx, const Field& f);
  std::optional<Field> get(std::string_view key) const;
  Field require(std::string_view key, const Loc& map_loc) const;
  const std::string& path() const { return path_; }

 private:
  MapView(const Ctx& ctx, const Field& f, std::vector<std::string_view> allowed,
          const UnknownNote& note, bool check_known);
  const Ctx& ctx_;
  std::string path_;
  std::vector<Field> fields_;
  std::vector<std::string> names_;
};

using geometry::any_value;
using geometry::ge;
using geometry::gt;
using geometry::in;
using geometry::bounds_text;

const std::string& scalar_of(const Ctx& ctx, const Field& f, std::string_view expected);
double read_number(const Ctx& ctx, const Field& f, Bounds b = any_value());
long long read_integer(const Ctx& ctx, const Field& f, long long lo, long long hi);
int read_int(const Ctx& ctx, const Field& f, int lo, int hi = std::numeric_limits<int>::max());
std::uint64_t read_seed(const Ctx& ctx, const Field& f);
// A sensor name, a list of them, a configuration (1, 2, 3 or integrated).
Sensor read_sensor(const Ctx& ctx, const Field& f);
std::vector<Sensor> read_sensor_list(const Ctx& ctx, const Field& f);
Config read_config(const Ctx& ctx, const Field& f);
// An integer seed or `per_run`.
geometry::SeedSetting read_seed_setting(const Ctx& ctx, const Field& f);
bool read_bool(const Ctx& ctx, const Field& f);
// Numbers without an upper bound of their own are at most this large in magnitude.
inline constexpr double kMaxMagnitude = 1e9;
// Strings (names, file paths) are UTF-8 and at most this long.
inline constexpr std::size_t kMaxStringBytes = 4096;
std::string read_string(const Ctx& ctx, const Field& f);
// A list of 3 numbers, each within b.
Eigen::Vector3d read_vec3(const Ctx& ctx, const Field& f, Bounds b = any_value());
// k1 k2 p1 p2 [k3]: radial-tangential coefficients, 4 or 5 of them.
geometry::Distortion read_distortion(const Ctx& ctx, const Field& f);
// A list of 4 numbers, each within b.
Eigen::Vector4d read_vec4(const Ctx& ctx, const Field& f, Bounds b = any_value());
// Timed waypoints [t, x, y, z]: at least two, times >= 0 and strictly increasing.
Waypoints read_waypoints(const Ctx& ctx, const Field& f);

}  // namespace wingman::sim
