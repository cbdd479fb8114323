#include "eval/regression/same_results.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <sstream>

#include "eval/output/json_file.hpp"
#include "eval/regression/metric_set.hpp"

namespace wingman::eval {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

const std::set<std::string> kDataExtensions = {".csv", ".json", ".yaml", ".tum", ".ply", ".txt"};

std::vector<std::string> lines_of(const fs::path& p) {
  std::ifstream in(p);
  if (!in) throw CheckInputError(fmt::format("{}: cannot open", p.string()));
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

std::vector<std::string> cells(const std::string& line) {
  std::vector<std::string> out(1);
  for (char c : line) {
    if (c == ',') out.emplace_back();
    else out.back().push_back(c);
  }
  return out;
}

bool no_value(const std::string& c) { return c.empty() || c == "nan" || c == "NaN"; }

// Two numbers the same up to a tolerance (0: bit for bit), relative above 1 in magnitude and
// absolute below: a velocity of 1e-6 m/s that rounding moves by 1e-15 is the same velocity.
bool same_number(double x, double y, double rel_tol) {
  if (x == y) return true;
  if (rel_tol <= 0 || !std::isfinite(x) || !std::isfinite(y)) return false;
  return std::abs(x - y) <= rel_tol * std::max({std::abs(x), std::abs(y), 1.0});
}

std::optional<double> as_number(const std::string& s) {
  double v = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || end != s.data() + s.size()) return std::nullopt;
  return v;
}

// Two fields the same: equal text, or numbers within the tolerance.
bool same_field(const std::string& x, const std::string& y, double rel_tol) {
  if (x == y) return true;
  const auto a = as_number(x), b = as_number(y);
  return a && b && same_number(*a, *b, rel_tol);
}

std::vector<std::string> words(const std::string& line) {
  std::vector<std::string> out;
  std::istringstream in(line);
  for (std::string w; in >> w;) out.push_back(w);
  return out;
}

bool same_line(const std::string& x, const std::string& y, double rel_tol) {
  if (x == y) return true;
  if (rel_tol <= 0) return false;
  const auto a = words(x), b = words(y);
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (!same_field(a[i], b[i], rel_tol)) return false;
  return true;
}
bool timing_column(const std::string& h) { return h.rfind("t_", 0) == 0 && h.size() > 5 && h.ends_with("_ms"); }

std::string csv_difference(const fs::path& a, const fs::path& b, double rel_tol) {
  const auto la = lines_of(a), lb = lines_of(b);
  if (la.empty() || lb.empty()) return la.size() == lb.size() ? "" : "one file is empty";
  if (la[0] != lb[0]) return fmt::format("header differs: '{}' vs '{}'", la[0], lb[0]);
  if (la.size() != lb.size()) return fmt::format("{} rows vs {}", la.size() - 1, lb.size() - 1);
  const auto header = cells(la[0]);
  for (std::size_t r = 1; r < la.size(); ++r) {
    if (la[r] == lb[r]) continue;
    const auto x = cells(la[r]), y = cells(lb[r]);
    if (x.size() != y.size()) return fmt::format("row {}: {} fields vs {}", r, x.size(), y.size());
    for (std::size_t c = 0; c < x.size(); ++c) {
      const std::string name = c < header.size() ? header[c] : fmt::format("#{}", c + 1);
      if (!same_field(x[c], y[c], rel_tol) && !(no_value(x[c]) && no_value(y[c])) && !timing_column(name))
        return fmt::format("row {}, column {}: {} vs {}", r, name, x[c], y[c]);
    }
  }
  return "";
}

bool ignored_key(const std::string& k, const json& x) {
  static const std::set<std::string> keys = {"wall_time_s", "timings_ms", "software_version", "scenario_path",
                                             "path", "real_time_factor", "renderer",
                                             "frame_cache", "frame_regions"};
  return keys.count(k) || k.ends_with("_ms") || k.ends_with("_ms_per_step") || (k == "scenario" && x.is_string());
}

std::string json_difference(const json& x, const json& y, const std::string& path, double rel_tol) {
  if (x.is_object() && y.is_object()) {
    std::set<std::string> keys;
    for (const auto& [k, v] : x.items()) keys.insert(k);
    for (const auto& [k, v] : y.items()) keys.insert(k);
    for (const auto& k : keys) {
      const std::string sub = path.empty() ? k : path + "." + k;
      if (ignored_key(k, x.contains(k) ? x[k] : y[k])) continue;  // on one side only, too (frame_cache)
      if (!x.contains(k) || !y.contains(k)) return fmt::format("{}: only in {}", sub, x.contains(k) ? "A" : "B");
      if (auto d = json_difference(x[k], y[k], sub, rel_tol); !d.empty()) return d;
    }
    return "";
  }
  if (x.is_array() && y.is_array()) {
    if (x.size() != y.size()) return fmt::format("{}: {} items vs {}", path, x.size(), y.size());
    for (std::size_t i = 0; i < x.size(); ++i)
      if (auto d = json_difference(x[i], y[i], fmt::format("{}[{}]", path, i), rel_tol); !d.empty()) return d;
    return "";
  }
  if (x.is_number() && y.is_number() && same_number(x.get<double>(), y.get<double>(), rel_tol)) return "";
  return x == y ? "" : fmt::format("{}: {} vs {}", path.empty() ? "(document)" : path, x.dump(), y.dump());
}

std::string text_difference(const fs::path& a, const fs::path& b, bool skip_comments, double rel_tol) {
  auto la = lines_of(a), lb = lines_of(b);
  if (skip_comments)
    for (auto* l : {&la, &lb}) std::erase_if(*l, [](const std::string& s) { return s.rfind("#", 0) == 0; });
  for (std::size_t i = 0; i < std::min(la.size(), lb.size()); ++i)
    if (!same_line(la[i], lb[i], rel_tol)) return fmt::format("line {}: '{}' vs '{}'", i + 1, la[i], lb[i]);
  return la.size() == lb.size() ? "" : fmt::format("{} lines vs {}", la.size(), lb.size());
}

// Data files under root, relative, sorted.
std::set<std::string> data_files(const fs::path& root) {
  std::set<std::string> files;
  for (const auto& e : fs::recursive_directory_iterator(root)) {
    const std::string rel = fs::relative(e.path(), root).string();
    if (rel.find(".partial-") != std::string::npos) continue;  // a run in progress
    if (e.is_regular_file() && kDataExtensions.count(e.path().extension().string())) files.insert(rel);
  }
  return files;
}

}  // namespace

