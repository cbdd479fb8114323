// Walkers of settings structs (geometry/settings.hpp) over YAML: read_settings fills a struct from
// one map of a scenario file, strictly (sim/yaml_input.hpp: unknown keys with a "did you mean",
// duplicate keys, types and ranges, each naming file:line:col and the key path); emit_settings
// writes the resolved values back as YAML.
#pragma once

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <Eigen/Core>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "geometry/camera.hpp"
#include "geometry/settings.hpp"
#include "sim/control_spec.hpp"
#include "sim/sensors.hpp"
#include "sim/trajectory.hpp"
#include "sim/yaml_input.hpp"

namespace wingman::sim {

// Where each key that was read came from, by key path ("estimator.map.max_landmarks").
using KeyLocations = std::map<std::string, Loc>;

// A number as settings print it: the shortest text that reads back to the same double.
inline std::string number_text(double x) { return fmt::format("{}", x); }

// A fixed-length vector as a flow list of such numbers.
template <int N>
void emit_numbers(YAML::Emitter& out, const Eigen::Matrix<double, N, 1>& v) {
  out << YAML::Flow << YAML::BeginSeq;
  for (int i = 0; i < N; ++i) out << number_text(v[i]);
  out << YAML::EndSeq;
}

namespace settings_detail {

// First pass over one map level: the keys it accepts.
struct KeyLister {
  std::vector<std::string_view> keys;
  template <typename T, typename... Rest>
  void operator()(std::string_view key, T&, Rest&&...) { keys.push_back(key); }
  template <typename E>
  void choice(std::string_view key, E&, geometry::Choices<E>) { keys.push_back(key); }
  template <typename Fn>
  void section(std::string_view key, Fn&&) { keys.push_back(key); }
  void pair(std::string_view key, int&, int&, geometry::Bounds = {}) { keys.push_back(key); }
  void check(std::string_view, bool, std::string_view) {}
  void other(std::string_view key) { keys.push_back(key); }
  void required(std::string_view) {}
  template <typename T>
  void optional(std::string_view key, T&) { keys.push_back(key); }
  template <typename T>
  void list(std::string_view key, std::vector<T>&, geometry::ListNames) { keys.push_back(key); }
};

// A list's item before it is read: T::list_item(i) where T has one (a default that depends on
// the position), else T{}.
template <typename T>
T list_item(std::size_t i) {
  if constexpr (requires { T::list_item(i); })
    return T::list_item(i);
  else
    return T{};
}

int to_int_bound(double v, int fallback);

// A map whose other keys another reader checks (the control: section's, sim's and app's).
struct OpenMap {};

// Second pass: reads the keys present in the map.
class Reader {
 public:
  Reader(const Ctx& ctx, const Field& f, std::vector<std::string_view> keys, KeyLocations* where)
      : ctx_(ctx), map_(ctx, f, std::move(keys)), map_loc_(f.loc()), where_(where) {}
  Reader(const Ctx& ctx, const Field& f, KeyLocations* where, OpenMap)
      : ctx_(ctx), map_(MapView::open(ctx, f)), map_loc_(f.loc()), where_(where) {}

