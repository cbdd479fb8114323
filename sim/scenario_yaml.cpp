// Strict YAML loader for scenarios (DESIGN.md §8): unknown keys, duplicate keys, wrong types and
// values out of range are errors of the form
//   <file>:<line>:<col>: <key.path>: <what is wrong>
// with the 1-based position of the offending node (the key for unknown/duplicate keys, the value
// otherwise). Variants are the base scenario with overrides parsed by the same code.
#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <sstream>
#include <string_view>

#include "sim/scenario.hpp"

namespace wingman::sim {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kTimeEps = 1e-9;

// Where something was written: the node's position and its key path.
struct Loc {
  YAML::Mark mark = YAML::Mark::null_mark();
  std::string path;
  bool valid() const { return !path.empty(); }
};

class Ctx {
 public:
  explicit Ctx(std::string origin) : origin_(std::move(origin)) {}
  const std::string& origin() const { return origin_; }

  [[noreturn]] void fail(const YAML::Mark& m, const std::string& path,
                         const std::string& what) const {
    std::string where = origin_;
    if (!m.is_null() && m.line >= 0) where += fmt::format(":{}:{}", m.line + 1, m.column + 1);
    if (path.empty()) throw ScenarioError(fmt::format("{}: {}", where, what));
    throw ScenarioError(fmt::format("{}: {}: {}", where, path, what));
  }
  [[noreturn]] void fail(const Loc& l, const std::string& what) const {
    fail(l.mark, l.path, what);
  }

 private:
  std::string origin_;
};

std::string describe(const YAML::Node& n) {
  if (!n.IsDefined() || n.IsNull()) return "nothing";
  if (n.IsScalar()) return fmt::format("'{}'", n.Scalar());
  if (n.IsSequence()) return "a list";
  if (n.IsMap()) return "a map";
  return "something else";
}

// Optimal string alignment distance (edit distance with adjacent transpositions).
std::size_t edit_distance(std::string_view a, std::string_view b) {
  const std::size_t n = a.size(), m = b.size();
  std::vector<std::vector<std::size_t>> d(n + 1, std::vector<std::size_t>(m + 1));
  for (std::size_t i = 0; i <= n; ++i) d[i][0] = i;
  for (std::size_t j = 0; j <= m; ++j) d[0][j] = j;
  for (std::size_t i = 1; i <= n; ++i) {
    for (std::size_t j = 1; j <= m; ++j) {
      const std::size_t cost = a[i - 1] == b[j - 1] ? 0 : 1;
      d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + cost});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1])
        d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
    }
  }
  return d[n][m];
}

// " (did you mean 'x'?)" for the closest candidate within edit distance 2, or "".
std::string suggestion(const std::string& word, const std::vector<std::string_view>& candidates) {
  std::size_t best = 3;
  std::string_view best_word;
  for (std::string_view c : candidates) {
    const std::size_t d = edit_distance(word, c);
    if (d < best && d < std::max(word.size(), c.size())) {
      best = d;
      best_word = c;
    }
  }
  if (best_word.empty()) return "";
  return fmt::format(" (did you mean '{}'?)", best_word);
}

std::string join(const std::vector<std::string_view>& v, std::string_view sep = ", ") {
  std::string out;
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (i) out += sep;
    out += v[i];
  }
  return out;
}

// One value in the document: the node, the key that introduced it and its key path.
struct Field {
  YAML::Node node;
  YAML::Mark key_mark = YAML::Mark::null_mark();
  std::string path;

  Loc loc() const {
    // An empty value (`key:` with nothing after it) is reported at its key: yaml-cpp places the
    // null where the next token starts, often on the following line.
    YAML::Mark m = node.IsDefined() && !node.IsNull() ? node.Mark() : YAML::Mark::null_mark();
    if (m.is_null()) m = key_mark;
    return {m, path};
  }
  Loc key_loc() const { return {key_mark.is_null() ? loc().mark : key_mark, path}; }
};

std::string child_path(const std::string& parent, std::string_view key) {
  return parent.empty() ? std::string(key) : fmt::format("{}.{}", parent, key);
}

std::string index_path(const std::string& parent, std::size_t i) {
  return fmt::format("{}[{}]", parent, i);
}

// A map whose keys have been checked: all known, none repeated.
class MapView {
 public:
  using UnknownNote = std::function<std::string(const std::string&)>;

  MapView(const Ctx& ctx, const Field& f, std::vector<std::string_view> allowed,
          const UnknownNote& note = {})
      : ctx_(ctx), path_(f.path) {
    if (!f.node.IsMap()) ctx.fail(f.loc(), fmt::format("expected a map, got {}", describe(f.node)));
    for (auto it = f.node.begin(); it != f.node.end(); ++it) {
      const YAML::Node key = it->first;
      if (!key.IsScalar())
        ctx.fail(key.Mark(), path_, fmt::format("expected a plain key, got {}", describe(key)));
      const std::string name = key.Scalar();
      const std::string path = child_path(path_, name);
      for (const Field& seen : fields_) {
        if (seen.path == path) {
          ctx.fail(
              key.Mark(), path,
              fmt::format("duplicate key '{}' (first at line {})", name, seen.key_mark.line + 1));
        }
      }
      if (std::find(allowed.begin(), allowed.end(), name) == allowed.end()) {
        std::string extra = note ? note(name) : std::string();
        if (extra.empty()) extra = suggestion(name, allowed);
        ctx.fail(key.Mark(), path, fmt::format("unknown key '{}'{}", name, extra));
      }
      fields_.push_back(Field{it->second, key.Mark(), path});
      names_.push_back(name);
    }
  }

  std::optional<Field> get(std::string_view key) const {
    for (std::size_t i = 0; i < names_.size(); ++i) {
      if (names_[i] == key) return fields_[i];
    }
    return std::nullopt;
  }

  Field require(std::string_view key, const Loc& map_loc) const {
    if (auto f = get(key)) return *f;
    ctx_.fail(map_loc, fmt::format("missing required key '{}'", key));
  }

  const std::string& path() const { return path_; }

 private:
  const Ctx& ctx_;
  std::string path_;
  std::vector<Field> fields_;
  std::vector<std::string> names_;
};

// ---- Scalars ---------------------------------------------------------------------------------

struct Bounds {
  double lo = -kInf, hi = kInf;
  bool lo_open = false, hi_open = false;

  bool ok(double v) const {
    if (lo_open ? !(v > lo) : !(v >= lo)) return false;
    if (hi_open ? !(v < hi) : !(v <= hi)) return false;
    return true;
  }
  std::string text() const {
    if (hi == kInf) return fmt::format("{} {}", lo_open ? ">" : ">=", lo);
    if (lo == -kInf) return fmt::format("{} {}", hi_open ? "<" : "<=", hi);
    return fmt::format("in {}{}, {}{}", lo_open ? '(' : '[', lo, hi, hi_open ? ')' : ']');
  }
};

Bounds any() { return {}; }
Bounds ge(double lo) { return {lo, kInf, false, false}; }
Bounds gt(double lo) { return {lo, kInf, true, false}; }
Bounds in(double lo, double hi, bool lo_open = false, bool hi_open = false) {
  return {lo, hi, lo_open, hi_open};
}

const std::string& scalar_of(const Ctx& ctx, const Field& f, std::string_view expected) {
  if (!f.node.IsScalar())
    ctx.fail(f.loc(), fmt::format("expected {}, got {}", expected, describe(f.node)));
  return f.node.Scalar();
}

