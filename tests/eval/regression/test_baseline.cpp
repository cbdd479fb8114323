// Baselines: the metrics a results directory offers, the YAML written and read back, every
// malformed baseline refused with its file, line and key; and the determinism comparison.
#include "eval/regression/baseline.hpp"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <fstream>

#include "eval/regression/check.hpp"
#include "eval/metrics/metrics.hpp"
#include "eval/regression/same_results.hpp"
#include "eval/output/writers.hpp"
#include "eval/eval_test_support.hpp"

namespace wingman::eval {
namespace {

namespace fs = std::filesystem;
using test::make_record;
using test::TempDir;

fs::path write_run(const fs::path& dir) {
  const RunRecord run = make_record();
  write_results(compute_metrics(run), run, dir);
  return dir;
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  return {std::istreambuf_iterator<char>(in), {}};
}

void put(const fs::path& p, const std::string& text) { std::ofstream(p) << text; }

TEST(MetricSet, ResultsDirectoryOffersTheTablesByPath) {
  TempDir tmp;
  const MetricSet set = read_metric_set(write_run(tmp.path() / "res"));
  EXPECT_FALSE(set.monte_carlo);
  EXPECT_EQ(set.scenario, "test");
  EXPECT_EQ(set.seeds, std::vector<std::uint64_t>{42});
  // make_record: the lead is off by (0.5, 0, 0) on every step; uav1 by 1 m in y on 9 of the 20
  // steps and 2 m in z on 11.
  EXPECT_DOUBLE_EQ(set.values.at("table4.total.lead.mse.x")[0], 0.25);
  EXPECT_DOUBLE_EQ(set.values.at("table4.total.uav1.mse.y")[0], 0.45);
  EXPECT_DOUBLE_EQ(set.values.at("table4.total.uav1.mse.z")[0], 2.2);
  EXPECT_TRUE(set.has("table4.phases.config2.agents.uav1.mse.z"));
  EXPECT_TRUE(set.has("table3.uav1.accepted_outlier_fraction"));
  EXPECT_TRUE(set.has("nees.mean"));
  EXPECT_FALSE(set.has("nees.per_step"));
  const auto d = default_metrics(set);
  ASSERT_FALSE(d.empty());
  EXPECT_EQ(d.front(), "table4.total.lead.mse.x");
  EXPECT_NE(std::find(d.begin(), d.end(), "wall_time_s"), d.end());
  EXPECT_TRUE(is_timing_metric("multi/timings_ms.update.mean"));
  EXPECT_FALSE(is_timing_metric("multi/table4.total.lead.mse.x"));
}

TEST(MetricSet, RefusesMetricsOfAnotherSchemaVersion) {
  TempDir tmp;
  const fs::path dir = write_run(tmp.path() / "res");
  std::string json = slurp(dir / "metrics.json");
  const std::string v = fmt::format("\"schema_version\": {}", kMetricsSchemaVersion);
  ASSERT_NE(json.find(v), std::string::npos);
  put(dir / "metrics.json", std::string(json).replace(json.find(v), v.size(), "\"schema_version\": 1"));
  EXPECT_THROW(read_metric_set(dir), CheckInputError);
  put(dir / "metrics.json", std::string(json).replace(json.find(v), v.size() + 1, ""));
  try {
    read_metric_set(dir);
    FAIL() << "a metrics.json without schema_version must be refused";
  } catch (const CheckInputError& e) {
    EXPECT_NE(std::string(e.what()).find("metrics.json: no schema_version"), std::string::npos) << e.what();
  }
  EXPECT_THROW(read_metric_set(tmp.path()), CheckInputError);  // not a results directory
}

TEST(MetricSet, GlobsSelectMetricsAndOneMatchingNothingIsNamed) {
  TempDir tmp;
  const MetricSet set = read_metric_set(write_run(tmp.path() / "res"));
  const auto chosen = select_metrics(set, {"table4.total.*.mse.z"});
  EXPECT_EQ(chosen, (std::vector<std::string>{"table4.total.lead.mse.z", "table4.total.uav1.mse.z"}));
  try {
    select_metrics(set, {"table9.*"});
    FAIL();
  } catch (const CheckInputError& e) {
    EXPECT_NE(std::string(e.what()).find("'table9.*'"), std::string::npos) << e.what();
  }
}

TEST(Baseline, YamlReadsBackExactly) {
  TempDir tmp;
  const MetricSet set = read_metric_set(write_run(tmp.path() / "res"));
  const Baseline b = make_baseline(set, {});
  put(tmp.path() / "b.yaml", baseline_yaml(b));
  const Baseline back = read_baseline(tmp.path() / "b.yaml");
  ASSERT_EQ(back.entries.size(), b.entries.size());
  for (std::size_t i = 0; i < b.entries.size(); ++i) {
    EXPECT_EQ(back.entries[i].metric, b.entries[i].metric);
    EXPECT_EQ(back.entries[i].reference, b.entries[i].reference);  // bit for bit
    EXPECT_EQ(back.entries[i].rule, b.entries[i].rule);
    EXPECT_EQ(back.entries[i].tolerance, b.entries[i].tolerance);
    EXPECT_EQ(back.entries[i].warn_only, b.entries[i].warn_only);
  }
  // Timings warn, errors fail; fractions are absolute.
  for (const auto& e : back.entries) {
    EXPECT_EQ(e.warn_only, is_timing_metric(e.metric)) << e.metric;
    if (e.metric.ends_with("_fraction")) {
      EXPECT_EQ(e.rule, Rule::kAbs) << e.metric;
    }
  }
  const CheckReport r = check_against_baseline(set, back);
  EXPECT_EQ(r.failed, 0);
  EXPECT_EQ(r.rows.size(), b.entries.size());
}

TEST(Baseline, ToleranceOptionsReplaceTheDefaults) {
  TempDir tmp;
  const MetricSet set = read_metric_set(write_run(tmp.path() / "res"));
  const Baseline b = make_baseline(set, {{}, 0.05, 0.001, ""});
  for (const auto& e : b.entries) {
    if (e.warn_only) continue;
    EXPECT_EQ(e.tolerance, e.rule == Rule::kAbs ? 0.001 : 0.05) << e.metric;
  }
}

// The line of the first occurrence of `text` in `yaml`, 1-based.
int line_of(const std::string& yaml, const std::string& text) {
  const auto pos = yaml.find(text);
  return pos == std::string::npos ? -1 : 1 + static_cast<int>(std::count(yaml.begin(), yaml.begin() + pos, '\n'));
}

TEST(Baseline, MalformedBaselinesAreRefusedWithFileLineAndKey) {
  TempDir tmp;
  const std::string good = "baseline_schema: 1\nmetrics_schema: " + std::to_string(kMetricsSchemaVersion) +
                           "\nmetrics:\n  - metric: nees.mean\n    reference: 9\n    rule: rel\n    tolerance: 0.25\n";
  put(tmp.path() / "good.yaml", good);
  EXPECT_EQ(read_baseline(tmp.path() / "good.yaml").entries.size(), 1u);
  struct Case {
    std::string from, to, expect;
  };
  const std::vector<Case> cases = {
      {"rule: rel", "rule: relative", "'rule' must be one of"},
      {"tolerance: 0.25", "tolerance: -1", "'tolerance' must be >= 0"},
      {"tolerance: 0.25", "tolerence: 0.25", "unknown key 'tolerence'"},
      {"reference: 9", "reference: nine", "'reference' must be a finite number"},
      {"reference: 9", "reference: .nan", "'reference' must be a finite number"},
      {"rule: rel", "rule: paired", "rule paired needs 'per_seed'"},
      {"rule: rel", "rule: max", "rule max needs 'limit'"},
      {"metrics_schema: " + std::to_string(kMetricsSchemaVersion), "metrics_schema: 1", "made from metrics schema 1"},
      {"    tolerance: 0.25\n", "    tolerance: 0.25\n  - metric: nees.mean\n    reference: 1\n    rule: abs\n    tolerance: 1\n",
       "listed twice"},
      {"rule: rel", "rule: [rel", "not valid YAML"},
      {"rule: rel", "rule: rel\n    rule: abs", "duplicate key 'rule' (first at line 6)"},
      {"metrics:\n", "metrix: 1\nmetrics:\n", "unknown key 'metrix'"},
  };
  for (const auto& c : cases) {
    std::string text = good;
    text.replace(text.find(c.from), c.from.size(), c.to);
    put(tmp.path() / "bad.yaml", text);
    try {
      read_baseline(tmp.path() / "bad.yaml");
      ADD_FAILURE() << "accepted: " << c.to;
    } catch (const CheckInputError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(c.expect), std::string::npos) << what;
      EXPECT_NE(what.find((tmp.path() / "bad.yaml").string() + ":"), std::string::npos) << what;
    }
  }
  // The line named is the key's own.
  std::string text = good;
  text.replace(text.find("tolerance: 0.25"), 15, "tolerance: -1");
  put(tmp.path() / "bad.yaml", text);
  try {
    read_baseline(tmp.path() / "bad.yaml");
  } catch (const CheckInputError& e) {
    EXPECT_NE(std::string(e.what()).find(fmt::format("bad.yaml:{}:", line_of(text, "tolerance"))), std::string::npos)
        << e.what();
  }
}

TEST(Baseline, AMetricTheResultsLackIsBadInputNamingItsLine) {
  TempDir tmp;
  const MetricSet set = read_metric_set(write_run(tmp.path() / "res"));
  const std::string text = "baseline_schema: 1\nmetrics_schema: " + std::to_string(kMetricsSchemaVersion) +
                           "\nmetrics:\n  - metric: nees.mean\n    reference: 9\n    rule: rel\n    tolerance: 0.25\n"
                           "  - metric: table4.total.nobody.mse.x\n    reference: 1\n    rule: rel\n    tolerance: 0.25\n";
  put(tmp.path() / "b.yaml", text);
  try {
    check_against_baseline(set, read_baseline(tmp.path() / "b.yaml"));
    FAIL();
  } catch (const CheckInputError& e) {
    EXPECT_NE(std::string(e.what()).find("b.yaml:8: metric table4.total.nobody.mse.x"), std::string::npos) << e.what();
  }
}

std::string difference_of(const TreeComparison& c, const std::string& file) {
  for (const auto& f : c.files)
    if (f.path == file) return f.difference;
  return "(not compared)";
}

TEST(SameResults, IdenticalRunsAgreeAndTimingsDoNotCount) {
  TempDir tmp;
  const fs::path a = write_run(tmp.path() / "a"), b = write_run(tmp.path() / "b");
  EXPECT_TRUE(compare_results_trees(a, b).identical());
  // A timing column and a timing key changed: still identical.
  std::string steps = slurp(b / "steps.csv");
  const auto header = steps.substr(0, steps.find('\n'));
  ASSERT_NE(header.find("t_update_ms"), std::string::npos);
  std::string json = slurp(b / "metrics.json");
  json.replace(json.find("\"wall_time_s\": 1.5"), 18, "\"wall_time_s\": 2.5");
  put(b / "metrics.json", json);
  EXPECT_TRUE(compare_results_trees(a, b).identical());
}

TEST(SameResults, TheFirstDifferingFieldIsNamed) {
  TempDir tmp;
  const fs::path a = write_run(tmp.path() / "a"), b = write_run(tmp.path() / "b");
  std::string json = slurp(b / "metrics.json");
  const auto pos = json.find("\"max_in_state\": 3");
  ASSERT_NE(pos, std::string::npos);
  put(b / "metrics.json", json.replace(pos, 17, "\"max_in_state\": 4"));
  const auto c = compare_results_trees(a, b);
  ASSERT_EQ(c.differing(), 1);
  EXPECT_EQ(difference_of(c, "metrics.json"), "landmarks.max_in_state: 3 vs 4");
  // A CSV cell: named by row and column.
  std::vector<std::string> lines;
  std::ifstream in(b / "steps.csv");
  for (std::string l; std::getline(in, l);) lines.push_back(l);
  const std::string row3 = lines[3];
  lines[3] = "9" + row3.substr(row3.find(','));
  std::string text;
  for (const auto& l : lines) text += l + "\n";
  put(b / "steps.csv", text);
  put(b / "metrics.json", slurp(a / "metrics.json"));
  const auto d = compare_results_trees(a, b);
  ASSERT_EQ(d.differing(), 1);
  EXPECT_EQ(difference_of(d, "steps.csv"), "row 3, column " + lines[0].substr(0, lines[0].find(',')) + ": 2 vs 9");
  fs::remove(b / "landmarks.csv");
  EXPECT_EQ(difference_of(compare_results_trees(a, b), "landmarks.csv"), "only in " + a.string());
}

// With a tolerance, numbers that differ by rounding are the same (relative above 1, absolute
// below) in CSV fields, JSON numbers and the words of text lines; a larger change is not.
TEST(SameResults, ATolerancePassesRoundingAndNothingLarger) {
  TempDir tmp;
  const fs::path a = write_run(tmp.path() / "a"), b = write_run(tmp.path() / "b");
  put(a / "extra.csv", "x,y\n1234.5,2e-7\n");
  put(a / "map.txt", "point 1234.5 2e-7\n");
  put(b / "extra.csv", "x,y\n1234.5000000001,2.000000001e-7\n");
  put(b / "map.txt", "point 1234.5000000001 2.000000001e-7\n");
  std::string json = slurp(b / "metrics.json");
  const auto pos = json.find("\"max_in_state\": 3");
  ASSERT_NE(pos, std::string::npos);
  put(b / "metrics.json", json.replace(pos, 17, "\"max_in_state\": 3.0000000000004"));
  EXPECT_EQ(compare_results_trees(a, b).differing(), 3);
  EXPECT_TRUE(compare_results_trees(a, b, 1e-9).identical());
  put(b / "extra.csv", "x,y\n1234.5000002,2e-7\n");  // 1.6e-10 relative
  put(b / "map.txt", "point 1234.5 2.1e-7\n");         // 1e-8 absolute
  const auto c = compare_results_trees(a, b, 1e-9);
  EXPECT_EQ(difference_of(c, "extra.csv"), "");
  EXPECT_EQ(difference_of(c, "map.txt"), "line 1: 'point 1234.5 2e-7' vs 'point 1234.5 2.1e-7'");
  put(b / "extra.csv", "x,y\n1234.50001,2e-7\n");  // 8e-9 relative
  EXPECT_EQ(difference_of(compare_results_trees(a, b, 1e-9), "extra.csv"), "row 1, column x: 1234.5 vs 1234.50001");
}

}  // namespace
}  // namespace wingman::eval