  void operator()(std::string_view key, double& x, geometry::Bounds b = {}) {
    if (auto f = get(key)) x = read_number(ctx_, *f, b);
  }
  void operator()(std::string_view key, float& x, geometry::Bounds b = {}) {
    if (auto f = get(key)) x = static_cast<float>(read_number(ctx_, *f, b));
  }
  void operator()(std::string_view key, int& x, geometry::Bounds b = {}) {
    if (auto f = get(key))
      x = read_int(ctx_, *f, to_int_bound(b.lo, std::numeric_limits<int>::min()),
                   to_int_bound(b.hi, std::numeric_limits<int>::max()));
  }
  void operator()(std::string_view key, bool& x) {
    if (auto f = get(key)) x = read_bool(ctx_, *f);
  }
  void operator()(std::string_view key, std::string& x) {
    if (auto f = get(key)) x = read_string(ctx_, *f);
  }
  void operator()(std::string_view key, Eigen::Vector3d& x, geometry::Bounds b = {}) {
    if (auto f = get(key)) x = read_vec3(ctx_, *f, b);
  }
  void operator()(std::string_view key, geometry::Distortion& x) {
    if (auto f = get(key)) x = read_distortion(ctx_, *f);
  }
  void operator()(std::string_view key, geometry::SeedSetting& x) {
    if (auto f = get(key)) x = read_seed_setting(ctx_, *f);
  }
  void operator()(std::string_view key, geometry::AutoNumber& x, geometry::Bounds b = {}) {
    auto f = get(key);
    if (!f) return;
    if (f->node.IsScalar() && f->node.Scalar() == "auto") {
      x.automatic = true;
      x.source.clear();
      return;
    }
    x = read_number(ctx_, *f, b);
  }
  // A key of this map that another reader reads.
  void other(std::string_view) {}
  // A condition on values already read: fails at `key`, or at item i of a list written
  // `key[i]` (at the map when the key is absent).
  void check(std::string_view key, bool ok, std::string_view what) {
    if (!ok) ctx_.fail(key_loc(key), std::string(what));
  }
  void required(std::string_view key) {
    if (!map_.get(key)) ctx_.fail(map_loc_, fmt::format("missing required key '{}'", key));
  }
  void optional(std::string_view key, std::string& x) { (*this)(key, x); }
  void optional(std::string_view key, std::optional<std::uint64_t>& x) {
    if (auto f = get(key)) x = read_seed(ctx_, *f);
  }
  void operator()(std::string_view key, YawSetpoint& x, geometry::Bounds b = {}) {
    auto f = get(key);
    if (!f) return;
    const bool scalar = f->node.IsScalar() && !f->node.Scalar().empty();
    const std::string s = scalar ? f->node.Scalar() : std::string();
    if (s == "lead_bearing")
      x.yaw.reset();
    else if (scalar && (std::isdigit(static_cast<unsigned char>(s[0])) || std::string_view("+-.").find(s[0]) != std::string_view::npos))
      x.yaw = read_number(ctx_, *f, b);
    else
      ctx_.fail(f->loc(), fmt::format("expected lead_bearing or a yaw in radians, got {}", describe(f->node)));
  }
  void operator()(std::string_view key, Sensor& x) {
    if (auto f = get(key)) x = read_sensor(ctx_, *f);
  }
  void operator()(std::string_view key, std::vector<Sensor>& x) {
    if (auto f = get(key)) x = read_sensor_list(ctx_, *f);
  }
  void operator()(std::string_view key, Config& x) {
    if (auto f = get(key)) x = read_config(ctx_, *f);
  }
  template <typename T>
  void list(std::string_view key, std::vector<T>& items, geometry::ListNames names) {
    if (auto f = get(key)) read_list(ctx_, *f, items, names, where_);
  }
  // Fills `items` from the list `f`, one map per item, each through T's visit().
  template <typename T>
  static void read_list(const Ctx& ctx, const Field& f, std::vector<T>& items, geometry::ListNames names,
                        KeyLocations* where) {
    if (!f.node.IsSequence())
      ctx.fail(f.loc(), fmt::format("expected a list of {}, got {}", names.plural, describe(f.node)));
    if (f.node.size() < names.min_items) ctx.fail(f.loc(), fmt::format("expected at least one {}", names.singular));
    items.clear();
    for (std::size_t i = 0; i < f.node.size(); ++i) {
      const Field item{f.node[i], f.key_mark, index_path(f.path, i)};
      if (where) (*where)[item.path] = item.loc();
      T x = list_item<T>(i);
      auto fn = [&](auto& v) { x.visit(v); };
      read_map(ctx, item, fn, where);
      items.push_back(std::move(x));
    }
  }
  void operator()(std::string_view key, Eigen::Vector4d& x, geometry::Bounds b = {}) {
    if (auto f = get(key)) x = read_vec4(ctx_, *f, b);
  }
  void operator()(std::string_view key, OptionalPath& x) {
    auto f = get(key);
    if (f) x.value = f->node.IsScalar() && f->node.Scalar().empty() ? std::string() : read_string(ctx_, *f);
  }
  void operator()(std::string_view key, Waypoints& x) {
    if (auto f = get(key)) x = read_waypoints(ctx_, *f);
  }
  template <typename E>
  void choice(std::string_view key, E& x, geometry::Choices<E> choices) {
    auto f = get(key);
    if (!f) return;
    std::vector<std::string_view> names;
    for (const auto& [name, value] : choices) names.push_back(name);
    const std::string& s = scalar_of(ctx_, *f, fmt::format("one of {}", join(names)));
    for (const auto& [name, value] : choices)
      if (s == name) {
        x = value;
        return;
      }
    ctx_.fail(f->loc(), fmt::format("expected one of {}, got '{}'{}", join(names), s, suggestion(s, names)));
  }
  template <typename Fn>
  void section(std::string_view key, Fn&& fn) {
    if (auto f = get(key)) read_map(ctx_, *f, fn, where_);
  }
  // Two integers written as [a, b].
  void pair(std::string_view key, int& a, int& b, geometry::Bounds bounds = {}) {
    auto f = get(key);
    if (!f) return;
    if (!f->node.IsSequence() || f->node.size() != 2)
      ctx_.fail(f->loc(), fmt::format("expected a list of 2 integers, got {}", describe(f->node)));
    int* out[2] = {&a, &b};
    for (std::size_t i = 0; i < 2; ++i)
      *out[i] = read_int(ctx_, Field{f->node[i], f->key_mark, index_path(f->path, i)},
                         to_int_bound(bounds.lo, std::numeric_limits<int>::min()),
                         to_int_bound(bounds.hi, std::numeric_limits<int>::max()));
  }

