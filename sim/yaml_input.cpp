// The strict YAML input of sim/yaml_input.hpp.
#include "sim/yaml_input.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cmath>

#include "sim/scenario.hpp"

namespace wingman::sim {

namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();

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
}  // namespace

namespace {
std::size_t utf8_sequence(const std::string& s, std::size_t i);
}  // namespace

std::string printable(const std::string& s) {
  std::string out;
  for (std::size_t i = 0; i < s.size();) {
    const unsigned char c = static_cast<unsigned char>(s[i]);
    const std::size_t n = utf8_sequence(s, i);
    if (n == 0 || c < 0x20 || c == 0x7f) {
      out += fmt::format("\\x{:02x}", c);
      ++i;
    } else {
      out.append(s, i, n);
      i += n;
    }
  }
  return out;
}

void Ctx::fail(const YAML::Mark& m, const std::string& path, const std::string& raw_what) const {
  const std::string what = printable(raw_what);  // a message never echoes raw bytes of the input
  std::string where = origin_;
  if (!m.is_null() && m.line >= 0) where += fmt::format(":{}:{}", m.line + 1, m.column + 1);
  if (path.empty()) throw ScenarioError(fmt::format("{}: {}", where, what));
  throw ScenarioError(fmt::format("{}: {}: {}", where, path, what));
}

std::string Ctx::where(const Loc& l) const {
  std::string w = origin_;
  if (!l.mark.is_null() && l.mark.line >= 0) w += fmt::format(":{}", l.mark.line + 1);
  return l.path.empty() ? w : fmt::format("{}: {}", w, l.path);
}



std::string describe(const YAML::Node& n) {
  if (!n.IsDefined() || n.IsNull()) return "nothing";
  if (n.IsScalar()) return fmt::format("'{}'", n.Scalar());
  if (n.IsSequence()) return "a list";
  if (n.IsMap()) return "a map";
  return "something else";
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

std::string join(const std::vector<std::string_view>& v, std::string_view sep) {
  std::string out;
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (i) out += sep;
    out += v[i];
  }
  return out;
}

Loc Field::loc() const {
  // An empty value (`key:` with nothing after it) is reported at its key: yaml-cpp places the
  // null where the next token starts, often on the following line.
  YAML::Mark m = node.IsDefined() && !node.IsNull() ? node.Mark() : YAML::Mark::null_mark();
  if (m.is_null()) m = key_mark;
  return {m, path};
}

std::string child_path(const std::string& parent, std::string_view key) {
  return parent.empty() ? std::string(key) : fmt::format("{}.{}", parent, key);
}

std::string index_path(const std::string& parent, std::size_t i) {
  return fmt::format("{}[{}]", parent, i);
}

MapView::MapView(const Ctx& ctx, const Field& f, std::vector<std::string_view> allowed,
                 const UnknownNote& note)
    : MapView(ctx, f, std::move(allowed), note, true) {}

MapView MapView::open(const Ctx& ctx, const Field& f) { return MapView(ctx, f, {}, {}, false); }

MapView::MapView(const Ctx& ctx, const Field& f, std::vector<std::string_view> allowed,
                 const UnknownNote& note, bool check_known)
    : ctx_(ctx), path_(f.path) {
  if (!f.node.IsMap()) ctx.fail(f.loc(), fmt::format("expected a map, got {}", describe(f.node)));
  for (auto it = f.node.begin(); it != f.node.end(); ++it) {
    const YAML::Node key = it->first;
    if (!key.IsScalar())
      ctx.fail(key.Mark(), path_, fmt::format("expected a plain key, got {}", describe(key)));
    const std::string name = key.Scalar();
    const std::string path = child_path(path_, name);
    for (const Field& seen : fields_) {
      if (seen.path == path)
        ctx.fail(key.Mark(), path,
                 fmt::format("duplicate key '{}' (first at line {})", name, seen.key_mark.line + 1));
    }
    if (check_known && std::find(allowed.begin(), allowed.end(), name) == allowed.end()) {
      std::string extra = note ? note(name) : std::string();
      if (extra.empty()) extra = suggestion(name, allowed);
      ctx.fail(key.Mark(), path, fmt::format("unknown key '{}'{}", name, extra));
    }
    fields_.push_back(Field{it->second, key.Mark(), path});
    names_.push_back(name);
  }
}

