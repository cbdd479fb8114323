// The rules of `wingman check` on inputs whose answer is known by hand.
#include "eval/regression/check.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace wingman::eval {
namespace {

const std::filesystem::path kFile = "baseline.yaml";

BaselineEntry entry(Rule rule, double reference, double tolerance, Better better = Better::kLower) {
  BaselineEntry e;
  e.metric = "multi/table4.total.lead.mse.x";
  e.line = 7;
  e.rule = rule;
  e.reference = reference;
  e.tolerance = tolerance;
  e.limit = tolerance;
  e.better = better;
  return e;
}

Verdict judge(const BaselineEntry& e, std::vector<double> values, std::vector<std::uint64_t> seeds = {1}) {
  if (seeds.size() != values.size()) {
    seeds.clear();
    for (std::size_t i = 0; i < values.size(); ++i) seeds.push_back(i + 1);
  }
  return check_metric(e, values, seeds, kFile).verdict;
}

TEST(CheckRules, RelFailsBeyondItsToleranceOnTheWorseSideOnly) {
  const auto e = entry(Rule::kRel, 1.0, 0.25);
  EXPECT_EQ(judge(e, {1.2}), Verdict::kPass);
  EXPECT_EQ(judge(e, {1.3}), Verdict::kFail);
  EXPECT_EQ(judge(e, {0.7}), Verdict::kImproved);
  EXPECT_EQ(judge(entry(Rule::kRel, 1.0, 0.25, Better::kHigher), {0.7}), Verdict::kFail);
  EXPECT_EQ(judge(entry(Rule::kRel, 1.0, 0.25, Better::kEither), {0.7}), Verdict::kFail);
  EXPECT_EQ(judge(entry(Rule::kRel, -2.0, 0.25), {-1.4}), Verdict::kFail);  // |reference| sets the width
  const CheckRow row = check_metric(e, {1.3}, {1}, kFile);
  EXPECT_NEAR(row.change, 0.3, 1e-12);
  EXPECT_NE(row.detail.find("allowed +0.25"), std::string::npos) << row.detail;
}

TEST(CheckRules, AbsAndBoundsCompareTheValueItself) {
  EXPECT_EQ(judge(entry(Rule::kAbs, 0.04, 0.02), {0.059}), Verdict::kPass);
  EXPECT_EQ(judge(entry(Rule::kAbs, 0.04, 0.02), {0.061}), Verdict::kFail);
  EXPECT_EQ(judge(entry(Rule::kMax, 0.04, 0.05), {0.05}), Verdict::kPass);
  EXPECT_EQ(judge(entry(Rule::kMax, 0.04, 0.05), {0.0501}), Verdict::kFail);
  EXPECT_EQ(judge(entry(Rule::kMin, 0.9, 0.8), {0.79}), Verdict::kFail);
  EXPECT_EQ(judge(entry(Rule::kMin, 0.9, 0.8), {0.81}), Verdict::kPass);
  // A Monte Carlo directory: the seeds' mean.
  EXPECT_EQ(judge(entry(Rule::kMax, 0, 1.0), {0.5, 1.4}), Verdict::kPass);
  EXPECT_EQ(judge(entry(Rule::kMax, 0, 1.0), {0.7, 1.4}), Verdict::kFail);
}

TEST(CheckRules, AMissingValueFailsAndAWarnOnlyRuleOnlyWarns) {
  auto e = entry(Rule::kRel, 1.0, 0.25);
  EXPECT_EQ(judge(e, {std::nan("")}), Verdict::kFail);
  e.warn_only = true;
  EXPECT_EQ(judge(e, {std::nan("")}), Verdict::kWarn);
  EXPECT_EQ(judge(e, {3.0}), Verdict::kWarn);
  EXPECT_EQ(judge(e, {1.0}), Verdict::kPass);
}

// Baseline mean 10, std 2 over 10 seeds; now 10 seeds of mean 12 and sample std exactly 2:
// Welch gives 18 dof and the 95 % interval 2 +/- 2.100922 * sqrt(0.8) = [0.120875, 3.879125].
std::vector<double> twelve_std_two() {
  const double r = std::sqrt(2.0);
  return {14, 10, 14, 10, 14, 10, 14, 10, 12 + r, 12 - r};
}

TEST(CheckRules, MeanUsesWelchsIntervalOfTheDifference) {
  auto e = entry(Rule::kMean, 10.0, 0.0);
  e.std = 2;
  e.n = 10;
  const CheckRow row = check_metric(e, twelve_std_two(), {1, 2, 3, 4, 5, 6, 7, 8, 9, 10}, kFile);
  EXPECT_EQ(row.verdict, Verdict::kFail);
  EXPECT_NE(row.detail.find("[+0.1209, +3.879]"), std::string::npos) << row.detail;
  EXPECT_NE(row.detail.find("18.0 dof"), std::string::npos) << row.detail;
  e.tolerance = 0.02;  // margin 0.2 > 0.120875: the difference may be inside the tolerance
  EXPECT_EQ(judge(e, twelve_std_two()), Verdict::kPass);
  e.tolerance = 0.01;  // margin 0.1 < 0.120875
  EXPECT_EQ(judge(e, twelve_std_two()), Verdict::kFail);
  e.tolerance = 0;
  e.better = Better::kHigher;
  EXPECT_EQ(judge(e, twelve_std_two()), Verdict::kImproved);
}

TEST(CheckRules, MeanDoesNotFailOnSeedNoise) {
  auto e = entry(Rule::kMean, 10.0, 0.0);
  e.std = 2;
  e.n = 10;
  auto v = twelve_std_two();
  for (double& x : v) x -= 1.5;  // mean 10.5: interval [-1.379, +2.379] holds 0
  EXPECT_EQ(judge(e, v), Verdict::kPass);
  // One run against a Monte Carlo baseline borrows the baseline's spread (se 2.1, 10.8 dof):
  // 12 is inside the interval's reach, 16 beyond it.
  EXPECT_EQ(judge(e, {12.0}), Verdict::kPass);
  EXPECT_EQ(judge(e, {16.0}), Verdict::kFail);
}

// Baseline logs {0, 0.2, -0.2, 0} (mean 0, variance 0.02667 over 4 seeds), now the same shifted
// by 1: Welch on the logs gives 6 dof and exp(1 +/- 2.446912 * 0.11547) = [2.049, 3.606].
TEST(CheckRules, MeanOfPositiveValuesJudgesTheGeometricMeanRatio) {
  auto e = entry(Rule::kMean, 1.0, 0.1);
  e.n = 4;
  e.per_seed = {{1, 1.0}, {2, std::exp(0.2)}, {3, std::exp(-0.2)}, {4, 1.0}};
  const std::vector<double> shifted = {std::exp(1.0), std::exp(1.2), std::exp(0.8), std::exp(1.0)};
  const CheckRow row = check_metric(e, shifted, {5, 6, 7, 8}, kFile);
  EXPECT_EQ(row.verdict, Verdict::kFail);
  EXPECT_NE(row.detail.find("ratio now/baseline 2.718, 95% CI [2.049, 3.606] (Welch on the logs, 6.0 dof)"),
            std::string::npos) << row.detail;
  e.tolerance = 1.5;  // up to x2.5 allowed: 2.049 is inside
  EXPECT_EQ(judge(e, shifted), Verdict::kPass);
  // One run borrows the baseline's spread and its 3 dof: exp(0.3 +/- 3.182446 * 0.182574) = [0.755, 2.413].
  e.tolerance = 0.1;
  const CheckRow one = check_metric(e, {std::exp(0.3)}, {9}, kFile);
  EXPECT_EQ(one.verdict, Verdict::kPass);
  EXPECT_NE(one.detail.find("95% CI [0.755, 2.413]"), std::string::npos) << one.detail;
  EXPECT_NE(one.detail.find("3.0 dof"), std::string::npos) << one.detail;
}

TEST(CheckRules, MeanWithoutASpreadOnEitherSideIsBadInput) {
  auto e = entry(Rule::kMean, 10.0, 0.1);
  EXPECT_THROW(check_metric(e, {11.0}, {1}, kFile), CheckInputError);
}

BaselineEntry paired(std::vector<double> per_seed, double tolerance, Better better = Better::kLower) {
  auto e = entry(Rule::kPaired, 0, tolerance, better);
  for (std::size_t i = 0; i < per_seed.size(); ++i) e.per_seed[i + 1] = per_seed[i];
  return e;
}

TEST(CheckRules, PairedJudgesTheGeometricMeanRatioSeedBySeed) {
  const auto e = paired({1, 2, 4, 8}, 0.1);
  const CheckRow twice = check_metric(e, {2, 4, 8, 16}, {1, 2, 3, 4}, kFile);
  EXPECT_EQ(twice.verdict, Verdict::kFail);
  EXPECT_NE(twice.detail.find("ratio now/baseline 2, 95% CI [2, 2]"), std::string::npos) << twice.detail;
  EXPECT_NE(twice.detail.find("worse on 4 of 4 seeds that changed (sign test p = 0.125)"), std::string::npos)
      << twice.detail;
  EXPECT_EQ(judge(e, {1.05, 2.1, 4.2, 8.4}), Verdict::kPass);
  EXPECT_EQ(judge(e, {0.5, 1, 2, 4}), Verdict::kImproved);
  EXPECT_EQ(judge(paired({1, 2, 4, 8}, 0.1, Better::kHigher), {0.5, 1, 2, 4}), Verdict::kFail);
  // Identical values: ratio 1, no seed changed.
  const CheckRow same = check_metric(e, {1, 2, 4, 8}, {1, 2, 3, 4}, kFile);
  EXPECT_EQ(same.verdict, Verdict::kPass);
  EXPECT_NE(same.detail.find("on 0 of 0 seeds"), std::string::npos) << same.detail;
}

TEST(CheckRules, PairedSurvivesSeedNoise) {
  // Log ratios 0.1 and 0.3: mean 0.2, sd 0.1414 over 2 seeds, t(0.975, 1) = 12.706:
  // exp(0.2 +/- 1.2706) = [0.3428, 4.352], which holds 1.1: not a regression.
  const auto e = paired({1, 1}, 0.1);
  const CheckRow row = check_metric(e, {std::exp(0.1), std::exp(0.3)}, {1, 2}, kFile);
  EXPECT_EQ(row.verdict, Verdict::kPass);
  EXPECT_NE(row.detail.find("95% CI [0.3428, 4.352]"), std::string::npos) << row.detail;
}

TEST(CheckRules, PairedUsesOnlyTheSeedsBothSidesHave) {
  const auto e = paired({1, 2, 4, 8}, 0.1);  // seeds 1..4
  // Seeds 3, 4 in common (ratio 2 on both); seeds 5, 6 are not in the baseline.
  EXPECT_EQ(check_metric(e, {8, 16, 100, 100}, {3, 4, 5, 6}, kFile).verdict, Verdict::kFail);
  try {
    check_metric(e, {8, 16}, {4, 5}, kFile);
    FAIL() << "one seed in common must be refused";
  } catch (const CheckInputError& err) {
    EXPECT_NE(std::string(err.what()).find("baseline.yaml:7: metric multi/table4.total.lead.mse.x"), std::string::npos)
        << err.what();
  }
}

TEST(CheckRules, PairedWithValuesAtZeroComparesDifferences) {
  // Differences 0.1 on every seed: interval [0.1, 0.1], margin 0.1 * mean(0, 0.01, 0.02) = 0.001.
  const auto e = paired({0, 0.01, 0.02}, 0.1);
  const CheckRow row = check_metric(e, {0.1, 0.11, 0.12}, {1, 2, 3}, kFile);
  EXPECT_EQ(row.verdict, Verdict::kFail);
  EXPECT_NE(row.detail.find("mean difference now - baseline +0.1"), std::string::npos) << row.detail;
  EXPECT_EQ(judge(e, {0, 0.0105, 0.0205}), Verdict::kPass);
}

}  // namespace
}  // namespace wingman::eval
