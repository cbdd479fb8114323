#include "frontend_bench/lead_scores.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>
#include <tuple>

#include "frontend_bench/match_files.hpp"

namespace wingman::frontend_bench {

namespace fs = std::filesystem;

void LeadScoreOptions::validate() const {
  if (!(min_visible > 0 && min_visible <= 1))
    throw std::invalid_argument(fmt::format("--min-visible must be in (0, 1], got {}", min_visible));
  if (!(match_px > 0 && match_px < 1e4))
    throw std::invalid_argument(fmt::format("--match-px must be in (0, 10000), got {}", match_px));
}

namespace {

bool in_image(const LeadFrame& f) {
  const auto& uv = f.truth.uv;
  return uv.allFinite() && uv.x() >= -0.5 && uv.y() >= -0.5 && uv.x() < f.width - 0.5 && uv.y() < f.height - 0.5;
}

std::string distance_bin(double d) {
  static const double edges[] = {8, 12, 16, 20};
  double lo = 0;
  for (double e : edges) {
    if (d < e) return fmt::format("{:g}-{:g} m", lo, e);
    lo = e;
  }
  return fmt::format(">= {:g} m", lo);
}

std::string visible_bin(double v) {
  if (v < 0.2) return "0-0.2";
  if (v < 0.5) return "0.2-0.5";
  if (v < 0.8) return "0.5-0.8";
  return "0.8-1";
}

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::sort(v.begin(), v.end());
  const double pos = q * static_cast<double>(v.size() - 1);
  const auto i = static_cast<std::size_t>(pos);
  return i + 1 < v.size() ? v[i] + (pos - static_cast<double>(i)) * (v[i + 1] - v[i]) : v[i];
}

// One row over the frames `keep` selects; `showing` decides which frames the rate counts.
LeadScore score(const std::vector<LeadFrame>& frames, const LeadScoreOptions& o, const std::string& by,
                const std::string& key, const std::function<bool(const LeadFrame&)>& keep,
                const std::function<bool(const LeadFrame&)>& showing) {
  LeadScore s{by, key};
  std::vector<double> err;
  double cpu = 0;
  long timed = 0;
  for (const LeadFrame& f : frames) {
    if (!keep(f)) continue;
    ++s.frames;
    if (std::isfinite(f.cpu_ms)) cpu += f.cpu_ms, ++timed;
    const bool shows = showing(f);
    s.showing += shows;
    if (!f.detected) continue;
    const double e = f.truth.uv.allFinite() ? (*f.detected - f.truth.uv).norm() : INFINITY;
    if (e > o.match_px) {
      ++s.false_detections;
    } else if (shows) {
      ++s.found;
      err.push_back(e);
    }
  }
  s.median_px = percentile(err, 0.5);
  s.p95_px = percentile(err, 0.95);
  if (timed > 0) s.cpu_ms = cpu / static_cast<double>(timed);
  return s;
}

}  // namespace

std::vector<LeadScore> score_leads(const std::vector<LeadFrame>& frames, const LeadScoreOptions& o) {
  const auto shows = [&](const LeadFrame& f) { return in_image(f) && f.truth.visible >= o.min_visible; };
  std::vector<LeadScore> out{score(frames, o, "all", "all", [](const LeadFrame&) { return true; }, shows)};
  // The keys of one grouping, in first-seen order.
  auto group = [&](const std::string& by, const std::function<std::string(const LeadFrame&)>& key,
                   const std::function<bool(const LeadFrame&)>& showing) {
    std::vector<std::string> keys;
    for (const auto& f : frames)
      if (std::find(keys.begin(), keys.end(), key(f)) == keys.end()) keys.push_back(key(f));
    if (by == "distance" || by == "visible")  // by the bins' lower edges
      std::sort(keys.begin(), keys.end(), [](const std::string& a, const std::string& b) {
        auto lo = [](const std::string& k) { return std::stod(k.substr(k.find_first_of("0123456789."))); };
        return lo(a) < lo(b);
      });
    for (const auto& k : keys)
      out.push_back(score(frames, o, by, k, [&](const LeadFrame& f) { return key(f) == k; }, showing));
  };
  group("lead", [](const LeadFrame& f) { return f.lead; }, shows);
  group("ground", [](const LeadFrame& f) { return f.ground; }, shows);
  group("distance", [](const LeadFrame& f) { return distance_bin(f.truth.distance); }, shows);
  group("visible", [](const LeadFrame& f) { return visible_bin(f.truth.visible); }, in_image);
  return out;
}

