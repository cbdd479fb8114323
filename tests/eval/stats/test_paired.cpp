// Paired comparison of two variants over seeds (eval/stats/paired.hpp): the sign test and the t
// quantile against tabulated values, the ratio and its interval against hand computation, and
// the reading of metrics.json files, including a malformed one.
#include "eval/stats/paired.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <array>
#include <cmath>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>

namespace wingman::eval {
namespace {

namespace fs = std::filesystem;

struct TempDir {
  fs::path path = fs::temp_directory_path() / ("wingman-paired-test-" + std::to_string(::getpid()));
  TempDir() { fs::create_directories(path); }
  ~TempDir() { fs::remove_all(path); }
};

// metrics.json with Table 4 totals (x, y, z MSE per agent) and Table 5's final MSE.
void write_metrics(const fs::path& dir, const std::map<std::string, std::array<double, 3>>& t4,
                   std::array<double, 3> t5) {
  fs::create_directories(dir);
  nlohmann::json m;
  for (const auto& [agent, mse] : t4) m["table4"]["total"][agent] = {{"mse", mse}, {"steps", 10}};
  m["table5"]["total"] = {{"count", 4}, {"final_mse", t5}, {"init_mse", t5}};
  std::ofstream(dir / "metrics.json") << m.dump();
}

}  // namespace

TEST(Paired, SignTestIsTheExactBinomialTail) {
  EXPECT_NEAR(sign_test_p(9, 9), 2.0 / 512, 1e-12);
  EXPECT_NEAR(sign_test_p(0, 9), 2.0 / 512, 1e-12);
  EXPECT_NEAR(sign_test_p(2, 9), 2.0 * (1 + 9 + 36) / 512, 1e-12);
  EXPECT_NEAR(sign_test_p(7, 9), sign_test_p(2, 9), 1e-12);
  EXPECT_DOUBLE_EQ(sign_test_p(5, 10), 1.0);  // capped: the two tails overlap
  EXPECT_NEAR(sign_test_p(30, 50), 0.2026, 1e-4);
  EXPECT_TRUE(std::isnan(sign_test_p(0, 0)));
}

TEST(Paired, StudentTQuantileMatchesTables) {
  EXPECT_NEAR(student_t_quantile(0.975, 1), 12.7062, 1e-3);
  EXPECT_NEAR(student_t_quantile(0.975, 2), 4.3027, 1e-4);
  EXPECT_NEAR(student_t_quantile(0.975, 8), 2.3060, 1e-4);
  EXPECT_NEAR(student_t_quantile(0.95, 20), 1.7247, 1e-4);
  EXPECT_NEAR(student_t_quantile(0.975, 1000), 1.9623, 1e-4);
  EXPECT_NEAR(student_t_quantile(0.5, 5), 0.0, 1e-9);
  EXPECT_NEAR(student_t_quantile(0.025, 8), -2.3060, 1e-4);
  EXPECT_THROW(student_t_quantile(1.0, 8), std::invalid_argument);
  EXPECT_THROW(student_t_quantile(0.9, 0.5), std::invalid_argument);
}

TEST(Paired, RatioIsTheGeometricMeanWithATInterval) {
  // log ratios 0, ln 2, ln 4: mean ln 2, std ln 2, t(0.975, 2) = 4.3027.
  const PairedRow r = compare_values({1, 1, 1}, {1, 2, 4});
  EXPECT_EQ(r.seeds, 3);
  EXPECT_EQ(r.b_worse, 2);  // equal is not worse
  EXPECT_NEAR(r.ratio, 2.0, 1e-12);
  const double hw = 4.302653 * std::log(2.0) / std::sqrt(3.0);
  EXPECT_NEAR(std::log(r.ratio_lo), std::log(2.0) - hw, 1e-4);
  EXPECT_NEAR(std::log(r.ratio_hi), std::log(2.0) + hw, 1e-4);

  // A constant ratio has a zero-width interval; zero, negative and NaN values leave their seed out.
  const PairedRow c = compare_values({1, 2, 0, 3, NAN, 5}, {0.5, 1, 1, -1, 1, 2.5});
  EXPECT_EQ(c.seeds, 3);
  EXPECT_EQ(c.b_worse, 0);
  EXPECT_NEAR(c.ratio, 0.5, 1e-12);
  EXPECT_NEAR(c.ratio_lo, 0.5, 1e-12);
  EXPECT_NEAR(c.ratio_hi, 0.5, 1e-12);
  EXPECT_NEAR(c.sign_p, 0.25, 1e-12);

  const PairedRow one = compare_values({1}, {2});
  EXPECT_EQ(one.seeds, 1);
  EXPECT_TRUE(std::isnan(one.ratio));
}

TEST(Paired, ReadsRunsAndComparesTheAgentsBothHave) {
  TempDir tmp;
  std::vector<fs::path> a, b;
  for (int s = 0; s < 4; ++s) {
    a.push_back(tmp.path / std::to_string(s) / "multi");
    b.push_back(tmp.path / std::to_string(s) / "single");
    const double k = 1 + s;
    write_metrics(a.back(), {{"lead", {k, 1, 1}}, {"uav1", {1, 1, 1}}, {"uav2", {1, 1, 1}}}, {0.1, 0.1, 0.1});
    // single: lead x always 2x, uav1 y worse on seeds 0-2 only, landmarks 100x.
    write_metrics(b.back(), {{"lead", {2 * k, 1, 1}}, {"uav1", {1, s < 3 ? 3.0 : 0.5, 1}}}, {10, 10, 10});
  }
  const PairedComparison c = compare_paired("multi", a, "single", b);
  EXPECT_EQ(c.seeds, 4);
  ASSERT_EQ(c.rows.size(), 9u);  // lead, uav1 (uav2 is multi's only), landmarks; 3 axes each
  {
    // From runs already read (`wingman montecarlo` reads each file once): the same rows, with the
    // files gone.
    const RunSet ra(a), rb(b);
    for (const auto& d : a) fs::remove(d / "metrics.json");
    for (const auto& d : b) fs::remove(d / "metrics.json");
    const PairedComparison again = compare_paired("multi", ra, "single", rb);
    ASSERT_EQ(again.rows.size(), c.rows.size());
    for (std::size_t i = 0; i < c.rows.size(); ++i) {
      EXPECT_EQ(again.rows[i].agent, c.rows[i].agent);
      EXPECT_EQ(again.rows[i].b_worse, c.rows[i].b_worse);
      EXPECT_DOUBLE_EQ(again.rows[i].ratio, c.rows[i].ratio);
    }
    EXPECT_THROW(compare_paired("multi", ra, "single", rb.slice(0, 3)), std::invalid_argument);
  }
  EXPECT_EQ(c.rows[0].agent, "lead");
  EXPECT_EQ(c.rows[3].agent, "uav1");
  EXPECT_EQ(c.rows[6].agent, "landmarks");
  EXPECT_EQ(c.rows[6].quantity, "table5");
  EXPECT_EQ(c.rows[0].b_worse, 4);
  EXPECT_NEAR(c.rows[0].ratio, 2.0, 1e-12);
  EXPECT_EQ(c.rows[1].b_worse, 0);  // equal everywhere
  EXPECT_NEAR(c.rows[1].ratio, 1.0, 1e-12);
  EXPECT_EQ(c.rows[4].b_worse, 3);
  EXPECT_NEAR(c.rows[4].ratio, std::exp((3 * std::log(3.0) + std::log(0.5)) / 4), 1e-12);
  EXPECT_LT(c.rows[4].ratio_lo, 1.0);  // 3 of 4 is not significant
  EXPECT_NEAR(c.rows[7].ratio, 100.0, 1e-9);
  EXPECT_NEAR(c.rows[7].sign_p, 0.125, 1e-12);

  const std::string text = format_paired(c);
  EXPECT_NE(text.find("single against multi, paired over 4 seeds"), std::string::npos);
  EXPECT_NE(text.find("4 of 4"), std::string::npos);
  // No phases in these files: the totals and Table 5 only.
  EXPECT_EQ(text.find("4 config"), std::string::npos);

  write_paired({c}, tmp.path / "comparison.json");
  std::ifstream in(tmp.path / "comparison.json");
  const auto j = nlohmann::json::parse(in);
  EXPECT_EQ(j[0]["b"], "single");
  EXPECT_EQ(j[0]["rows"].size(), 9u);
  EXPECT_NEAR(j[0]["rows"][0]["ratio_b_over_a"].get<double>(), 2.0, 1e-12);
}

// Table 4 per phase: matched by name, and a seed that lacks the phase or the agent in it is left
// out of that row only.
TEST(Paired, ComparesEachPhaseOfTable4) {
  TempDir tmp;
  std::vector<fs::path> a, b;
  auto phase = [](const std::string& name, double lead_x, bool with_uav1) {
    nlohmann::json p = {{"name", name}, {"agents", {{"lead", {{"mse", {lead_x, 1.0, 1.0}}}}}}};
    if (with_uav1) p["agents"]["uav1"] = {{"mse", {1.0, 1.0, 1.0}}};
    return p;
  };
  for (int s = 0; s < 3; ++s) {
    a.push_back(tmp.path / std::to_string(s) / "multi");
    b.push_back(tmp.path / std::to_string(s) / "single");
    write_metrics(a.back(), {{"lead", {1, 1, 1}}, {"uav1", {1, 1, 1}}}, {1, 1, 1});
    write_metrics(b.back(), {{"lead", {1, 1, 1}}, {"uav1", {1, 1, 1}}}, {1, 1, 1});
    nlohmann::json ma = nlohmann::json::parse(std::ifstream(a.back() / "metrics.json"));
    nlohmann::json mb = nlohmann::json::parse(std::ifstream(b.back() / "metrics.json"));
    ma["table4"]["phases"] = {phase("config1", 1, true), phase("config3", 1, true)};
    // B lists its phases in the other order; config3's lead x is 4x, config1's 0.5x; seed 2's
    // config1 has no uav1.
    mb["table4"]["phases"] = {phase("config3", 4, true), phase("config1", 0.5, s != 2)};
    std::ofstream(a.back() / "metrics.json") << ma.dump();
    std::ofstream(b.back() / "metrics.json") << mb.dump();
  }
  const PairedComparison c = compare_paired("multi", a, "single", b);
  // 6 totals, 3 Table 5, then config1 and config3 for lead and uav1, 3 axes each.
  ASSERT_EQ(c.rows.size(), 9u + 12u);
  const PairedRow& c1_lead_x = c.rows[9];
  EXPECT_EQ(c1_lead_x.phase, "config1");
  EXPECT_EQ(c1_lead_x.agent, "lead");
  EXPECT_EQ(c1_lead_x.seeds, 3);
  EXPECT_NEAR(c1_lead_x.ratio, 0.5, 1e-12);
  EXPECT_EQ(c.rows[12].agent, "uav1");
  EXPECT_EQ(c.rows[12].seeds, 2);  // seed 2's config1 has no uav1 in B
  const PairedRow& c3_lead_x = c.rows[15];
  EXPECT_EQ(c3_lead_x.phase, "config3");
  EXPECT_EQ(c3_lead_x.b_worse, 3);
  EXPECT_NEAR(c3_lead_x.ratio, 4.0, 1e-12);
  EXPECT_TRUE(c.rows[0].phase.empty());

  const std::string text = format_paired(c);
  EXPECT_NE(text.find("4 config3"), std::string::npos);
  write_paired({c}, tmp.path / "comparison.json");
  const auto j = nlohmann::json::parse(std::ifstream(tmp.path / "comparison.json"));
  EXPECT_EQ(j[0]["rows"][15]["phase"], "config3");
}

TEST(Paired, MalformedRunsNameTheFile) {
  TempDir tmp;
  const fs::path a = tmp.path / "a", b = tmp.path / "b";
  write_metrics(a, {{"lead", {1, 1, 1}}}, {1, 1, 1});
  fs::create_directories(b);
  std::ofstream(b / "metrics.json") << "{ not json";
  try {
    compare_paired("a", {a}, "b", {b});
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find((b / "metrics.json").string()), std::string::npos) << e.what();
  }
  // No Table 5 in B.
  nlohmann::json m;
  m["table4"]["total"]["lead"]["mse"] = {1, 1, 1};
  std::ofstream(b / "metrics.json") << m.dump();
  try {
    compare_paired("a", {a}, "b", {b});
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("table5"), std::string::npos) << e.what();
  }
  EXPECT_THROW(compare_paired("a", {a, a}, "b", {b}), std::invalid_argument);
  EXPECT_THROW(compare_paired("a", {tmp.path / "missing"}, "b", {b}), std::runtime_error);
}

}  // namespace wingman::eval
