// Strict YAML loader for scenarios (docs/design.md, files): unknown keys, duplicate keys, wrong types and
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

#include "sim/assets.hpp"
#include "sim/budget.hpp"
#include "sim/scenario.hpp"
#include "sim/settings_yaml.hpp"
#include "sim/yaml_input.hpp"

namespace wingman::sim {

namespace {

constexpr double kTimeEps = 1e-9;


// Names become directory and file names and JSON keys: short, and plain ASCII.
constexpr std::size_t kMaxNameLength = 64;

bool name_ok(const std::string& s, bool allow_dash) {
  if (s.empty() || s.size() > kMaxNameLength) return false;
  for (char c : s) {
    const bool ok =
        (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_' || (allow_dash && c == '-');
    if (!ok) return false;
  }
  return true;
}

bool scenario_name_ok(const std::string& s) {
  if (s.empty() || s.size() > kMaxNameLength || s.front() == '.' || s.front() == '-') return false;
  return std::all_of(s.begin(), s.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
           c == '.' || c == '-';
  });
}

// A name as a message may print it: at most 80 bytes of it.
std::string short_name(const std::string& s) {
  return s.size() > 80 ? s.substr(0, 80) + fmt::format("... ({} bytes)", s.size()) : s;
}

// Helpers that assign a key's value when the key is present.
template <typename T, typename Read>
std::optional<Field> set_if(const MapView& m, std::string_view key, T& target, Read read) {
  auto f = m.get(key);
  if (f) target = read(*f);
  return f;
}

std::optional<Field> num(const Ctx& ctx, const MapView& m, std::string_view key, double& target,
                         Bounds b = any_value()) {
  return set_if(m, key, target, [&](const Field& f) { return read_number(ctx, f, b); });
}

// ---- Provenance: where the values that cross-field checks look at came from -----------------

struct Provenance {
  Loc uavs;  // the uavs list, if given
  bool phases_given = false;
  std::vector<Loc> phase_to;      // per phase, its `to` value
  std::vector<Loc> outage_agent;  // per outage, its `agent` value (invalid when absent)
  KeyLocations keys;              // size-driving keys as set: "duration", "landmarks.density", ...
  Loc control_uavs;               // control.uavs, or the control section, if given
};

// Where a key was set, or its path marked as a default.
Loc key_loc(const Provenance& prov, const std::string& path) {
  if (auto it = prov.keys.find(path); it != prov.keys.end()) return it->second;
  return Loc{YAML::Mark::null_mark(), path + " (default)"};
}

// ---- Sections --------------------------------------------------------------------------------






void parse_uavs(const Ctx& ctx, const Field& f, std::vector<UavSpec>& uavs, Provenance& prov) {
  if (!f.node.IsSequence())
    ctx.fail(f.loc(), fmt::format("expected a list of UAVs, got {}", describe(f.node)));
  if (f.node.size() == 0) ctx.fail(f.loc(), "at least one UAV is needed");
  prov.uavs = f.loc();
  uavs.clear();
  std::vector<Loc> name_locs;
  for (std::size_t i = 0; i < f.node.size(); ++i) {
    const Field item{f.node[i], f.key_mark, index_path(f.path, i)};
    UavSpec u;
    KeyLocations where;
    read_settings(ctx, item, u, &where);
    if (u.name.empty()) ctx.fail(item.loc(), "missing required key 'name'");
    const Loc name_loc = where.at(child_path(item.path, "name"));
    if (u.name == "lead")
      ctx.fail(name_loc, "'lead' is reserved for the lead agent; choose another UAV name");
    if (!name_ok(u.name, false))
      ctx.fail(name_loc, fmt::format("UAV names must match [a-z0-9_]+ and be at most {} characters, got '{}'",
                                     kMaxNameLength, short_name(u.name)));
    for (std::size_t j = 0; j < uavs.size(); ++j) {
      if (uavs[j].name == u.name)
        ctx.fail(name_loc, fmt::format("duplicate UAV name '{}' (first at line {})", u.name,
                                       name_locs[j].mark.line + 1));
    }
    uavs.push_back(std::move(u));
    name_locs.push_back(name_loc);
    prov.keys.insert(where.begin(), where.end());
  }
}

// The phases as visit() reads them (sim/scenario.hpp), then what involves two of them: unique
// names, sorted and not overlapping.
void read_phases(const Ctx& ctx, const Field& f, std::vector<Phase>& phases, Provenance& prov) {
  KeyLocations where;
  settings_detail::Reader::read_list(ctx, f, phases, kPhaseList, &where);
  prov.phases_given = true;
  prov.phase_to.clear();
  auto at = [&](std::size_t i, const std::string& key) {
    const std::string item = index_path(f.path, i);
    const auto k = where.find(key.empty() ? item : child_path(item, key));
    return k != where.end() ? k->second : where.at(item);
  };
  for (std::size_t i = 0; i < phases.size(); ++i) {
    Phase& p = phases[i];
    p.source = index_path(f.path, i);
    p.source_line = at(i, "").mark.line + 1;
    for (std::size_t j = 0; j < i; ++j)
      if (phases[j].name == p.name)
        ctx.fail(at(i, "name"), fmt::format("duplicate phase name '{}' (first at line {})", p.name,
                                            at(j, "name").mark.line + 1));
    if (i > 0 && p.t_start < phases[i - 1].t_end - kTimeEps)
      ctx.fail(at(i, "from"), fmt::format("phase '{}' starts at {}, before the previous phase '{}' ends ({}); "
                                          "phases must be sorted and must not overlap",
                                          p.name, p.t_start, phases[i - 1].name, phases[i - 1].t_end));
    prov.phase_to.push_back(at(i, "to"));
  }
}

void read_outages(const Ctx& ctx, const Field& f, std::vector<Outage>& outages, Provenance& prov) {
  KeyLocations where;
  settings_detail::Reader::read_list(ctx, f, outages, kOutageList, &where);
  prov.outage_agent.clear();
  for (std::size_t i = 0; i < outages.size(); ++i) {
    const auto k = where.find(child_path(index_path(f.path, i), "agent"));
    prov.outage_agent.push_back(k != where.end() ? k->second : Loc{});
  }
}


// ---- control: (closed loop, paper section 6 and 7.3) ----------------------------------------

// A number for all four components of lambda = [lx, ly, lz, psi], or a list of four.

// The section's presence turns the closed loop on; every UAV of the scenario needs an entry
// (default: section 7.3's uav1 and uav2).
// Every controlled UAV is a UAV of the scenario and every UAV is controlled.
void check_control_uavs(const Ctx& ctx, const ControlSpec& c, const std::vector<UavSpec>& uavs, const Loc& where) {
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

void read_control(const Ctx& ctx, const Field& f, ControlSpec& c, const std::vector<UavSpec>& uavs,
                  Provenance& prov) {
  // The controller's keys (gains, switching, limits) are control::SlidingModeSettings', checked
  // and read by app/ from settings_layers; ControlSpec's are the truth's and the evaluation's.
  c.enabled = true;
  KeyLocations where;
  read_settings_open(ctx, f, c, &where);
  const std::string list = child_path(f.path, "uavs");
  const auto given = where.find(list);
  if (given == where.end() && c.uavs.empty()) c.uavs = paper_control_uavs();
  prov.control_uavs = given != where.end() ? given->second : f.key_loc();
  for (std::size_t i = 0; i < c.uavs.size() && given != where.end(); ++i)
    for (std::size_t j = 0; j < i; ++j)
      if (c.uavs[j].uav == c.uavs[i].uav)
        ctx.fail(where.at(child_path(index_path(list, i), "name")),
                 fmt::format("duplicate UAV '{}' (first at line {})", c.uavs[i].uav,
                             where.at(child_path(index_path(list, j), "name")).mark.line + 1));
  check_control_uavs(ctx, c, uavs, prov.control_uavs);
}

// The sections a variant may override; the top level parses them with the same code.
const std::vector<std::string_view> kCommonKeys = {"uavs", "seed", "duration", "noise",   "landmarks",
                                                   "phases",    "outages",  "estimator", "control",
                                                   "frontend"};

void apply_common(const Ctx& ctx, const MapView& m, Scenario& s, Provenance& prov) {
  if (auto f = m.get("uavs")) parse_uavs(ctx, *f, s.uavs, prov);
  if (auto f = m.get("seed")) s.seed = read_seed(ctx, *f);
  num(ctx, m, "duration", s.duration, gt(0));
  if (auto f = m.get("duration")) prov.keys["duration"] = f->loc();
  if (auto f = m.get("noise")) read_settings(ctx, *f, s.noise);
  if (auto f = m.get("landmarks")) read_settings(ctx, *f, s.field, &prov.keys);
  if (auto f = m.get("phases")) read_phases(ctx, *f, s.phases, prov);
  if (auto f = m.get("outages")) read_outages(ctx, *f, s.outages, prov);
  if (auto f = m.get("control")) read_control(ctx, *f, s.control, s.uavs, prov);
  for (std::string_view key : {"estimator", "control", "frontend"})
    if (auto f = m.get(key))
      s.settings_layers.push_back(std::make_shared<const SettingsLayer>(SettingsLayer{std::string(key), ctx, *f}));
}

// The run's size against what it drives and the machine (sim/budget.hpp).
void check_budget(const Ctx& ctx, const Scenario& s, const Provenance& prov) {
  using L = RunLimits;
  const double steps = s.duration * s.rate;
  if (!(steps <= L::kMaxSteps))
    ctx.fail(key_loc(prov, "duration"), fmt::format("{} s at rate {} Hz is {:.3g} steps; at most {:.3g}",
                                                    s.duration, s.rate, steps, L::kMaxSteps));
  if (std::llround(steps) < 1)
    ctx.fail(key_loc(prov, "duration"), fmt::format("{} s at rate {} Hz is shorter than one step ({} s): "
                                                    "the run would have no step", s.duration, s.rate, s.dt()));
  if (s.uavs.size() > static_cast<std::size_t>(L::kMaxUavs))
    ctx.fail(prov.uavs, fmt::format("{} UAVs; at most {}", s.uavs.size(), L::kMaxUavs));
  auto check_position = [&](const Eigen::Vector3d& p, const std::string& path) {
    if (p.cwiseAbs().maxCoeff() > L::kMaxCoordinate)
      ctx.fail(key_loc(prov, path), fmt::format("[{}, {}, {}] is farther than {:.3g} m from the origin in "
                                                "some axis", p.x(), p.y(), p.z(), L::kMaxCoordinate));
  };
  check_position(s.lead.initial_position, "lead.initial_position");
  for (std::size_t i = 0; i < s.uavs.size(); ++i)
    check_position(s.uavs[i].initial_position, fmt::format("uavs[{}].initial_position", i));
  const RunEstimate e = estimate_run(s);
  const std::string& type = s.lead.trajectory.type;
  const std::string traj = type == "line" ? "velocity" : type == "waypoints" ? "waypoints" : type == "file" ? "file" : "scale";
  if (!(e.extent_m <= 2 * L::kMaxCoordinate))
    ctx.fail(key_loc(prov, "lead.trajectory." + traj),
             fmt::format("the flight spans {:.3g} m; at most {:.3g}", e.extent_m, 2 * L::kMaxCoordinate));
  if (!(e.max_abs_z_m <= L::kMaxCoordinate))
    ctx.fail(key_loc(prov, "lead.trajectory.z_amplitude"),
             fmt::format("the flight reaches {:.3g} m from z = 0; at most {:.3g}", e.max_abs_z_m, L::kMaxCoordinate));
  const bool rendered = s.measurements == MeasurementMode::Rendered;
  if (!rendered && !(e.landmarks <= L::kMaxLandmarks))
    ctx.fail(key_loc(prov, "landmarks.density"),
             fmt::format("{} points/m^2 over the flight's {:.3g} m plus {} m of margin is {:.3g} "
                         "landmarks; at most {:.3g}", s.field.density, e.extent_m, s.field.margin,
                         e.landmarks, L::kMaxLandmarks));
  if (rendered && !(e.terrain_vertices <= L::kMaxTerrainVertices))
    ctx.fail(key_loc(prov, s.world.terrain.extent > 0 ? "world.terrain.extent" : "world.terrain.resolution"),
             fmt::format("the terrain mesh would have {:.3g} vertices; at most {:.3g} (raise resolution "
                         "or lower extent/margin)", e.terrain_vertices, L::kMaxTerrainVertices));
  if (rendered && !(e.pixels <= L::kMaxPixelsPerStep))
    ctx.fail(prov.uavs, fmt::format("the cameras have {:.3g} pixels in all; at most {:.3g}", e.pixels,
                                    L::kMaxPixelsPerStep));
  const double mem = memory_available();
  if (!(e.bytes <= mem))
    ctx.fail(key_loc(prov, "duration"),
             fmt::format("this run would need about {} of memory ({:.3g} steps, {:.3g} landmarks, {:.3g} "
                         "terrain vertices, {:.3g} pixels a step); this machine allows {}",
                         bytes_text(e.bytes), steps, rendered ? 0.0 : e.landmarks, e.terrain_vertices,
                         e.pixels, bytes_text(mem)));
  if (!(e.seconds <= L::kMaxSeconds))
    ctx.fail(key_loc(prov, "duration"),
             fmt::format("this run would take about {} on two cores ({:.3g} steps); at most {}",
                         duration_text(e.seconds), steps, duration_text(L::kMaxSeconds)));
}

// A camera's exposure and readout fit in its frame interval (sim/camera_sensor.hpp).
void check_cameras(const Ctx& ctx, const Scenario& s, const Provenance& prov) {
  for (std::size_t i = 0; i < s.uavs.size(); ++i) {
    const CameraSpec& c = s.uavs[i].camera;
    if (c.frame_time() <= s.dt()) continue;
    const std::string cam = fmt::format("uavs[{}].camera.", i);
    const bool auto_max = c.sensor.physical() && c.sensor.auto_exposure.enabled &&
                          c.sensor.auto_exposure.max_exposure > c.shutter.exposure;
    const std::string key = auto_max ? cam + "sensor.auto_exposure.max_exposure"
                            : c.shutter.exposure > 0 ? cam + "shutter.exposure" : cam + "shutter.line_delay";
    ctx.fail(key_loc(prov, key),
             fmt::format("exposure and readout take {:.4g} s, longer than the frame interval {:.4g} s "
                         "(rate {} Hz)", c.frame_time(), s.dt(), s.rate));
  }
}

// The spline of a `waypoints` or `file` trajectory; its start is the lead's initial position
// unless the scenario sets one.
void build_lead_path(const Ctx& ctx, Scenario& s, const Provenance& prov) {
  LeadTrajectorySpec& tr = s.lead.trajectory;
  if (!tr.spline()) {
    // Given, but for another type (the resolved settings print them empty).
    for (const auto& [key, given] : {std::pair{"waypoints", !tr.waypoints.rows.empty()},
                                     std::pair{"file", !tr.file.empty()}})
      if (given)
        ctx.fail(key_loc(prov, std::string("lead.trajectory.") + key),
                 fmt::format("is used by type {}; this trajectory's type is {}", key, tr.type));
    return;
  }
  const Loc type_loc = key_loc(prov, "lead.trajectory.type");
  std::vector<TrajectorySample> samples;
  if (tr.type == "waypoints") {
    if (tr.waypoints.rows.empty()) ctx.fail(type_loc, "type waypoints needs a list `waypoints` of [t, x, y, z]");
    for (const auto& r : tr.waypoints.rows) samples.push_back({r[0], r.tail<3>(), std::nullopt});
  } else {
    if (tr.file.empty()) ctx.fail(type_loc, "type file needs `file`: a TUM or CSV trajectory");
    const Loc file_loc = key_loc(prov, "lead.trajectory.file");
    std::optional<TrajectoryFormat> format = tr.format == "tum"   ? TrajectoryFormat::Tum
                                             : tr.format == "csv" ? TrajectoryFormat::Csv
                                                                  : format_from_extension(tr.file.value);
    if (!format)
      ctx.fail(file_loc, fmt::format("'{}': cannot tell its format from the extension (.tum, .txt, .csv); set "
                                     "lead.trajectory.format to tum or csv", tr.file.value));
    std::filesystem::path path(tr.file.value);
    if (path.is_relative()) path = std::filesystem::path(ctx.origin()).parent_path() / path;
    try {
      samples = read_trajectory_file(path.lexically_normal().string(), *format);
    } catch (const TrajectoryFileError& e) {
      ctx.fail(file_loc, e.what());
    }
    // The resolved settings (config.yaml) then name the file wherever they are read from.
    tr.file.value = std::filesystem::absolute(path).lexically_normal().string();
  }
  tr.path = std::make_shared<const SplinePath>(samples, tr.ends);
  if (!prov.keys.count("lead.initial_position")) s.lead.initial_position = tr.path->at(0).position;
}

// Defaults that depend on other fields, then the checks that involve the whole scenario.
void finalise(const Ctx& ctx, Scenario& s, const Provenance& prov) {
  build_lead_path(ctx, s, prov);
  // A variant's own uavs against the control section it inherits.
  if (s.control.enabled) check_control_uavs(ctx, s.control, s.uavs, prov.uavs.valid() ? prov.uavs : prov.control_uavs);
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
                           s.uav_names()));
  }
  check_budget(ctx, s, prov);
  check_cameras(ctx, s, prov);
}