std::string lead_scores_table(const std::vector<LeadScore>& scores, const std::string& detector) {
  std::string t = fmt::format("Lead detector: {}\n{:<9} {:<22} {:>7} {:>8} {:>9} {:>11} {:>10} {:>8} {:>9}\n",
                              detector, "by", "", "frames", "showing", "detected", "false/frame", "median px",
                              "p95 px", "CPU ms");
  auto num = [](double x, int digits) { return std::isfinite(x) ? fmt::format("{:.{}f}", x, digits) : "-"; };
  for (const LeadScore& s : scores)
    t += fmt::format("{:<9} {:<22} {:>7} {:>8} {:>8.1f}% {:>11} {:>10} {:>8} {:>9}\n", s.by, s.key, s.frames,
                     s.showing, 100 * s.rate(), num(s.false_per_frame(), 3), num(s.median_px, 2), num(s.p95_px, 2),
                     num(s.cpu_ms, 2));
  return t;
}

std::string lead_scores_json(const std::vector<LeadScore>& scores, const std::string& detector,
                             const LeadScoreOptions& o) {
  auto num = [](double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr); };
  nlohmann::json j;
  j["schema_version"] = 1;
  j["detector"] = detector;
  j["min_visible"] = o.min_visible;
  j["match_px"] = o.match_px;
  for (const LeadScore& s : scores)
    j["scores"].push_back({{"by", s.by}, {"key", s.key}, {"frames", s.frames}, {"showing", s.showing},
                           {"detected", s.found}, {"detection_rate", s.rate()},
                           {"false_detections", s.false_detections}, {"false_per_frame", s.false_per_frame()},
                           {"median_px", num(s.median_px)}, {"p95_px", num(s.p95_px)}, {"cpu_ms", num(s.cpu_ms)}});
  return j.dump(1) + "\n";
}

std::vector<LeadDetectionRow> read_lead_detections(const fs::path& file) {
  std::ifstream in(file);
  if (!in) throw MatchInputError(file.string() + ": cannot read the lead detections file");
  auto fail = [&](int line, const std::string& what) {
    throw MatchInputError(fmt::format("{}:{}: {}", file.string(), line, what));
  };
  auto number = [&](const std::string& s, int line, const char* what) {
    std::size_t used = 0;
    double v = 0;
    try {
      v = std::stod(s, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != s.size() || !std::isfinite(v) || std::abs(v) > 1e9)
      fail(line, fmt::format("{} '{}' is not a finite number", what, s));
    return v;
  };
  std::vector<LeadDetectionRow> out;
  std::string text;
  int line = 0;
  while (std::getline(in, text)) {
    ++line;
    if (!text.empty() && text.back() == '\r') text.pop_back();
    if (text.empty() || text[0] == '#') continue;
    std::vector<std::string> cells;
    std::stringstream ss(text);
    for (std::string c; std::getline(ss, c, ',');) cells.push_back(c);
    if (text.back() == ',') cells.emplace_back();
    if (cells.size() != 6) fail(line, fmt::format("expected 6 columns ({}), got {}", kLeadDetectionsHeader + 1, cells.size()));
    LeadDetectionRow r;
    r.dataset = cells[0];
    r.agent = cells[1];
    if (r.agent.empty()) fail(line, "the agent is empty");
    const double t = number(cells[2], line, "timestamp");
    if (t < 0 || t != std::floor(t)) fail(line, fmt::format("timestamp '{}' is not whole nanoseconds >= 0", cells[2]));
    r.t_ns = static_cast<std::int64_t>(t);
    r.uv = {number(cells[3], line, "u"), number(cells[4], line, "v")};
    r.score = number(cells[5], line, "score");
    out.push_back(r);
  }
  return out;
}

std::string lead_detections_csv(const std::vector<LeadDetectionRow>& rows) {
  std::string s = std::string(kLeadDetectionsHeader) + "\n";
  for (const auto& r : rows)
    s += fmt::format("{},{},{},{:.6f},{:.6f},{:.6g}\n", r.dataset, r.agent, r.t_ns, r.uv.x(), r.uv.y(), r.score);
  return s;
}

void attach_detections(std::vector<LeadFrame>& frames, const std::vector<LeadDetectionRow>& rows,
                       const fs::path& file) {
  std::map<std::tuple<std::string, std::string, std::int64_t>, LeadFrame*> index;
  for (auto& f : frames) index[{f.dataset, f.agent, f.t_ns}] = &f;
  std::map<LeadFrame*, double> best;
  for (const auto& r : rows) {
    const auto it = index.find({r.dataset, r.agent, r.t_ns});
    if (it == index.end())
      throw MatchInputError(fmt::format("{}: no frame of dataset '{}', agent '{}' at {} ns", file.string(), r.dataset,
                                        r.agent, r.t_ns));
    const auto b = best.find(it->second);
    if (b != best.end() && b->second >= r.score) continue;
    best[it->second] = r.score;
    it->second->detected = r.uv;
  }
}

}  // namespace wingman::frontend_bench