double read_number(const Ctx& ctx, const Field& f, Bounds b = any()) {
  std::string s = scalar_of(ctx, f, "a number");
  std::string_view sv = s;
  if (!sv.empty() && sv.front() == '+') sv.remove_prefix(1);
  double v = 0;
  const auto [p, ec] = std::from_chars(sv.data(), sv.data() + sv.size(), v);
  if (sv.empty() || ec != std::errc() || p != sv.data() + sv.size())
    ctx.fail(f.loc(), fmt::format("expected a number, got '{}'", s));
  if (!std::isfinite(v)) ctx.fail(f.loc(), fmt::format("expected a finite number, got '{}'", s));
  if (!b.ok(v)) ctx.fail(f.loc(), fmt::format("must be {}, got {}", b.text(), s));
  return v;
}

long long read_integer(const Ctx& ctx, const Field& f, long long lo, long long hi) {
  std::string s = scalar_of(ctx, f, "an integer");
  std::string_view sv = s;
  if (!sv.empty() && sv.front() == '+') sv.remove_prefix(1);
  long long v = 0;
  const auto [p, ec] = std::from_chars(sv.data(), sv.data() + sv.size(), v);
  if (sv.empty() || p != sv.data() + sv.size() ||
      (ec != std::errc() && ec != std::errc::result_out_of_range))
    ctx.fail(f.loc(), fmt::format("expected an integer, got '{}'", s));
  if (ec == std::errc::result_out_of_range || v < lo || v > hi) {
    if (hi == std::numeric_limits<int>::max()) {
      if (ec == std::errc() && v < lo)
        ctx.fail(f.loc(), fmt::format("must be >= {}, got {}", lo, s));
      ctx.fail(f.loc(), fmt::format("must be at most {}, got {}", hi, s));
    }
    ctx.fail(f.loc(), fmt::format("must be in [{}, {}], got {}", lo, hi, s));
  }
  return v;
}

int read_int(const Ctx& ctx, const Field& f, int lo, int hi = std::numeric_limits<int>::max()) {
  return static_cast<int>(read_integer(ctx, f, lo, hi));
}

std::uint64_t read_seed(const Ctx& ctx, const Field& f) {
  std::string s = scalar_of(ctx, f, "an integer");
  std::string_view sv = s;
  if (!sv.empty() && sv.front() == '+') sv.remove_prefix(1);
  if (!sv.empty() && sv.front() == '-') {
    long long neg = 0;
    const auto [p, ec] = std::from_chars(sv.data(), sv.data() + sv.size(), neg);
    if (p == sv.data() + sv.size() && (ec == std::errc() || ec == std::errc::result_out_of_range))
      ctx.fail(f.loc(), fmt::format("must be >= 0, got {}", s));
    ctx.fail(f.loc(), fmt::format("expected an integer, got '{}'", s));
  }
  std::uint64_t v = 0;
  const auto [p, ec] = std::from_chars(sv.data(), sv.data() + sv.size(), v);
  if (sv.empty() || p != sv.data() + sv.size() ||
      (ec != std::errc() && ec != std::errc::result_out_of_range))
    ctx.fail(f.loc(), fmt::format("expected an integer, got '{}'", s));
  if (ec == std::errc::result_out_of_range)
    ctx.fail(f.loc(), fmt::format("must be at most {}, got {}",
                                  std::numeric_limits<std::uint64_t>::max(), s));
  return v;
}

bool read_bool(const Ctx& ctx, const Field& f) {
  const std::string& s = scalar_of(ctx, f, "true or false");
  if (s == "true" || s == "True" || s == "TRUE") return true;
  if (s == "false" || s == "False" || s == "FALSE") return false;
  ctx.fail(f.loc(), fmt::format("expected true or false, got '{}'", s));
}

std::string read_string(const Ctx& ctx, const Field& f) {
  const std::string& s = scalar_of(ctx, f, "a string");
  if (s.empty()) ctx.fail(f.loc(), "expected a non-empty string");
  return s;
}

Eigen::Vector3d read_vec3(const Ctx& ctx, const Field& f) {
  if (!f.node.IsSequence() || f.node.size() != 3) {
    ctx.fail(f.loc(), fmt::format("expected a list of 3 numbers, got {}",
                                  f.node.IsSequence() ? fmt::format("a list of {}", f.node.size())
                                                      : describe(f.node)));
  }
  Eigen::Vector3d v;
  for (std::size_t i = 0; i < 3; ++i)
    v[static_cast<Eigen::Index>(i)] =
        read_number(ctx, Field{f.node[i], f.key_mark, index_path(f.path, i)});
  return v;
}