std::vector<UavSpec> paper_uavs() {
  UavSpec u1;
  u1.name = "uav1";
  u1.initial_position = {-1.5, 0, 15};
  u1.sees_lead = u1.altimeter = u1.range = true;
  UavSpec u2;
  u2.name = "uav2";
  u2.initial_position = {1.5, 0, 17};
  u2.sees_lead = u2.altimeter = u2.range = false;
  return {u1, u2};
}

// A variant may light the world otherwise (the same flight under another sky: a condition of the
// frontend benchmark); the world's ground, objects and lead stay the base's.
void apply_variant_light(const Ctx& ctx, const MapView& m, Scenario& v) {
  const auto f = m.get("world");
  if (!f) return;
  const MapView w(ctx, *f, {"light"}, [](const std::string&) { return std::string(" (a variant may set only world.light)"); });
  if (auto light = w.get("light")) read_settings(ctx, *light, v.world.light);
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

  if (auto f = top.get("name")) {
    base.name = read_string(ctx, *f);
    if (!scenario_name_ok(base.name))
      ctx.fail(f->loc(), fmt::format("the scenario's name names its results directory: it must match "
                                     "[A-Za-z0-9_.-]+, not start with '.' or '-', and be at most {} "
                                     "characters, got '{}'", kMaxNameLength, short_name(base.name)));
  }
  num(ctx, top, "rate", base.rate, in(0, 1000, true, false));
  if (auto f = top.get("rate")) prov.keys["rate"] = f->loc();
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
  if (auto f = top.get("lead")) read_settings(ctx, *f, base.lead, &prov.keys);
  if (auto f = top.get("world")) read_settings(ctx, *f, base.world, &prov.keys);
  for (const char* key : {"world.texture.image", "world.lead.model"})
    if (auto it = prov.keys.find(key); it != prov.keys.end())
      base.world_file_keys[key] = {it->second.mark.line + 1, it->second.mark.column + 1};
  apply_common(ctx, top, base, prov);
  // A rendered run reads these files; a missing one is bad input, found before anything runs.
  if (base.measurements == MeasurementMode::Rendered) check_world_files(base);

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
  variant_keys.push_back("world");  // its light only: apply_variant_light
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
      ctx.fail(nf.loc(), fmt::format("variant names must match [a-z0-9_-]+ and be at most {} characters, got '{}'",
                                     kMaxNameLength, short_name(name)));
    for (std::size_t j = 0; j < out.size(); ++j) {
      if (out[j].variant == name)
        ctx.fail(nf.loc(), fmt::format("duplicate variant name '{}' (first at line {})", name,
                                       name_locs[j].mark.line + 1));
    }
    Scenario v = base;
    Provenance vp = prov;
    v.variant = name;
    apply_common(ctx, m, v, vp);
    apply_variant_light(ctx, m, v);
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
  // Read at most one byte past the limit, so /dev/zero or a mistaken multi-gigabyte file is
  // refused after 4 MiB, not after filling the memory.
  std::string text(kMaxScenarioBytes + 1, '\0');
  in.read(text.data(), static_cast<std::streamsize>(text.size()));
  if (in.bad()) {
    const int err = errno;
    throw ScenarioError(
        fmt::format("{}: cannot read scenario: {}", path, std::strerror(err != 0 ? err : EIO)));
  }
  text.resize(static_cast<std::size_t>(in.gcount()));
  if (text.size() > kMaxScenarioBytes)
    throw ScenarioError(fmt::format("{}: larger than {} MiB; a scenario file is a few kilobytes of YAML",
                                    path, kMaxScenarioBytes >> 20));
  if (text.find('\0') != std::string::npos)
    throw ScenarioError(fmt::format("{}: holds a NUL byte at offset {}; a scenario file is YAML text", path,
                                    text.find('\0')));
  return parse_scenarios(text, path);
}

std::string window_problem(double from, double to) {
  return to > from ? "" : fmt::format("must be greater than from ({}), got {}", from, to);
}

std::string phase_name_problem(const std::string& name) {
  if (scenario_name_ok(name)) return "";
  return fmt::format("phase names must match [A-Za-z0-9_.-]+ and be at most {} characters, got '{}'",
                     kMaxNameLength, short_name(name));
}

int added_and_removed(const std::vector<Sensor>& add, const std::vector<Sensor>& remove) {
  for (std::size_t k = 0; k < remove.size(); ++k)
    if (std::find(add.begin(), add.end(), remove[k]) != add.end()) return static_cast<int>(k);
  return -1;
}

}  // namespace wingman::sim