std::optional<Field> MapView::get(std::string_view key) const {
  for (std::size_t i = 0; i < names_.size(); ++i)
    if (names_[i] == key) return fields_[i];
  return std::nullopt;
}

Field MapView::require(std::string_view key, const Loc& map_loc) const {
  if (auto f = get(key)) return *f;
  ctx_.fail(map_loc, fmt::format("missing required key '{}'", key));
}

// ---- Scalars ---------------------------------------------------------------------------------


const std::string& scalar_of(const Ctx& ctx, const Field& f, std::string_view expected) {
  if (!f.node.IsScalar())
    ctx.fail(f.loc(), fmt::format("expected {}, got {}", expected, describe(f.node)));
  return f.node.Scalar();
}

double read_number(const Ctx& ctx, const Field& f, Bounds b) {
  std::string s = scalar_of(ctx, f, "a number");
  std::string_view sv = s;
  if (!sv.empty() && sv.front() == '+') sv.remove_prefix(1);
  double v = 0;
  const auto [p, ec] = std::from_chars(sv.data(), sv.data() + sv.size(), v);
  if (sv.empty() || ec != std::errc() || p != sv.data() + sv.size())
    ctx.fail(f.loc(), fmt::format("expected a number, got '{}'", s));
  if (!std::isfinite(v)) ctx.fail(f.loc(), fmt::format("expected a finite number, got '{}'", s));
  if (!b.ok(v)) ctx.fail(f.loc(), fmt::format("must be {}, got {}", bounds_text(b), s));
  // No setting is a physical quantity this large; a value past it is a typo or a probe, and
  // would turn into inf or NaN somewhere in the run.
  if (std::abs(v) > kMaxMagnitude && !(std::isfinite(b.hi) && std::abs(v) <= std::abs(b.hi)))
    ctx.fail(f.loc(), fmt::format("{} is beyond any setting's scale (magnitude at most {:g})", s, kMaxMagnitude));
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

int read_int(const Ctx& ctx, const Field& f, int lo, int hi) {
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

geometry::SeedSetting read_seed_setting(const Ctx& ctx, const Field& f) {
  const std::string s = scalar_of(ctx, f, "an integer or per_run");
  if (s == "per_run") return {true, 1};
  if (s.empty() || s.find_first_not_of("+-0123456789") != std::string::npos)
    ctx.fail(f.loc(), fmt::format("expected an integer or per_run, got '{}'", s));
  return {false, read_seed(ctx, f)};
}

bool read_bool(const Ctx& ctx, const Field& f) {
  const std::string& s = scalar_of(ctx, f, "true or false");
  if (s == "true" || s == "True" || s == "TRUE") return true;
  if (s == "false" || s == "False" || s == "FALSE") return false;
  ctx.fail(f.loc(), fmt::format("expected true or false, got '{}'", s));
}

namespace {

// Length of the well-formed UTF-8 sequence at s[i] (no overlong forms, surrogates or code points
// past U+10FFFF), or 0.
std::size_t utf8_sequence(const std::string& s, std::size_t i) {
  const unsigned char c = static_cast<unsigned char>(s[i]);
  const int n = c < 0x80 ? 0 : (c >> 5) == 0x6 ? 1 : (c >> 4) == 0xe ? 2 : (c >> 3) == 0x1e ? 3 : -1;
  if (n < 0 || i + n >= s.size()) return 0;
  std::uint32_t cp = n == 0 ? c : c & (0x3f >> n);
  for (int k = 1; k <= n; ++k) {
    const unsigned char d = static_cast<unsigned char>(s[i + k]);
    if ((d >> 6) != 0x2) return 0;
    cp = (cp << 6) | (d & 0x3f);
  }
  const std::uint32_t min[] = {0, 0x80, 0x800, 0x10000};
  if (cp < min[n] || cp > 0x10ffff || (cp >= 0xd800 && cp <= 0xdfff)) return 0;
  return static_cast<std::size_t>(n) + 1;
}

bool valid_utf8(const std::string& s) {
  for (std::size_t i = 0; i < s.size();) {
    const std::size_t n = utf8_sequence(s, i);
    if (n == 0) return false;
    i += n;
  }
  return true;
}

}  // namespace

std::string read_string(const Ctx& ctx, const Field& f) {
  const std::string& s = scalar_of(ctx, f, "a string");
  if (s.empty()) ctx.fail(f.loc(), "expected a non-empty string");
  if (s.size() > kMaxStringBytes)
    ctx.fail(f.loc(), fmt::format("a string of {} bytes; at most {}", s.size(), kMaxStringBytes));
  if (!valid_utf8(s)) ctx.fail(f.loc(), "not valid UTF-8 text");
  return s;
}

namespace {

// A list of exactly N numbers, each within b; `scalar_too`: one number stands for all N.
template <int N>
Eigen::Matrix<double, N, 1> read_list(const Ctx& ctx, const Field& f, Bounds b, bool scalar_too,
                                      const char* what) {
  if (scalar_too && f.node.IsScalar()) return Eigen::Matrix<double, N, 1>::Constant(read_number(ctx, f, b));
  if (!f.node.IsSequence() || f.node.size() != N) {
    ctx.fail(f.loc(), fmt::format("expected {}, got {}", what,
                                  f.node.IsSequence() ? fmt::format("a list of {}", f.node.size())
                                                      : describe(f.node)));
  }
  Eigen::Matrix<double, N, 1> v;
  for (std::size_t i = 0; i < N; ++i)
    v[static_cast<Eigen::Index>(i)] = read_number(ctx, Field{f.node[i], f.key_mark, index_path(f.path, i)}, b);
  return v;
}

}  // namespace

Eigen::Vector3d read_vec3(const Ctx& ctx, const Field& f, Bounds b) {
  return read_list<3>(ctx, f, b, false, "a list of 3 numbers");
}

geometry::Distortion read_distortion(const Ctx& ctx, const Field& f) {
  const YAML::Node& n = f.node;
  if (!n.IsSequence() || (n.size() != 4 && n.size() != 5)) {
    ctx.fail(f.loc(), fmt::format("expected a list of 4 or 5 numbers (k1 k2 p1 p2 [k3]), got {}",
                                  n.IsSequence() ? fmt::format("a list of {}", n.size()) : describe(n)));
  }
  double k[5] = {0, 0, 0, 0, 0};
  for (std::size_t i = 0; i < n.size(); ++i) k[i] = read_number(ctx, Field{n[i], f.key_mark, index_path(f.path, i)});
  return geometry::Distortion{k[0], k[1], k[2], k[3], k[4]};
}
Eigen::Vector4d read_vec4(const Ctx& ctx, const Field& f, Bounds b) {
  return read_list<4>(ctx, f, b, true, "a number or a list of 4 numbers (x, y, z, yaw)");
}

Waypoints read_waypoints(const Ctx& ctx, const Field& f) {
  // An empty list is no waypoints (what the resolved settings print for other trajectories).
  if (!f.node.IsSequence() || f.node.size() == 1)
    ctx.fail(f.loc(), fmt::format("expected a list of at least 2 waypoints [t, x, y, z], got {}",
                                  f.node.IsSequence() ? fmt::format("a list of {}", f.node.size()) : describe(f.node)));
  Waypoints w;
  for (std::size_t i = 0; i < f.node.size(); ++i) {
    const Field row{f.node[i], f.key_mark, index_path(f.path, i)};
    const Eigen::Vector4d r = read_list<4>(ctx, row, any_value(), false, "a waypoint [t, x, y, z]");
    if (r[0] < 0) ctx.fail(row.loc(), fmt::format("time {} is negative; times are seconds from the start", r[0]));
    if (!w.rows.empty() && !(r[0] > w.rows.back()[0]))
      ctx.fail(row.loc(), fmt::format("time {} is not after the previous waypoint's ({}); waypoints must be "
                                      "in increasing time order", r[0], w.rows.back()[0]));
    w.rows.push_back(r);
  }
  return w;
}

namespace {
const std::vector<std::string_view> kSensorNames = {"landmarks", "lead_projection", "altimeter",
                                                    "range", "gps"};

}  // namespace

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

}  // namespace wingman::sim

namespace wingman::sim::settings_detail {

int to_int_bound(double v, int fallback) {
  if (!std::isfinite(v)) return fallback;
  return static_cast<int>(std::max<double>(std::numeric_limits<int>::min(),
                                           std::min<double>(std::numeric_limits<int>::max(), v)));
}

}  // namespace wingman::sim::settings_detail