bool name_ok(const std::string& s, bool allow_dash) {
  if (s.empty()) return false;
  for (char c : s) {
    const bool ok =
        (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_' || (allow_dash && c == '-');
    if (!ok) return false;
  }
  return true;
}

const std::vector<std::string_view> kSensorNames = {"landmarks", "lead_projection", "altimeter",
                                                    "range", "gps"};

Sensor read_sensor(const Ctx& ctx, const Field& f) {
  const std::string& s = scalar_of(ctx, f, "a sensor name");
  if (auto k = sensor_from_string(s)) return *k;
  ctx.fail(f.loc(), fmt::format("unknown sensor '{}'{}; expected one of {}", s,
                                suggestion(s, kSensorNames), join(kSensorNames)));
}

std::vector<Sensor> read_sensor_list(const Ctx& ctx, const Field& f) {
  if (!f.node.IsSequence())
    ctx.fail(f.loc(), fmt::format("expected a list of sensor names, got {}", describe(f.node)));
  std::vector<Sensor> out;
  for (std::size_t i = 0; i < f.node.size(); ++i)
    out.push_back(read_sensor(ctx, Field{f.node[i], f.key_mark, index_path(f.path, i)}));
  return out;
}

Config read_config(const Ctx& ctx, const Field& f) {
  const std::string& s = scalar_of(ctx, f, "1, 2, 3 or integrated");
  if (s == "1") return Config::C1;
  if (s == "2") return Config::C2;
  if (s == "3") return Config::C3;
  if (s == "integrated") return Config::Integrated;
  ctx.fail(f.loc(), fmt::format("expected 1, 2, 3 or integrated, got '{}'", s));
}

// Helpers that assign a key's value when the key is present.
template <typename T, typename Read>
std::optional<Field> set_if(const MapView& m, std::string_view key, T& target, Read read) {
  auto f = m.get(key);
  if (f) target = read(*f);
  return f;
}

std::optional<Field> num(const Ctx& ctx, const MapView& m, std::string_view key, double& target,
                         Bounds b = any()) {
  return set_if(m, key, target, [&](const Field& f) { return read_number(ctx, f, b); });
}
std::optional<Field> integer(const Ctx& ctx, const MapView& m, std::string_view key, int& target,
                             int lo) {
  return set_if(m, key, target, [&](const Field& f) { return read_int(ctx, f, lo); });
}
std::optional<Field> boolean(const Ctx& ctx, const MapView& m, std::string_view key, bool& target) {
  return set_if(m, key, target, [&](const Field& f) { return read_bool(ctx, f); });
}

// ---- Provenance: where the values that cross-field checks look at came from -----------------

struct Provenance {
  Loc uavs;  // the uavs list, if given
  bool phases_given = false;
  std::vector<Loc> phase_to;      // per phase, its `to` value
  std::vector<Loc> outage_agent;  // per outage, its `agent` value (invalid when absent)
  Loc mode, single_uav, max_landmarks, target_per_camera;
};

Loc loc_of(const std::optional<Field>& f) { return f ? f->loc() : Loc{}; }

// ---- Sections --------------------------------------------------------------------------------

void parse_noise(const Ctx& ctx, const Field& f, NoiseSpec& n) {
  MapView m(ctx, f,
            {"pixel_sigma", "pixel_bias_sigma", "gps_sigma", "altimeter_sigma", "range_sigma", "ahrs_yaw_sigma",
             "outlier_fraction", "cooperative_outlier_fraction", "outlier_max_px",
             "gimbal_amplitude", "gimbal_omega", "gimbal_random_phase", "motion"});
  num(ctx, m, "pixel_sigma", n.pixel_sigma, ge(0));
  num(ctx, m, "pixel_bias_sigma", n.pixel_bias_sigma, ge(0));
  num(ctx, m, "gps_sigma", n.gps_sigma, ge(0));
  num(ctx, m, "altimeter_sigma", n.altimeter_sigma, ge(0));
  num(ctx, m, "range_sigma", n.range_sigma, ge(0));
  num(ctx, m, "ahrs_yaw_sigma", n.ahrs_yaw_sigma, ge(0));
  num(ctx, m, "outlier_fraction", n.outlier_fraction, in(0, 1));
  num(ctx, m, "cooperative_outlier_fraction", n.cooperative_outlier_fraction, in(0, 1));
  num(ctx, m, "outlier_max_px", n.outlier_max_px, ge(0));
  num(ctx, m, "gimbal_amplitude", n.gimbal_amplitude);
  num(ctx, m, "gimbal_omega", n.gimbal_omega);
  boolean(ctx, m, "gimbal_random_phase", n.gimbal_random_phase);
  if (auto f = m.get("motion")) {
    MapView mm(ctx, *f, {"accel_sigma_lead", "accel_sigma_uav", "accel_sigma_common"});
    num(ctx, mm, "accel_sigma_lead", n.motion.accel_sigma_lead, ge(0));
    num(ctx, mm, "accel_sigma_uav", n.motion.accel_sigma_uav, ge(0));
    num(ctx, mm, "accel_sigma_common", n.motion.accel_sigma_common, ge(0));
  }
}

void parse_landmarks(const Ctx& ctx, const Field& f, LandmarkFieldSpec& l) {
  MapView m(ctx, f, {"density", "ground_height", "height_spread", "margin"});
  num(ctx, m, "density", l.density, gt(0));
  num(ctx, m, "ground_height", l.ground_height);
  num(ctx, m, "height_spread", l.height_spread, ge(0));
  num(ctx, m, "margin", l.margin, ge(0));
}

void parse_trajectory(const Ctx& ctx, const Field& f, LeadTrajectorySpec& t) {
  MapView m(ctx, f, {"type", "scale", "omega", "z_amplitude", "z_omega", "velocity"});
  if (auto tf = m.get("type")) {
    const std::string s = read_string(ctx, *tf);
    if (s != "lemniscate" && s != "line")
      ctx.fail(tf->loc(),
               fmt::format("unknown trajectory type '{}' (known: 'lemniscate', 'line')", s));
    t.type = s;
  }
  set_if(m, "velocity", t.velocity, [&](const Field& x) { return read_vec3(ctx, x); });
  num(ctx, m, "scale", t.scale);
  num(ctx, m, "omega", t.omega);
  num(ctx, m, "z_amplitude", t.z_amplitude);
  num(ctx, m, "z_omega", t.z_omega);
}

void parse_lead(const Ctx& ctx, const Field& f, LeadSpec& l) {
  MapView m(ctx, f, {"initial_position", "gps", "trajectory"});
  set_if(m, "initial_position", l.initial_position,
         [&](const Field& x) { return read_vec3(ctx, x); });
  boolean(ctx, m, "gps", l.gps);
  if (auto t = m.get("trajectory")) parse_trajectory(ctx, *t, l.trajectory);
}

void parse_camera(const Ctx& ctx, const Field& f, CameraSpec& c) {
  MapView m(ctx, f, {"fx", "fy", "cx", "cy", "width", "height", "distortion", "offset"});
  num(ctx, m, "fx", c.fx, gt(0));
  num(ctx, m, "fy", c.fy, gt(0));
  num(ctx, m, "cx", c.cx);
  num(ctx, m, "cy", c.cy);
  set_if(m, "width", c.width, [&](const Field& x) { return read_int(ctx, x, 1, 16384); });
  set_if(m, "height", c.height, [&](const Field& x) { return read_int(ctx, x, 1, 16384); });
  if (auto d = m.get("distortion")) {
    const YAML::Node& n = d->node;
    if (!n.IsSequence() || (n.size() != 4 && n.size() != 5)) {
      ctx.fail(d->loc(),
               fmt::format("expected a list of 4 or 5 numbers (k1 k2 p1 p2 [k3]), got {}",
                           n.IsSequence() ? fmt::format("a list of {}", n.size()) : describe(n)));
    }
    double k[5] = {0, 0, 0, 0, 0};
    for (std::size_t i = 0; i < n.size(); ++i)
      k[i] = read_number(ctx, Field{n[i], d->key_mark, index_path(d->path, i)});
    c.distortion = geometry::Distortion{k[0], k[1], k[2], k[3], k[4]};
  }
  set_if(m, "offset", c.offset, [&](const Field& x) { return read_vec3(ctx, x); });
}

void parse_uavs(const Ctx& ctx, const Field& f, std::vector<UavSpec>& uavs, Provenance& prov) {
  if (!f.node.IsSequence())
    ctx.fail(f.loc(), fmt::format("expected a list of UAVs, got {}", describe(f.node)));
  if (f.node.size() == 0) ctx.fail(f.loc(), "at least one UAV is needed");
  prov.uavs = f.loc();
  uavs.clear();
  std::vector<Loc> name_locs;
  for (std::size_t i = 0; i < f.node.size(); ++i) {
    const Field item{f.node[i], f.key_mark, index_path(f.path, i)};
    MapView m(ctx, item, {"name", "initial_position", "sees_lead", "altimeter", "range", "camera"});
    UavSpec u;
    const Field nf = m.require("name", item.loc());
    u.name = read_string(ctx, nf);
    if (u.name == "lead")
      ctx.fail(nf.loc(), "'lead' is reserved for the lead agent; choose another UAV name");
    if (!name_ok(u.name, false))
      ctx.fail(nf.loc(), fmt::format("UAV names must match [a-z0-9_]+, got '{}'", u.name));
    for (std::size_t j = 0; j < uavs.size(); ++j) {
      if (uavs[j].name == u.name)
        ctx.fail(nf.loc(), fmt::format("duplicate UAV name '{}' (first at line {})", u.name,
                                       name_locs[j].mark.line + 1));
    }
    set_if(m, "initial_position", u.initial_position,
           [&](const Field& x) { return read_vec3(ctx, x); });
    boolean(ctx, m, "sees_lead", u.sees_lead);
    boolean(ctx, m, "altimeter", u.altimeter);
    boolean(ctx, m, "range", u.range);
    if (auto c = m.get("camera")) parse_camera(ctx, *c, u.camera);
    uavs.push_back(std::move(u));
    name_locs.push_back(nf.loc());
  }
}

// A time window [from, to) of a phase or an outage: from >= 0 and to > from.
void read_window(const Ctx& ctx, const Field& from, const Field& to, double& t_start, double& t_end) {
  t_start = read_number(ctx, from, ge(0));
  t_end = read_number(ctx, to);
  if (!(t_end > t_start))
    ctx.fail(to.loc(), fmt::format("must be greater than from ({}), got {}", t_start, to.node.Scalar()));
}

void parse_phases(const Ctx& ctx, const Field& f, std::vector<Phase>& phases, Provenance& prov) {
  if (!f.node.IsSequence())
    ctx.fail(f.loc(), fmt::format("expected a list of phases, got {}", describe(f.node)));
  if (f.node.size() == 0) ctx.fail(f.loc(), "expected at least one phase");
  phases.clear();
  prov.phases_given = true;
  prov.phase_to.clear();
  std::vector<Loc> name_locs;
  for (std::size_t i = 0; i < f.node.size(); ++i) {
    const Field item{f.node[i], f.key_mark, index_path(f.path, i)};
    MapView m(ctx, item, {"name", "from", "to", "config", "add", "remove"});
    Phase p;
    p.name = fmt::format("phase{}", i + 1);
    auto nf = m.get("name");
    if (nf) p.name = read_string(ctx, *nf);
    const Field from = m.require("from", item.loc());
    const Field to = m.require("to", item.loc());
    read_window(ctx, from, to, p.t_start, p.t_end);
    p.config = read_config(ctx, m.require("config", item.loc()));
    if (auto a = m.get("add")) p.add = read_sensor_list(ctx, *a);
    if (auto r = m.get("remove")) {
      p.remove = read_sensor_list(ctx, *r);
      for (std::size_t k = 0; k < p.remove.size(); ++k) {
        if (std::find(p.add.begin(), p.add.end(), p.remove[k]) != p.add.end())
          ctx.fail(Field{r->node[k], r->key_mark, index_path(r->path, k)}.loc(),
                   fmt::format("sensor '{}' is both added and removed", to_string(p.remove[k])));
      }
    }
    const Loc name_loc = nf ? nf->loc() : item.loc();
    for (std::size_t j = 0; j < phases.size(); ++j) {
      if (phases[j].name == p.name)
        ctx.fail(name_loc, fmt::format("duplicate phase name '{}' (first at line {})", p.name,
                                       name_locs[j].mark.line + 1));
    }
    if (!phases.empty() && p.t_start < phases.back().t_end - kTimeEps) {
      ctx.fail(from.loc(),
               fmt::format("phase '{}' starts at {}, before the previous phase '{}' ends ({}); "
                           "phases must be sorted and must not overlap",
                           p.name, p.t_start, phases.back().name, phases.back().t_end));
    }
    phases.push_back(std::move(p));
    name_locs.push_back(name_loc);
    prov.phase_to.push_back(to.loc());
  }
}

void parse_outages(const Ctx& ctx, const Field& f, std::vector<Outage>& outages, Provenance& prov) {
  if (!f.node.IsSequence())
    ctx.fail(f.loc(), fmt::format("expected a list of outages, got {}", describe(f.node)));
  outages.clear();
  prov.outage_agent.clear();
  for (std::size_t i = 0; i < f.node.size(); ++i) {
    const Field item{f.node[i], f.key_mark, index_path(f.path, i)};
    MapView m(ctx, item, {"sensor", "from", "to", "agent"});
    Outage o;
    o.sensor = read_sensor(ctx, m.require("sensor", item.loc()));
    const Field from = m.require("from", item.loc());
    const Field to = m.require("to", item.loc());
    read_window(ctx, from, to, o.t_start, o.t_end);
    auto af = m.get("agent");
    if (af) o.agent = read_string(ctx, *af);
    outages.push_back(std::move(o));
    prov.outage_agent.push_back(loc_of(af));
  }
}

void parse_estimator(const Ctx& ctx, const Field& f, EstimatorSpec& e, Provenance& prov) {
  MapView m(ctx, f,
            {"mode", "single_uav", "process_noise", "measurement_noise", "initial_sigma", "gating",
             "map", "initialisation"});
  if (auto mf = m.get("mode")) {
    const std::string& s = scalar_of(ctx, *mf, "multi or single");
    if (s == "multi")
      e.mode = EstimatorMode::MultiUav;
    else if (s == "single")
      e.mode = EstimatorMode::SingleUav;
    else
      ctx.fail(mf->loc(), fmt::format("expected multi or single, got '{}'", s));
    prov.mode = mf->loc();
  }
  if (auto sf = m.get("single_uav")) {
    e.single_uav = read_string(ctx, *sf);
    prov.single_uav = sf->loc();
  }
  if (auto pf = m.get("process_noise")) {
    MapView p(ctx, *pf, {"accel_sigma_lead", "accel_sigma_uav", "accel_sigma_common", "common_acceleration_state"});
    num(ctx, p, "accel_sigma_lead", e.accel_sigma_lead, ge(0));
    num(ctx, p, "accel_sigma_uav", e.accel_sigma_uav, ge(0));
    num(ctx, p, "accel_sigma_common", e.accel_sigma_common, ge(0));
    if (auto cf = p.get("common_acceleration_state")) {
      MapView c(ctx, *cf, {"sigma", "time_constant"});
      num(ctx, c, "sigma", e.common_accel_state_sigma, ge(0));
      num(ctx, c, "time_constant", e.common_accel_state_time_constant, ge(0));
    }
  }
  if (auto rf = m.get("measurement_noise")) {
    MapView r(ctx, *rf, {"pixel_sigma", "pixel_offset_sigma", "gps_sigma", "altimeter_sigma", "range_sigma",
                         "orientation_sigma", "orientation_time_constant"});
    num(ctx, r, "pixel_sigma", e.pixel_sigma, ge(0));
    num(ctx, r, "pixel_offset_sigma", e.pixel_offset_sigma, ge(0));
    num(ctx, r, "gps_sigma", e.gps_sigma, ge(0));
    num(ctx, r, "altimeter_sigma", e.altimeter_sigma, ge(0));
    num(ctx, r, "range_sigma", e.range_sigma, ge(0));
    num(ctx, r, "orientation_sigma", e.orientation_sigma, ge(0));
    num(ctx, r, "orientation_time_constant", e.orientation_time_constant, ge(0));
  }
  if (auto inf = m.get("initial_sigma")) {
    MapView s(ctx, *inf, {"position", "velocity", "draw"});
    num(ctx, s, "position", e.initial_position_sigma, ge(0));
    num(ctx, s, "velocity", e.initial_velocity_sigma, ge(0));
    boolean(ctx, s, "draw", e.draw_initial_error);
  }
  if (auto gf = m.get("gating")) {
    MapView g(ctx, *gf,
              {"probability", "one_point_ransac", "ransac_inlier_px", "ransac_success_probability",
               "ransac_max_hypotheses"});
    num(ctx, g, "probability", e.gate_probability, in(0, 1, true, true));
    boolean(ctx, g, "one_point_ransac", e.one_point_ransac);
    num(ctx, g, "ransac_inlier_px", e.ransac_inlier_px, gt(0));
    num(ctx, g, "ransac_success_probability", e.ransac_success_probability, in(0, 1));
    integer(ctx, g, "ransac_max_hypotheses", e.ransac_max_hypotheses, 1);
  }
  if (auto mapf = m.get("map")) {
    MapView mm(ctx, *mapf, {"max_landmarks", "target_per_camera", "max_misses", "image_margin_px"});
    if (auto x = integer(ctx, mm, "max_landmarks", e.max_landmarks, 1))
      prov.max_landmarks = x->loc();
    if (auto x = integer(ctx, mm, "target_per_camera", e.target_landmarks_per_camera, 1))
      prov.target_per_camera = x->loc();
    integer(ctx, mm, "max_misses", e.max_misses, 1);
    num(ctx, mm, "image_margin_px", e.image_margin_px, ge(0));
  }
  if (auto initf = m.get("initialisation")) {
    MapView i(ctx, *initf,
              {"min_parallax_deg", "max_reprojection_px", "min_depth_m", "low_parallax_inverse_depth",
               "monocular_fill", "inverse_depth_rho", "inverse_depth_sigma", "linearity_threshold"});
    num(ctx, i, "min_parallax_deg", e.min_parallax_deg, in(0, 90, false, true));
    num(ctx, i, "max_reprojection_px", e.max_reprojection_px, gt(0));
    num(ctx, i, "min_depth_m", e.min_depth_m, ge(0));
    boolean(ctx, i, "low_parallax_inverse_depth", e.low_parallax_inverse_depth);
    boolean(ctx, i, "monocular_fill", e.monocular_fill);
    num(ctx, i, "inverse_depth_rho", e.inverse_depth_rho, gt(0));
    num(ctx, i, "inverse_depth_sigma", e.inverse_depth_sigma, ge(0));
    num(ctx, i, "linearity_threshold", e.linearity_threshold, gt(0));
  }
}

// ---- control: (closed loop, paper section 6 and 7.3) ----------------------------------------

// A number for all four components of lambda = [lx, ly, lz, psi], or a list of four.
Eigen::Vector4d read_vec4(const Ctx& ctx, const Field& f, Bounds b) {
  if (f.node.IsScalar()) return Eigen::Vector4d::Constant(read_number(ctx, f, b));
  if (!f.node.IsSequence() || f.node.size() != 4) {
    ctx.fail(f.loc(), fmt::format("expected a number or a list of 4 numbers (x, y, z, yaw), got {}",
                                  f.node.IsSequence() ? fmt::format("a list of {}", f.node.size())
                                                      : describe(f.node)));
  }
  Eigen::Vector4d v;
  for (std::size_t i = 0; i < 4; ++i)
    v[static_cast<Eigen::Index>(i)] =
        read_number(ctx, Field{f.node[i], f.key_mark, index_path(f.path, i)}, b);
  return v;
}

void parse_control_uavs(const Ctx& ctx, const Field& f, std::vector<UavControlSpec>& out) {
  if (!f.node.IsSequence() || f.node.size() == 0)
    ctx.fail(f.loc(), fmt::format("expected a list of controlled UAVs, got {}", describe(f.node)));
  out.clear();
  std::vector<Loc> name_locs;
  for (std::size_t i = 0; i < f.node.size(); ++i) {
    const Field item{f.node[i], f.key_mark, index_path(f.path, i)};
    MapView m(ctx, item, {"name", "initial_yaw", "lambda_d", "yaw_d"});
    UavControlSpec u;
    const Field nf = m.require("name", item.loc());
    u.uav = read_string(ctx, nf);
    for (std::size_t j = 0; j < out.size(); ++j)
      if (out[j].uav == u.uav)
        ctx.fail(nf.loc(), fmt::format("duplicate UAV '{}' (first at line {})", u.uav,
                                       name_locs[j].mark.line + 1));
    num(ctx, m, "initial_yaw", u.initial_yaw, in(-2 * M_PI, 2 * M_PI));
    set_if(m, "lambda_d", u.lambda_d, [&](const Field& x) { return read_vec3(ctx, x); });
    if (auto y = m.get("yaw_d")) {
      if (y->node.IsScalar() && y->node.Scalar() == "lead_bearing")
        u.yaw_d.reset();
      else if (y->node.IsScalar() && !y->node.Scalar().empty() &&
               (std::isdigit(static_cast<unsigned char>(y->node.Scalar()[0])) ||
                std::string_view("+-.").find(y->node.Scalar()[0]) != std::string_view::npos))
        u.yaw_d = read_number(ctx, *y, in(-2 * M_PI, 2 * M_PI));
      else
        ctx.fail(y->loc(), fmt::format("expected lead_bearing or a yaw in radians, got {}",
                                       describe(y->node)));
    }
    out.push_back(std::move(u));
    name_locs.push_back(nf.loc());
  }
}

// The section's presence turns the closed loop on; every UAV of the scenario needs an entry
// (default: section 7.3's uav1 and uav2).
void parse_control(const Ctx& ctx, const Field& f, ControlSpec& c, const std::vector<UavSpec>& uavs) {
  MapView m(ctx, f,
            {"settling_time", "k1", "k2", "switching", "boundary_width", "limits", "anti_windup",
             "lead_bearing_min_range", "disturbance", "uavs"});
  c.enabled = true;
  num(ctx, m, "settling_time", c.settling_time, ge(0));
  set_if(m, "k1", c.k1, [&](const Field& x) { return read_vec4(ctx, x, ge(0)); });
  set_if(m, "k2", c.k2, [&](const Field& x) { return read_vec4(ctx, x, gt(0)); });
  if (auto sf = m.get("switching")) {
    const std::string& s = scalar_of(ctx, *sf, "sign, sat or tanh");
    if (s == "sign")
      c.switching = SwitchingSpec::Sign;
    else if (s == "sat")
      c.switching = SwitchingSpec::Saturation;
    else if (s == "tanh")
      c.switching = SwitchingSpec::Tanh;
    else
      ctx.fail(sf->loc(), fmt::format("expected sign, sat or tanh, got '{}'{}", s,
                                      suggestion(s, {"sign", "sat", "tanh"})));
  }
  set_if(m, "boundary_width", c.boundary_width, [&](const Field& x) { return read_vec4(ctx, x, gt(0)); });
  if (auto lf = m.get("limits")) {
    MapView l(ctx, *lf, {"horizontal_speed", "vertical_speed", "yaw_rate", "acceleration"});
    num(ctx, l, "horizontal_speed", c.max_horizontal_speed, gt(0));
    num(ctx, l, "vertical_speed", c.max_vertical_speed, gt(0));
    num(ctx, l, "yaw_rate", c.max_yaw_rate, gt(0));
    num(ctx, l, "acceleration", c.max_acceleration, ge(0));
  }
  boolean(ctx, m, "anti_windup", c.anti_windup);
  num(ctx, m, "lead_bearing_min_range", c.lead_bearing_min_range, ge(0));
  if (auto df = m.get("disturbance")) {
    MapView d(ctx, *df, {"bound", "seed"});
    set_if(d, "bound", c.disturbance_bound, [&](const Field& x) { return read_vec4(ctx, x, ge(0)); });
    if (auto s = d.get("seed")) c.disturbance_seed = read_seed(ctx, *s);
  }
  const auto uf = m.get("uavs");
  if (uf) parse_control_uavs(ctx, *uf, c.uavs);
  else if (c.uavs.empty()) c.uavs = paper_control_uavs();
  const Loc where = uf ? uf->loc() : f.key_loc();
  for (const UavControlSpec& u : c.uavs) {
    const bool known = std::any_of(uavs.begin(), uavs.end(), [&](const UavSpec& s) { return s.name == u.uav; });
    if (!known) {
      std::vector<std::string_view> names;
      for (const UavSpec& s : uavs) names.push_back(s.name);
      ctx.fail(where, fmt::format("'{}' is not a UAV of this scenario (UAVs: {})", u.uav, join(names)));
    }
  }
  for (const UavSpec& s : uavs) {
    if (std::none_of(c.uavs.begin(), c.uavs.end(), [&](const UavControlSpec& u) { return u.uav == s.name; }))
      ctx.fail(where, fmt::format("UAV '{}' has no entry; in closed loop every UAV needs its "
                                  "lambda_d and initial_yaw", s.name));
  }
}

// ---- World (sim/world.hpp): what `wingman render` draws --------------------------------------

template <typename E>
E read_enum(const Ctx& ctx, const Field& f, const std::vector<std::pair<std::string_view, E>>& v) {
  const std::string& s = scalar_of(ctx, f, "a name");
  std::vector<std::string_view> names;
  for (const auto& [n, e] : v) {
    if (n == s) return e;
    names.push_back(n);
  }
  ctx.fail(f.loc(), fmt::format("unknown value '{}'{}; expected one of {}", s, suggestion(s, names),
                                join(names)));
}

void parse_world_terrain(const Ctx& ctx, const Field& f, TerrainSpec& t) {
  MapView m(ctx, f, {"extent", "margin", "mean_height", "relief", "relief_scale", "resolution",
                     "road_half_width", "road_blend"});
  num(ctx, m, "extent", t.extent, ge(0));
  num(ctx, m, "margin", t.margin, ge(0));
  num(ctx, m, "mean_height", t.mean_height);
  num(ctx, m, "relief", t.relief, ge(0));
  num(ctx, m, "relief_scale", t.relief_scale, gt(0));
  num(ctx, m, "resolution", t.resolution, in(0.1, 50));
  num(ctx, m, "road_half_width", t.road_half_width, ge(0));
  num(ctx, m, "road_blend", t.road_blend, gt(0));
}

void parse_world_texture(const Ctx& ctx, const Field& f, TextureSpec& t) {
  MapView m(ctx, f, {"type", "image", "mode", "tile_size", "detail_min", "detail_max", "size",
                     "anisotropy", "filter"});
  if (auto x = m.get("type"))
    t.type = read_enum<TextureSpec::Type>(
        ctx, *x, {{"image", TextureSpec::Type::Image}, {"procedural", TextureSpec::Type::Procedural}});
  if (auto x = m.get("image")) t.image = read_string(ctx, *x);
  if (auto x = m.get("mode"))
    t.mode = read_enum<TextureSpec::Mode>(
        ctx, *x, {{"tiled", TextureSpec::Mode::Tiled}, {"stretched", TextureSpec::Mode::Stretched}});
  num(ctx, m, "tile_size", t.tile_size, gt(0));
  auto lo = num(ctx, m, "detail_min", t.detail_min, gt(0));
  auto hi = num(ctx, m, "detail_max", t.detail_max, gt(0));
  if (t.detail_max < t.detail_min)
    ctx.fail(hi ? hi->loc() : loc_of(lo),
             fmt::format("detail_max ({}) must be at least detail_min ({})", t.detail_max,
                         t.detail_min));
  set_if(m, "size", t.size, [&](const Field& x) { return read_int(ctx, x, 16, 8192); });
  num(ctx, m, "anisotropy", t.anisotropy, in(1, 64));
  if (auto x = m.get("filter"))
    t.filter = read_enum<TextureSpec::Filter>(
        ctx, *x, {{"trilinear", TextureSpec::Filter::Trilinear}, {"bilinear", TextureSpec::Filter::Bilinear}});
}

void parse_world_objects(const Ctx& ctx, const Field& f, ObjectsSpec& o) {
  MapView m(ctx, f, {"boulders", "trees", "buildings", "clearance"});
  num(ctx, m, "boulders", o.boulders, in(0, 10000));
  num(ctx, m, "trees", o.trees, in(0, 10000));
  num(ctx, m, "buildings", o.buildings, in(0, 1000));
  num(ctx, m, "clearance", o.clearance, ge(0));
}

void parse_world_lead(const Ctx& ctx, const Field& f, LeadModelSpec& l) {
  MapView m(ctx, f, {"model", "kind", "height", "up", "yaw_offset", "cue", "aruco_id",
                     "marker_size", "panel_colour"});
  if (auto x = m.get("model")) l.model = read_string(ctx, *x);
  if (auto x = m.get("kind"))
    l.kind = read_enum<LeadModelSpec::Kind>(
        ctx, *x, {{"ground", LeadModelSpec::Kind::Ground}, {"aerial", LeadModelSpec::Kind::Aerial}});
  num(ctx, m, "height", l.height, gt(0));
  if (auto x = m.get("up"))
    l.up = read_enum<std::string>(ctx, *x, {{"y", "y"}, {"z", "z"}});
  num(ctx, m, "yaw_offset", l.yaw_offset);
  if (auto x = m.get("cue"))
    l.cue = read_enum<LeadModelSpec::Cue>(ctx, *x,
                                          {{"aruco", LeadModelSpec::Cue::Aruco},
                                           {"panel", LeadModelSpec::Cue::Panel},
                                           {"none", LeadModelSpec::Cue::None}});
  set_if(m, "aruco_id", l.aruco_id, [&](const Field& x) { return read_int(ctx, x, 0, 49); });
  num(ctx, m, "marker_size", l.marker_size, gt(0));
  if (auto x = m.get("panel_colour")) {
    l.panel_colour = read_vec3(ctx, *x);
    if (l.panel_colour.minCoeff() < 0 || l.panel_colour.maxCoeff() > 1)
      ctx.fail(x->loc(), "colour components must be in [0, 1]");
  }
}

void parse_world_light(const Ctx& ctx, const Field& f, LightSpec& l) {
  MapView m(ctx, f, {"direction", "ambient", "diffuse"});
  if (auto x = m.get("direction")) {
    l.direction = read_vec3(ctx, *x);
    if (l.direction.norm() < 1e-9) ctx.fail(x->loc(), "must not be the zero vector");
  }
  num(ctx, m, "ambient", l.ambient, in(0, 2));
  num(ctx, m, "diffuse", l.diffuse, in(0, 2));
}

void parse_world_image(const Ctx& ctx, const Field& f, ImageEffectsSpec& e) {
  MapView m(ctx, f, {"msaa", "noise_sigma", "blur_sigma", "exposure_gain", "exposure_variation",
                     "sky"});
  if (auto x = m.get("msaa")) {
    e.msaa = read_int(ctx, *x, 1, 16);
    if ((e.msaa & (e.msaa - 1)) != 0) ctx.fail(x->loc(), fmt::format("must be 1, 2, 4, 8 or 16, got {}", e.msaa));
  }
  num(ctx, m, "noise_sigma", e.noise_sigma, ge(0));
  num(ctx, m, "blur_sigma", e.blur_sigma, ge(0));
  num(ctx, m, "exposure_gain", e.exposure_gain, gt(0));
  num(ctx, m, "exposure_variation", e.exposure_variation, in(0, 1));
  if (auto x = m.get("sky")) {
    e.sky = read_vec3(ctx, *x);
    if (e.sky.minCoeff() < 0 || e.sky.maxCoeff() > 1)
      ctx.fail(x->loc(), "colour components must be in [0, 1]");
  }
}

void parse_world(const Ctx& ctx, const Field& f, WorldSpec& w) {
  MapView m(ctx, f, {"terrain", "texture", "objects", "lead", "light", "image", "near", "far"});
  if (auto x = m.get("terrain")) parse_world_terrain(ctx, *x, w.terrain);
  if (auto x = m.get("texture")) parse_world_texture(ctx, *x, w.texture);
  if (auto x = m.get("objects")) parse_world_objects(ctx, *x, w.objects);
  if (auto x = m.get("lead")) parse_world_lead(ctx, *x, w.lead);
  if (auto x = m.get("light")) parse_world_light(ctx, *x, w.light);
  if (auto x = m.get("image")) parse_world_image(ctx, *x, w.image);
  num(ctx, m, "near", w.near, gt(0));
  auto ff = num(ctx, m, "far", w.far, gt(0));
  if (w.far <= w.near)
    ctx.fail(ff ? ff->loc() : f.loc(), fmt::format("far ({}) must exceed near ({})", w.far, w.near));
}

// frontend: detector, features and bucketing grid, per-detector thresholds, tracking and
// cross-UAV matching (rendered measurements; a synthetic run ignores it).
void parse_frontend(const Ctx& ctx, const Field& f, FrontendSpec& fe) {
  MapView m(ctx, f, {"detector", "max_features", "grid", "orb", "akaze", "sift", "gftt", "tracking",
                     "cross_matching", "oracle_pixels"});
  if (auto d = m.get("detector")) {
    static const std::vector<std::string_view> kinds = {"orb", "akaze", "sift", "gftt_orb"};
    const std::string& s = scalar_of(ctx, *d, "a detector name");
    if (std::find(kinds.begin(), kinds.end(), s) == kinds.end())
      ctx.fail(d->loc(), fmt::format("unknown detector '{}' (expected orb, akaze, sift or gftt_orb){}", s,
                                     suggestion(s, kinds)));
    fe.detector = s;
  }
  integer(ctx, m, "max_features", fe.max_features, 1);
  if (auto g = m.get("grid")) {
    if (!g->node.IsSequence() || g->node.size() != 2)
      ctx.fail(g->loc(), fmt::format("expected [columns, rows], got {}", describe(g->node)));
    fe.grid_cols = read_int(ctx, Field{g->node[0], g->key_mark, index_path(g->path, 0)}, 1);
    fe.grid_rows = read_int(ctx, Field{g->node[1], g->key_mark, index_path(g->path, 1)}, 1);
  }
  if (auto x = m.get("orb")) {
    MapView o(ctx, *x, {"fast_threshold", "levels", "scale_factor"});
    integer(ctx, o, "fast_threshold", fe.orb_fast_threshold, 1);
    integer(ctx, o, "levels", fe.orb_levels, 1);
    num(ctx, o, "scale_factor", fe.orb_scale_factor, in(1, 2, true, false));
  }
  if (auto x = m.get("akaze")) {
    MapView a(ctx, *x, {"threshold"});
    num(ctx, a, "threshold", fe.akaze_threshold, gt(0));
  }
  if (auto x = m.get("sift")) {
    MapView a(ctx, *x, {"contrast_threshold"});
    num(ctx, a, "contrast_threshold", fe.sift_contrast, gt(0));
  }
  if (auto x = m.get("gftt")) {
    MapView a(ctx, *x, {"quality", "min_distance_px"});
    num(ctx, a, "quality", fe.gftt_quality, in(0, 1, true, true));
    num(ctx, a, "min_distance_px", fe.gftt_min_distance_px, ge(0));
  }
  if (auto x = m.get("tracking")) {
    MapView t(ctx, *x, {"gate_d2", "ratio", "max_search_radius_px", "max_distance", "match_latest_descriptor"});
    num(ctx, t, "gate_d2", fe.tracking_gate_d2, gt(0));
    num(ctx, t, "ratio", fe.tracking_ratio, in(0, 1, true, false));
    num(ctx, t, "max_search_radius_px", fe.max_search_radius_px, ge(0));
    num(ctx, t, "max_distance", fe.tracking_max_distance, ge(0));
    boolean(ctx, t, "match_latest_descriptor", fe.tracking_match_latest);
  }
  if (auto x = m.get("cross_matching")) {
    MapView c(ctx, *x, {"ratio", "max_epipolar_px", "max_reprojection_px"});
    num(ctx, c, "ratio", fe.cross_ratio, in(0, 1, true, false));
    num(ctx, c, "max_epipolar_px", fe.max_epipolar_px, gt(0));
    num(ctx, c, "max_reprojection_px", fe.max_reprojection_px, gt(0));
  }
  boolean(ctx, m, "oracle_pixels", fe.oracle_pixels);
}

// The sections a variant may override; the top level parses them with the same code.
const std::vector<std::string_view> kCommonKeys = {"seed",      "duration", "noise",   "landmarks",
                                                   "phases",    "outages",  "estimator", "control",
                                                   "frontend"};

void apply_common(const Ctx& ctx, const MapView& m, Scenario& s, Provenance& prov) {
  if (auto f = m.get("seed")) s.seed = read_seed(ctx, *f);
  num(ctx, m, "duration", s.duration, gt(0));
  if (auto f = m.get("noise")) parse_noise(ctx, *f, s.noise);
  if (auto f = m.get("landmarks")) parse_landmarks(ctx, *f, s.field);
  if (auto f = m.get("phases")) parse_phases(ctx, *f, s.phases, prov);
  if (auto f = m.get("outages")) parse_outages(ctx, *f, s.outages, prov);
  if (auto f = m.get("estimator")) parse_estimator(ctx, *f, s.estimator, prov);
  if (auto f = m.get("control")) parse_control(ctx, *f, s.control, s.uavs);
  if (auto f = m.get("frontend")) parse_frontend(ctx, *f, s.frontend);
}

std::string uav_names(const Scenario& s) {
  std::vector<std::string_view> names;
  for (const UavSpec& u : s.uavs) names.push_back(u.name);
  return join(names);
}

// Defaults that depend on other fields, then the checks that involve the whole scenario.
void finalise(const Ctx& ctx, Scenario& s, const Provenance& prov) {
  if (!prov.phases_given) {
    Phase all;
    all.name = "all";
    all.t_start = 0;
    all.t_end = s.duration;
    all.config = Config::Integrated;
    s.phases = {all};
  } else {
    for (std::size_t i = 0; i < s.phases.size(); ++i) {
      if (s.phases[i].t_end > s.duration + kTimeEps)
        ctx.fail(prov.phase_to[i],
                 fmt::format("phase '{}' ends at {}, after the scenario's duration ({})",
                             s.phases[i].name, s.phases[i].t_end, s.duration));
    }
  }

  for (std::size_t i = 0; i < s.outages.size(); ++i) {
    const std::string& a = s.outages[i].agent;
    if (!a.empty() && a != "lead" && s.uav_index(a) < 0)
      ctx.fail(prov.outage_agent[i],
               fmt::format("unknown agent '{}' (expected lead or one of the UAVs: {})", a,
                           uav_names(s)));
  }

  const EstimatorSpec& e = s.estimator;
  if (s.uav_index(e.single_uav) < 0) {
    if (prov.single_uav.valid())
      ctx.fail(prov.single_uav, fmt::format("'{}' is not a UAV of this scenario (UAVs: {})",
                                            e.single_uav, uav_names(s)));
    if (e.mode == EstimatorMode::SingleUav)
      ctx.fail(prov.mode,
               fmt::format("single mode uses estimator.single_uav, whose default '{}' is not a "
                           "UAV of this scenario (UAVs: {}); set single_uav",
                           e.single_uav, uav_names(s)));
  }
  if (e.mode == EstimatorMode::MultiUav && s.uavs.size() < 2) {
    if (prov.mode.valid())
      ctx.fail(prov.mode,
               fmt::format("mode multi needs at least 2 UAVs, the scenario has {}", s.uavs.size()));
    ctx.fail(prov.uavs, fmt::format("the estimator's mode multi (the default) needs at least 2 "
                                    "UAVs, got {}; add a UAV or set estimator.mode: single",
                                    s.uavs.size()));
  }
  if (s.closed_loop() && e.mode == EstimatorMode::SingleUav)
    ctx.fail(prov.mode, "closed loop (the control: section) needs mode multi: the controller of "
                        "every UAV takes its position from the estimator");
  if (e.target_landmarks_per_camera > e.max_landmarks) {
    if (prov.target_per_camera.valid())
      ctx.fail(prov.target_per_camera, fmt::format("must not exceed max_landmarks ({}), got {}",
                                                   e.max_landmarks, e.target_landmarks_per_camera));
    ctx.fail(prov.max_landmarks, fmt::format("must be at least target_per_camera ({}), got {}",
                                             e.target_landmarks_per_camera, e.max_landmarks));
  }
}

std::vector<UavSpec> paper_uavs() {
  UavSpec u1;
  u1.name = "uav1";
  u1.initial_position = {-1.5, 0, 15};
  u1.sees_lead = u1.altimeter = u1.range = true;
  UavSpec u2;
  u2.name = "uav2";
  u2.initial_position = {1.5, 0, 17};
  return {u1, u2};
}

std::vector<Scenario> parse_document(const Ctx& ctx, const YAML::Node& root) {
  const std::vector<std::string_view> top_keys = {
      "name",  "duration",  "rate",   "seed",    "measurements", "lead",    "uavs",
      "noise", "landmarks", "phases", "outages", "estimator",    "control",
      "variants", "world", "frontend"};
  if (!root.IsMap()) {
    ctx.fail(root.Mark(), "",
             fmt::format("expected a map of scenario settings at the top level, got {}",
                         describe(root)));
  }
  const MapView top(ctx, Field{root, root.Mark(), ""}, top_keys);

  Scenario base;
  base.source_path = ctx.origin();
  base.name = std::filesystem::path(ctx.origin()).stem().string();
  if (base.name.empty()) base.name = "scenario";
  base.uavs = paper_uavs();
  Provenance prov;

  if (auto f = top.get("name")) base.name = read_string(ctx, *f);
  num(ctx, top, "rate", base.rate, in(0, 1000, true, false));
  if (auto f = top.get("measurements")) {
    const std::string& s = scalar_of(ctx, *f, "a measurement mode");
    if (s == "synthetic")
      base.measurements = MeasurementMode::Synthetic;
    else if (s == "rendered")
      base.measurements = MeasurementMode::Rendered;
    else
      ctx.fail(f->loc(), fmt::format(
                             "unknown measurement mode '{}' (expected 'synthetic' or 'rendered')", s));
  }
  if (auto f = top.get("lead")) parse_lead(ctx, *f, base.lead);
  if (auto f = top.get("uavs")) parse_uavs(ctx, *f, base.uavs, prov);
  if (auto f = top.get("world")) parse_world(ctx, *f, base.world);
  apply_common(ctx, top, base, prov);

  std::vector<Scenario> out;
  const auto vf = top.get("variants");
  if (!vf) {
    finalise(ctx, base, prov);
    out.push_back(std::move(base));
    return out;
  }
  if (!vf->node.IsSequence())
    ctx.fail(vf->loc(), fmt::format("expected a list of variants, got {}", describe(vf->node)));
  if (vf->node.size() == 0) ctx.fail(vf->loc(), "expected at least one variant");

  std::vector<std::string_view> variant_keys = {"name"};
  variant_keys.insert(variant_keys.end(), kCommonKeys.begin(), kCommonKeys.end());
  const auto note = [&](const std::string& key) -> std::string {
    if (std::find(top_keys.begin(), top_keys.end(), key) == top_keys.end()) return "";
    return fmt::format(" (a variant may set only {})", join(variant_keys));
  };
  std::vector<Loc> name_locs;
  for (std::size_t i = 0; i < vf->node.size(); ++i) {
    const Field item{vf->node[i], vf->key_mark, index_path(vf->path, i)};
    const MapView m(ctx, item, variant_keys, note);
    const Field nf = m.require("name", item.loc());
    const std::string name = read_string(ctx, nf);
    if (!name_ok(name, true))
      ctx.fail(nf.loc(), fmt::format("variant names must match [a-z0-9_-]+, got '{}'", name));
    for (std::size_t j = 0; j < out.size(); ++j) {
      if (out[j].variant == name)
        ctx.fail(nf.loc(), fmt::format("duplicate variant name '{}' (first at line {})", name,
                                       name_locs[j].mark.line + 1));
    }
    Scenario v = base;
    Provenance vp = prov;
    v.variant = name;
    apply_common(ctx, m, v, vp);
    finalise(ctx, v, vp);
    out.push_back(std::move(v));
    name_locs.push_back(nf.loc());
  }
  return out;
}

}  // namespace