namespace wingman::eval {
namespace {

TEST(MetricSet, MonteCarloDirectoryGivesOneValuePerSeedAndItsFailedSeedsFail) {
  test::TempDir tmp;
  const fs::path mc = tmp.path() / "mc";
  for (const char* seed : {"seed1", "seed2"}) write_run(mc / "runs" / seed);
  put(mc / "montecarlo.json",
      R"({"scenario": "x.yaml", "seeds": [1, 2], "failed_seeds": [{"seed": 3, "reason": "exit 1"}], "variants": []})");
  const MetricSet set = read_metric_set(mc);
  EXPECT_TRUE(set.monte_carlo);
  EXPECT_EQ(set.seeds, (std::vector<std::uint64_t>{1, 2}));
  EXPECT_EQ(set.values.at("table4.total.lead.mse.x"), (std::vector<double>{0.25, 0.25}));
  ASSERT_EQ(set.failures.size(), 1u);
  EXPECT_NE(set.failures[0].find("seed 3: exit 1"), std::string::npos) << set.failures[0];

  const Baseline b = make_baseline(set, {{"table4.total.lead.mse.x"}, -1, -1, ""});
  ASSERT_EQ(b.entries.size(), 1u);
  EXPECT_EQ(b.entries[0].rule, Rule::kPaired);
  EXPECT_EQ(b.entries[0].per_seed.size(), 2u);
  const CheckReport r = check_against_baseline(set, b);
  ASSERT_EQ(r.rows.size(), 2u);
  EXPECT_EQ(r.rows[0].verdict, Verdict::kPass);
  EXPECT_EQ(r.rows[1].metric, "failed_run");
  EXPECT_EQ(r.rows[1].verdict, Verdict::kFail);
  EXPECT_EQ(r.failed, 1);
}

}  // namespace
}  // namespace wingman::eval

namespace wingman::eval {
namespace {

TEST(Baseline, AMetricWithoutAValueIsLeftOutAndNamed) {
  MetricSet set;
  set.paths = {"nees.mean", "table4.total.lead.mse.x"};
  set.values = {{"nees.mean", {kNaN}}, {"table4.total.lead.mse.x", {0.25}}};
  set.seeds = {1};
  const Baseline b = make_baseline(set, {{"*"}, -1, -1, ""});
  ASSERT_EQ(b.entries.size(), 1u);
  EXPECT_EQ(b.entries[0].metric, "table4.total.lead.mse.x");
  EXPECT_EQ(b.left_out, std::vector<std::string>{"nees.mean"});
}

}  // namespace
}  // namespace wingman::eval