std::string first_difference(const fs::path& a, const fs::path& b, double rel_tol) {
  const std::string ext = a.extension().string();
  if (ext == ".csv") return csv_difference(a, b, rel_tol);
  if (ext == ".json") {
    try {
      return json_difference(read_json_file(a), read_json_file(b), "", rel_tol);
    } catch (const std::runtime_error& e) {
      throw CheckInputError(e.what());
    }
  }
  return text_difference(a, b, ext == ".yaml", rel_tol);
}

int TreeComparison::differing() const {
  return static_cast<int>(std::count_if(files.begin(), files.end(), [](const File& f) { return !f.difference.empty(); }));
}

TreeComparison compare_results_trees(const fs::path& a, const fs::path& b, double rel_tol) {
  for (const auto& d : {a, b})
    if (!fs::is_directory(d)) throw CheckInputError(fmt::format("{}: no such directory", d.string()));
  const auto fa = data_files(a), fb = data_files(b);
  if (std::none_of(fa.begin(), fa.end(), [](const auto& f) { return f.ends_with("metrics.json"); }))
    throw CheckInputError(fmt::format("{}: holds no results (no metrics.json)", a.string()));
  std::set<std::string> all = fa;
  all.insert(fb.begin(), fb.end());
  TreeComparison c;
  for (const auto& f : all) {
    if (!fa.count(f) || !fb.count(f)) c.files.push_back({f, fmt::format("only in {}", (fa.count(f) ? a : b).string())});
    else c.files.push_back({f, first_difference(a / f, b / f, rel_tol)});
  }
  return c;
}

}  // namespace wingman::eval