  template <typename Fn>
  static void read_map(const Ctx& ctx, const Field& f, Fn& fn, KeyLocations* where) {
    KeyLister lister;
    fn(lister);
    Reader r(ctx, f, std::move(lister.keys), where);
    fn(r);
  }

 private:
  std::optional<Field> get(std::string_view key) {
    auto f = map_.get(key);
    if (f && where_) (*where_)[f->path] = f->loc();
    return f;
  }
  Loc key_loc(std::string_view key) const {
    const std::size_t bracket = key.find('[');
    const auto f = map_.get(key.substr(0, bracket));
    if (!f) return Loc{map_loc_.mark, child_path(map_loc_.path, key)};
    if (bracket == std::string_view::npos) return f->loc();
    const std::size_t i = static_cast<std::size_t>(std::atol(std::string(key.substr(bracket + 1)).c_str()));
    if (!f->node.IsSequence() || i >= f->node.size()) return f->loc();
    return Field{f->node[i], f->key_mark, index_path(f->path, i)}.loc();
  }
  const Ctx& ctx_;
  MapView map_;
  Loc map_loc_;
  KeyLocations* where_;
};

// Writes every key with its value, sections as nested maps.
class Emitter {
 public:
  explicit Emitter(YAML::Emitter& out) : out_(out) {}
  template <typename T, typename... Rest>
  void operator()(std::string_view key, const T& x, Rest&&...) {
    out_ << YAML::Key << std::string(key) << YAML::Value;
    put(x);
  }
  template <typename E>
  void choice(std::string_view key, const E& x, geometry::Choices<E> choices) {
    for (const auto& [name, value] : choices)
      if (value == x) out_ << YAML::Key << std::string(key) << YAML::Value << std::string(name);
  }
  template <typename Fn>
  void section(std::string_view key, Fn&& fn) {
    out_ << YAML::Key << std::string(key) << YAML::Value << YAML::BeginMap;
    fn(*this);
    out_ << YAML::EndMap;
  }
  void check(std::string_view, bool, std::string_view) {}
  void other(std::string_view) {}
  void required(std::string_view) {}
  void optional(std::string_view key, const std::string& x) {
    if (!x.empty()) out_ << YAML::Key << std::string(key) << YAML::Value << x;
  }
  void optional(std::string_view key, const std::optional<std::uint64_t>& x) {
    if (x) out_ << YAML::Key << std::string(key) << YAML::Value << *x;
  }
  // A list of sensors is left out when empty (nothing added, nothing removed).
  void operator()(std::string_view key, const std::vector<Sensor>& x) {
    if (x.empty()) return;
    out_ << YAML::Key << std::string(key) << YAML::Value << YAML::Flow << YAML::BeginSeq;
    for (Sensor s : x) out_ << to_string(s);
    out_ << YAML::EndSeq;
  }
  // Each item as a flow map on a line of its own.
  template <typename T>
  void list(std::string_view key, const std::vector<T>& items, geometry::ListNames) {
    out_ << YAML::Key << std::string(key) << YAML::Value << YAML::BeginSeq;
    for (const T& item : items) {
      T copy = item;
      out_ << YAML::Flow << YAML::BeginMap;
      copy.visit(*this);
      out_ << YAML::EndMap;
    }
    out_ << YAML::EndSeq;
  }
  void pair(std::string_view key, int a, int b, geometry::Bounds = {}) {
    out_ << YAML::Key << std::string(key) << YAML::Value << YAML::Flow << YAML::BeginSeq << a << b
         << YAML::EndSeq;
  }

