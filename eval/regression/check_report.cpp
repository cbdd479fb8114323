// The reports of `wingman check`: the terminal table, Markdown, JUnit XML and JSON.
#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <nlohmann/json.hpp>
#include <pugixml.hpp>
#include <sstream>

#include "eval/regression/check.hpp"

namespace wingman::eval {
namespace {

std::string value_text(double v) { return std::isfinite(v) ? fmt::format("{:.4g}", v) : "-"; }

std::string change_text(const CheckRow& r) {
  if (!std::isfinite(r.change)) return "-";
  if (!r.change_relative) return fmt::format("{:+.4g}", r.change);
  return std::abs(r.change) < 10 ? fmt::format("{:+.1f}%", 100 * r.change) : fmt::format("{:+.0f}%", 100 * r.change);
}

std::string summary_line(const CheckReport& r) {
  return fmt::format("{} metric{}: {} failed, {} warned, {} passed", r.rows.size(), r.rows.size() == 1 ? "" : "s",
                     r.failed, r.warned, r.rows.size() - r.failed - r.warned);
}

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

bool passed(const CheckRow& row) { return row.verdict == Verdict::kPass || row.verdict == Verdict::kImproved; }

// The testcase's class: wingman.check.<variant> ("multi/table4..." -> wingman.check.multi), or
// wingman.check for a scenario without variants.
std::string junit_class(const CheckRow& row) {
  const auto slash = row.metric.find('/');
  return slash == std::string::npos ? "wingman.check" : "wingman.check." + row.metric.substr(0, slash);
}

}  // namespace

std::string format_check(const CheckReport& r, bool all_details) {
  std::size_t width = 6;
  for (const auto& row : r.rows) width = std::max(width, row.metric.size());
  std::string s = fmt::format("{} against {}\n", r.results.string(), r.baseline.string());
  s += fmt::format("{:<{}}  {:>10}  {:>10}  {:>9}  {:<14}  {}\n", "metric", width, "baseline", "now", "change", "rule",
                   "verdict");
  for (const auto& row : r.rows)
    s += fmt::format("{:<{}}  {:>10}  {:>10}  {:>9}  {:<14}  {}\n", row.metric, width, value_text(row.reference),
                     value_text(row.now), change_text(row), row.rule, verdict_name(row.verdict));
  for (const auto& row : r.rows)
    if (!passed(row)) s += fmt::format("{} {}: {}\n", verdict_name(row.verdict), row.metric, row.detail);
  for (const auto& row : r.rows)
    if (row.verdict == Verdict::kImproved || (all_details && row.verdict == Verdict::kPass))
      s += fmt::format("{} {}: {}\n", verdict_name(row.verdict), row.metric, row.detail);
  return s + summary_line(r) + "\n";
}

std::string check_markdown(const CheckReport& r) {
  std::string s = fmt::format("### wingman check: {}\n\n`{}` against `{}`\n\n", summary_line(r), r.results.string(),
                              r.baseline.string());
  s += "| metric | baseline | now | change | rule | verdict |\n|---|---:|---:|---:|---|---|\n";
  for (const auto& row : r.rows) {
    const std::string v = passed(row) ? verdict_name(row.verdict) : fmt::format("**{}**", verdict_name(row.verdict));
    s += fmt::format("| `{}` | {} | {} | {} | {} | {} |\n", row.metric, value_text(row.reference), value_text(row.now),
                     change_text(row), row.rule, v);
  }
  bool any = false;
  for (const auto& row : r.rows)
    if (!passed(row)) s += fmt::format("{}- **{}** `{}`: {}\n", any ? "" : "\n", verdict_name(row.verdict), row.metric,
                                       row.detail), any = true;
  return s;
}

std::string check_junit(const CheckReport& r) {
  pugi::xml_document doc;
  auto decl = doc.append_child(pugi::node_declaration);
  decl.append_attribute("version") = "1.0";
  decl.append_attribute("encoding") = "UTF-8";
  auto suites = doc.append_child("testsuites");
  suites.append_attribute("name") = "wingman check";
  auto suite = suites.append_child("testsuite");
  suite.append_attribute("name") = fmt::format("wingman check {}", r.results.string()).c_str();
  for (auto node : {suites, suite}) {
    node.append_attribute("tests") = static_cast<int>(r.rows.size());
    node.append_attribute("failures") = r.failed;
    node.append_attribute("errors") = 0;
    node.append_attribute("skipped") = 0;
    node.append_attribute("time") = "0";
  }
  for (const auto& row : r.rows) {
    auto tc = suite.append_child("testcase");
    tc.append_attribute("classname") = junit_class(row).c_str();
    tc.append_attribute("name") = row.metric.c_str();
    tc.append_attribute("file") = r.baseline.string().c_str();
    tc.append_attribute("line") = row.line;
    tc.append_attribute("time") = "0";
    const std::string text = fmt::format("baseline {}, now {} ({}), rule {}: {}", value_text(row.reference),
                                         value_text(row.now), change_text(row), row.rule, row.detail);
    if (row.verdict == Verdict::kFail) {
      auto f = tc.append_child("failure");
      f.append_attribute("type") = "regression";
      f.append_attribute("message") = text.c_str();
      f.append_child(pugi::node_pcdata).set_value(text.c_str());
    } else {
      tc.append_child("system-out").append_child(pugi::node_pcdata).set_value(
          fmt::format("{}: {}", verdict_name(row.verdict), text).c_str());
    }
  }
  std::ostringstream out;
  doc.save(out, "  ", pugi::format_default, pugi::encoding_utf8);
  return out.str();
}

std::string check_json(const CheckReport& r) {
  using nlohmann::json;
  auto num = [](double v) { return std::isfinite(v) ? json(v) : json(nullptr); };
  json rows = json::array();
  for (const auto& row : r.rows)
    rows.push_back({{"metric", row.metric}, {"baseline_line", row.line}, {"baseline", num(row.reference)},
                    {"now", num(row.now)}, {"change", num(row.change)},
                    {"change_is_relative", row.change_relative}, {"rule", row.rule},
                    {"verdict", lower(verdict_name(row.verdict))}, {"detail", row.detail}});
  const json j = {{"results", r.results.string()}, {"baseline", r.baseline.string()}, {"failed", r.failed},
                  {"warned", r.warned}, {"passed", r.rows.size() - r.failed - r.warned}, {"rows", rows}};
  return j.dump(2) + "\n";
}

}  // namespace wingman::eval
