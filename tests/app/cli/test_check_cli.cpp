// `wingman baseline` and `wingman check` end to end on the smoke scene: the shipped filter passes
// its committed baseline, a deliberately worsened one fails it, the reports parse back, and bad
// input exits 2 naming the file and metric with no report written.
#include <gtest/gtest.h>

#include <pugixml.hpp>

#include "app/app_test_support.hpp"

namespace wingman::app::test {
namespace {

const fs::path kSmokeBaseline = kSourceDir / "baselines" / "smoke.yaml";

// "<file>:<line>:", as messages name a place in a file.
std::string fmt_line(const fs::path& file, int line) { return file.string() + ":" + std::to_string(line) + ":"; }

// Runs the smoke scene (or a text of it) into dir/name.
fs::path run_smoke(const TempDir& tmp, const std::string& name, const std::string& scenario_text = "",
                   const std::vector<std::string>& extra = {}) {
  fs::path scenario = kSmoke;
  if (!scenario_text.empty()) write_file(scenario = tmp / (name + ".yaml"), scenario_text);
  std::vector<std::string> args = {"run", scenario.string(), "--out", (tmp / name).string(), "-q", "--no-plots"};
  args.insert(args.end(), extra.begin(), extra.end());
  const RunResult r = run_wingman(args, tmp.path());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  return tmp / name;
}

// The smoke scene with the estimator's pixel sigma ten times too small: an overconfident filter.
std::string worsened_smoke() {
  std::string text = read_file(kSmoke);
  replace_once(text, "measurement_noise: {pixel_sigma: 3,", "measurement_noise: {pixel_sigma: 0.3,");
  return text;
}

TEST(CheckCli, ShippedSmokePassesItsBaselineAndAWorsenedFilterFails) {
  TempDir tmp;
  const fs::path good = run_smoke(tmp, "good");
  const RunResult pass =
      run_wingman({"check", good.string(), "--baseline", kSmokeBaseline.string(), "--verbose"}, tmp.path());
  EXPECT_EQ(pass.exit_code, 0) << pass.output;
  EXPECT_NE(pass.output.find("0 failed"), std::string::npos) << pass.output;
  // --verbose: the numbers behind a pass too.
  EXPECT_NE(pass.output.find("pass multi/table4.total.lead.mse.x: "), std::string::npos) << pass.output;

  const fs::path worse = run_smoke(tmp, "worse", worsened_smoke());
  const RunResult fail = run_wingman({"check", worse.string(), "--baseline", kSmokeBaseline.string()}, tmp.path());
  EXPECT_EQ(fail.exit_code, 1) << fail.output;
  // The table names the metric, both values and the rule; the details give the numbers.
  EXPECT_NE(fail.output.find("multi/table4.total.lead.mse.x"), std::string::npos) << fail.output;
  EXPECT_NE(fail.output.find("FAIL multi/nees.mean:"), std::string::npos) << fail.output;
  EXPECT_NE(fail.output.find("allowed"), std::string::npos) << fail.output;
}

TEST(CheckCli, JunitAndMarkdownReportsParseBack) {
  TempDir tmp;
  const fs::path worse = run_smoke(tmp, "worse", worsened_smoke());
  const RunResult r = run_wingman({"check", worse.string(), "--baseline", kSmokeBaseline.string(), "--junit",
                                   (tmp / "reports/junit.xml").string(), "--markdown", (tmp / "reports/check.md").string(),
                                   "--json", (tmp / "reports/check.json").string(), "-q"},
                                  tmp.path());
  ASSERT_EQ(r.exit_code, 1) << r.output;

  pugi::xml_document doc;
  ASSERT_TRUE(doc.load_file((tmp / "reports/junit.xml").c_str())) << "JUnit XML does not parse";
  const pugi::xml_node suite = doc.child("testsuites").child("testsuite");
  ASSERT_TRUE(suite);
  int cases = 0, failures = 0;
  for (const pugi::xml_node tc : suite.children("testcase")) {
    ++cases;
    EXPECT_FALSE(std::string(tc.attribute("name").value()).empty());
    EXPECT_EQ(std::string(tc.attribute("classname").value()).rfind("wingman.check", 0), 0u);
    if (const pugi::xml_node f = tc.child("failure")) {
      ++failures;
      EXPECT_NE(std::string(f.attribute("message").value()).find("baseline "), std::string::npos);
    }
  }
  EXPECT_EQ(suite.attribute("tests").as_int(), cases);
  EXPECT_EQ(suite.attribute("failures").as_int(), failures);
  EXPECT_GT(failures, 10);

  // Markdown: a table with one row per testcase, the failing ones in bold.
  int rows = 0, bold = 0;
  for (const std::string& line : lines_of(read_file(tmp / "reports/check.md"))) {
    if (line.rfind("| `", 0) != 0) continue;
    ++rows;
    EXPECT_EQ(std::count(line.begin(), line.end(), '|'), 7) << line;
    bold += line.find("| **FAIL** |") != std::string::npos;
  }
  EXPECT_EQ(rows, cases);
  EXPECT_EQ(bold, failures);
  EXPECT_NE(read_file(tmp / "reports/check.json").find("\"verdict\": \"fail\""), std::string::npos);
}

// Expects exit 2, the messages' parts in the output, and no report written.
void expect_bad_input(const TempDir& tmp, const std::vector<std::string>& args, const std::vector<std::string>& parts) {
  std::vector<std::string> full = args;
  full.insert(full.end(), {"--junit", (tmp / "bad.xml").string(), "--markdown", (tmp / "bad.md").string()});
  const RunResult r = run_wingman(full, tmp.path());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  for (const auto& p : parts) EXPECT_NE(r.output.find(p), std::string::npos) << "'" << p << "' not in: " << r.output;
  EXPECT_FALSE(fs::exists(tmp / "bad.xml"));
  EXPECT_FALSE(fs::exists(tmp / "bad.md"));
}

TEST(CheckCli, BadInputExits2NamingFileLineAndMetricWithNoReport) {
  TempDir tmp;
  const fs::path good = run_smoke(tmp, "good");
  std::string baseline = read_file(kSmokeBaseline);
  // A metric the results do not have, on a known line.
  std::string missing = baseline;
  const int line = replace_once(missing, "multi/table4.total.lead.mse.x", "multi/table4.total.nobody.mse.x");
  write_file(tmp / "missing.yaml", missing);
  expect_bad_input(tmp, {"check", good.string(), "--baseline", (tmp / "missing.yaml").string()},
                   {fmt_line(tmp / "missing.yaml", line), "multi/table4.total.nobody.mse.x"});
  // A malformed rule.
  std::string bad_rule = baseline;
  const int rule_line = replace_once(bad_rule, "rule: rel", "rule: around");
  write_file(tmp / "rule.yaml", bad_rule);
  expect_bad_input(tmp, {"check", good.string(), "--baseline", (tmp / "rule.yaml").string()},
                   {fmt_line(tmp / "rule.yaml", rule_line), "'rule' must be one of"});
  // Not YAML, no such baseline, not a results directory.
  write_file(tmp / "broken.yaml", "metrics: [\n");
  expect_bad_input(tmp, {"check", good.string(), "--baseline", (tmp / "broken.yaml").string()}, {"broken.yaml:", "not valid YAML"});
  expect_bad_input(tmp, {"check", good.string(), "--baseline", (tmp / "none.yaml").string()}, {"none.yaml: no such file"});
  expect_bad_input(tmp, {"check", tmp.path().string(), "--baseline", kSmokeBaseline.string()}, {"not a results directory"});
  // Results of an older metrics schema.
  std::string metrics = read_file(good / "multi" / "metrics.json");
  replace_once(metrics, "\"schema_version\": 2", "\"schema_version\": 1");
  write_file(good / "multi" / "metrics.json", metrics);
  expect_bad_input(tmp, {"check", good.string(), "--baseline", kSmokeBaseline.string()},
                   {"multi/metrics.json: metrics schema 1, this wingman reads schema 2"});
}

TEST(CheckCli, AgainstFindsTheFirstDifferenceBetweenTwoRuns) {
  TempDir tmp;
  const fs::path a = run_smoke(tmp, "a"), b = run_smoke(tmp, "b");
  const RunResult same = run_wingman({"check", a.string(), "--against", b.string()}, tmp.path());
  EXPECT_EQ(same.exit_code, 0) << same.output;
  EXPECT_NE(same.output.find("data files"), std::string::npos) << same.output;
  const fs::path c = run_smoke(tmp, "c", "", {"--seed", "2"});
  const RunResult differ = run_wingman({"check", a.string(), "--against", c.string(), "--junit", (tmp / "d.xml").string()},
                                       tmp.path());
  EXPECT_EQ(differ.exit_code, 1) << differ.output;
  EXPECT_NE(differ.output.find("multi/config.yaml: line"), std::string::npos) << differ.output;  // seed: 1 vs 2
  EXPECT_NE(differ.output.find("multi/steps.csv: row "), std::string::npos) << differ.output;
  EXPECT_TRUE(fs::exists(tmp / "d.xml"));
}

TEST(CheckCli, BaselineNeverReplacesAnExistingFileWithoutForce) {
  TempDir tmp;
  const fs::path good = run_smoke(tmp, "good");
  write_file(tmp / "mine.yaml", "my notes\n");
  const RunResult r = run_wingman({"baseline", good.string(), "--out", (tmp / "mine.yaml").string()}, tmp.path());
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_EQ(read_file(tmp / "mine.yaml"), "my notes\n");
  const RunResult f = run_wingman({"baseline", good.string(), "--out", (tmp / "mine.yaml").string(), "--force",
                                   "--metrics", "*/nees.mean"}, tmp.path());
  EXPECT_EQ(f.exit_code, 0) << f.output;
  EXPECT_NE(read_file(tmp / "mine.yaml").find("metric: \"single/nees.mean\""), std::string::npos);
}

TEST(CheckCli, EachMetricsOptionTakesOneGlobAndKeepsItsOrder) {
  TempDir tmp;
  const fs::path good = run_smoke(tmp, "good");
  // A glob before the positional argument leaves it positional.
  const RunResult r = run_wingman({"baseline", "--metrics", "single/nees.mean", good.string(), "--metrics",
                                   "multi/table4.total.lead.mse.x", "--out", (tmp / "b.yaml").string()},
                                  tmp.path());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::string yaml = read_file(tmp / "b.yaml");
  EXPECT_LT(yaml.find("single/nees.mean"), yaml.find("multi/table4.total.lead.mse.x"));
  int entries = 0;
  for (const auto& line : lines_of(yaml)) entries += line.rfind("  - metric:", 0) == 0;
  EXPECT_EQ(entries, 2) << yaml;
}

TEST(CheckCli, MonteCarloBaselineIsJudgedSeedBySeed) {
  TempDir tmp;
  const auto mc = [&](const std::string& name, const fs::path& scenario) {
    const RunResult r = run_wingman({"montecarlo", scenario.string(), "--runs", "3", "--out", (tmp / name).string(),
                                     "--no-plots", "-q", "--variant", "multi"}, tmp.path());
    EXPECT_EQ(r.exit_code, 0) << r.output;
    return tmp / name;
  };
  const fs::path ref = mc("ref", kSmoke);
  ASSERT_EQ(run_wingman({"baseline", ref.string(), "--out", (tmp / "mc.yaml").string()}, tmp.path()).exit_code, 0);
  EXPECT_NE(read_file(tmp / "mc.yaml").find("rule: paired"), std::string::npos);
  const RunResult same = run_wingman({"check", ref.string(), "--baseline", (tmp / "mc.yaml").string()}, tmp.path());
  EXPECT_EQ(same.exit_code, 0) << same.output;
  write_file(tmp / "worse.yaml", worsened_smoke());
  const fs::path worse = mc("worse", tmp / "worse.yaml");
  const RunResult fail = run_wingman({"check", worse.string(), "--baseline", (tmp / "mc.yaml").string()}, tmp.path());
  EXPECT_EQ(fail.exit_code, 1) << fail.output;
  EXPECT_NE(fail.output.find("3 seeds in common: ratio now/baseline"), std::string::npos) << fail.output;
  // A single run cannot be judged seed by seed.
  const fs::path one = run_smoke(tmp, "one", "", {"--variant", "multi"});
  expect_bad_input(tmp, {"check", one.string(), "--baseline", (tmp / "mc.yaml").string()}, {"rule paired needs two seeds"});
}

}  // namespace
}  // namespace wingman::app::test