std::vector<Scenario> parse_scenarios(const std::string& yaml_text, const std::string& origin) {
  const Ctx ctx(origin);
  std::vector<YAML::Node> docs;
  try {
    docs = YAML::LoadAll(yaml_text);
  } catch (const YAML::ParserException& e) {
    ctx.fail(e.mark, "", fmt::format("YAML syntax error: {}", e.msg));
  } catch (const YAML::Exception& e) {
    ctx.fail(e.mark, "", fmt::format("YAML error: {}", e.msg));
  }
  if (docs.size() > 1)
    ctx.fail(docs[1].Mark(), "", "more than one YAML document; a scenario file holds exactly one");
  if (docs.empty() || docs[0].IsNull())
    throw ScenarioError(
        fmt::format("{}: empty document: expected a map of scenario settings", origin));
  try {
    return parse_document(ctx, docs[0]);
  } catch (const YAML::Exception& e) {  // should not happen: every access is checked
    ctx.fail(e.mark, "", fmt::format("YAML error: {}", e.msg));
  }
}

std::vector<Scenario> load_scenarios(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))
    throw ScenarioError(fmt::format("{}: cannot read scenario: {}", path, std::strerror(EISDIR)));
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    const int err = errno;
    throw ScenarioError(
        fmt::format("{}: cannot read scenario: {}", path, std::strerror(err != 0 ? err : ENOENT)));
  }
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) {
    const int err = errno;
    throw ScenarioError(
        fmt::format("{}: cannot read scenario: {}", path, std::strerror(err != 0 ? err : EIO)));
  }
  return parse_scenarios(text.str(), path);
}

}  // namespace wingman::sim