 private:
  void put(double x) { out_ << number_text(x); }
  void put(float x) { out_ << fmt::format("{}", x); }
  void put(int x) { out_ << x; }
  void put(bool x) { out_ << (x ? "true" : "false"); }
  void put(const std::string& x) { out_ << x; }
  void put(Sensor s) { out_ << to_string(s); }
  void put(const YawSetpoint& y) { out_ << (y.yaw ? number_text(*y.yaw) : std::string("lead_bearing")); }
  void put(Config c) { out_ << to_string(c); }
  // A derived value prints as the number with its origin as a comment, so that the file reruns
  // the same; one not yet derived prints as `auto`.
  void put(const geometry::AutoNumber& a) {
    if (a.automatic && a.source.empty())
      out_ << "auto";
    else if (a.automatic)
      out_ << number_text(a.value) << YAML::Comment(a.source);
    else
      out_ << number_text(a.value);
  }
  void put(const geometry::SeedSetting& s) {
    if (s.per_run)
      out_ << "per_run";
    else
      out_ << s.value;
  }
  void put(const OptionalPath& p) { out_ << YAML::DoubleQuoted << p.value; }
  void put(const Waypoints& w) {
    out_ << YAML::BeginSeq;
    for (const auto& r : w.rows) emit_numbers(out_, r);
    out_ << YAML::EndSeq;
  }
  void put(const geometry::Distortion& d) { put(Eigen::Matrix<double, 5, 1>(d.k1, d.k2, d.p1, d.p2, d.k3)); }
  template <int N>
  void put(const Eigen::Matrix<double, N, 1>& v) {
    emit_numbers(out_, v);
  }
  YAML::Emitter& out_;
};

}  // namespace settings_detail

// Fills `settings` from the map `f`; keys absent keep their values.
template <typename S>
void read_settings(const Ctx& ctx, const Field& f, S& settings, KeyLocations* where = nullptr) {
  auto fn = [&](auto& v) { settings.visit(v); };
  settings_detail::Reader::read_map(ctx, f, fn, where);
}

// The same for a map whose other keys another reader checks.
template <typename S>
void read_settings_open(const Ctx& ctx, const Field& f, S& settings, KeyLocations* where = nullptr) {
  settings_detail::Reader r(ctx, f, where, settings_detail::OpenMap{});
  settings.visit(r);
}

// Writes `settings` as the value of `key` in the map being emitted.
template <typename S>
void emit_settings(YAML::Emitter& out, std::string_view key, const S& settings) {
  S copy = settings;  // visit() is one list for reading and writing, so it takes a mutable struct
  settings_detail::Emitter e(out);
  e.section(key, [&](auto& v) { copy.visit(v); });
}

}  // namespace wingman::sim
