// Monte Carlo aggregation (eval/montecarlo): NEES bounds for N runs, fraction of steps inside
// per phase, and the spread of Table 4, on results directories written here by hand.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <random>

#include "eval/stats/montecarlo.hpp"
#include "geometry/chi2.hpp"

using namespace wingman::eval;
namespace fs = std::filesystem;

namespace {
// A run of nees.size() + 1 steps 0.1 s apart in two phases that split it in half (4 NEES: t =
// 0..0.4 s, phases [0, 0.2) and [0.2, 0.4]), with the given NEES per step (step 0 has none) and
// lead x MSE per phase.
void write_run(const fs::path& dir, const std::vector<double>& nees, double mse_phase0, double mse_phase1) {
  fs::create_directories(dir);
  const int steps = static_cast<int>(nees.size()) + 1;
  const double end = 0.1 * (steps - 1), mid = 0.1 * ((steps - 1) / 2);
  nlohmann::json m;
  m["nees"]["dof"] = 6;
  m["nees"]["per_step"] = nlohmann::json::array({nullptr});
  for (double v : nees) m["nees"]["per_step"].push_back(v);
  m["phases"] = {{{"name", "a"}, {"t_start", 0.0}, {"t_end", mid}},
                 {{"name", "b"}, {"t_start", mid}, {"t_end", end}}};
  auto agents = [](double x) { return nlohmann::json{{"lead", {{"mse", {x, 0.0, 0.0}}}}}; };
  m["table4"]["phases"] = {{{"agents", agents(mse_phase0)}}, {{"agents", agents(mse_phase1)}}};
  m["table4"]["total"] = agents(0.5 * (mse_phase0 + mse_phase1));
  std::ofstream(dir / "metrics.json") << m.dump();
  std::ofstream csv(dir / "steps.csv");
  csv << "k,t,nees\n";
  for (int k = 0; k < steps; ++k) csv << k << "," << 0.1 * k << ",0\n";
}

// `runs` runs of 201 steps (phases [0, 10) and [10, 20] s) under root/<r>, NEES ~ chi2(6) white
// in time, times scale(run, step).
std::vector<fs::path> write_chi2_runs(const fs::path& root, int runs, std::uint64_t seed,
                                      const std::function<double(int, int)>& scale) {
  std::mt19937_64 rng(seed);
  std::chi_squared_distribution<double> chi2(6);
  std::vector<fs::path> dirs;
  for (int r = 0; r < runs; ++r) {
    std::vector<double> nees(200);
    for (int k = 0; k < 200; ++k) nees[k] = chi2(rng) * scale(r, k);
    dirs.push_back(root / std::to_string(r));
    write_run(dirs.back(), nees, 0.1, 0.1);
  }
  return dirs;
}

struct TempDir {
  fs::path path = fs::temp_directory_path() / ("wingman-mc-test-" + std::to_string(::getpid()));
  TempDir() { fs::create_directories(path); }
  ~TempDir() { fs::remove_all(path); }
};
}  // namespace

TEST(MonteCarlo, SpreadOfValues) {
  const Spread s = spread_of({1, 2, 3, 4, NAN});
  EXPECT_EQ(s.n, 4);
  EXPECT_DOUBLE_EQ(s.mean, 2.5);
  EXPECT_NEAR(s.std, std::sqrt(5.0 / 3.0), 1e-12);
  EXPECT_DOUBLE_EQ(s.min, 1);
  EXPECT_DOUBLE_EQ(s.max, 4);
}

TEST(MonteCarlo, BoundsAverageAndFractionInsidePerPhase) {
  TempDir tmp;
  // Two runs; bounds for N = 2, dof 6: chi2(12) quantiles / 2 = [2.20, 11.67].
  write_run(tmp.path / "r1", {6, 6, 30, 6}, 0.1, 0.3);
  write_run(tmp.path / "r2", {6, 1, 30, 6}, 0.3, 0.5);
  const MonteCarloSummary m = aggregate_runs("multi", {tmp.path / "r1", tmp.path / "r2"});
  EXPECT_EQ(m.runs, 2);
  EXPECT_EQ(m.dof, 6);
  EXPECT_NEAR(m.lower, wingman::geometry::chi2_quantile(0.025, 12) / 2, 1e-12);
  EXPECT_NEAR(m.upper, wingman::geometry::chi2_quantile(0.975, 12) / 2, 1e-12);
  EXPECT_NEAR(m.lower, 2.2019, 1e-3);
  ASSERT_EQ(m.average_nees.size(), 5u);
  EXPECT_TRUE(std::isnan(m.average_nees[0]));
  EXPECT_DOUBLE_EQ(m.average_nees[2], 3.5);
  EXPECT_DOUBLE_EQ(m.average_nees[3], 30);
  ASSERT_EQ(m.phases.size(), 3u);  // a, b, total
  // Phase a: steps at t = 0.1 (6, inside); phase b: t = 0.2 (3.5, inside), 0.3 (30, outside),
  // 0.4 (6, inside; the last phase keeps its end).
  EXPECT_EQ(m.phases[0].steps, 1);
  EXPECT_EQ(m.phases[0].inside, 1);
  EXPECT_EQ(m.phases[1].steps, 3);
  EXPECT_EQ(m.phases[1].inside, 2);
  EXPECT_EQ(m.phases[2].name, "total");
  EXPECT_EQ(m.phases[2].steps, 4);
  EXPECT_NEAR(m.phases[2].fraction_inside, 0.75, 1e-12);
  // Table 4 spread over the runs.
  ASSERT_EQ(m.phases[0].agents.size(), 1u);
  EXPECT_NEAR(m.phases[0].agents[0].mse[0].mean, 0.2, 1e-12);
  EXPECT_NEAR(m.phases[1].agents[0].mse[0].max, 0.5, 1e-12);
  EXPECT_NEAR(m.phases[2].agents[0].mse[0].mean, 0.3, 1e-12);
}

TEST(MonteCarlo, BlockNeesAveragedOverRunsPerPhase) {
  TempDir tmp;
  write_run(tmp.path / "r1", {6, 6, 6, 6}, 0.1, 0.1);
  write_run(tmp.path / "r2", {6, 6, 6, 6}, 0.1, 0.1);
  auto add_blocks = [&](const char* run, double pos0, double vel1) {
    nlohmann::json m = nlohmann::json::parse(std::ifstream(tmp.path / run / "metrics.json"));
    m["nees"]["per_agent"]["uav1"] = {{"position_per_phase_mean", {pos0, 3.0}},
                                      {"velocity_per_phase_mean", {3.0, vel1}}};
    std::ofstream(tmp.path / run / "metrics.json") << m.dump();
  };
  add_blocks("r1", 2.0, 1.0);
  add_blocks("r2", 4.0, 2.0);
  const MonteCarloSummary m = aggregate_runs("multi", {tmp.path / "r1", tmp.path / "r2"});
  ASSERT_EQ(m.phases.size(), 3u);
  ASSERT_EQ(m.phases[0].blocks.size(), 1u);
  EXPECT_EQ(m.phases[0].blocks[0].agent, "uav1");
  EXPECT_DOUBLE_EQ(m.phases[0].blocks[0].position.mean, 3.0);
  EXPECT_DOUBLE_EQ(m.phases[0].blocks[0].position.max, 4.0);
  EXPECT_DOUBLE_EQ(m.phases[1].blocks[0].velocity.mean, 1.5);
  EXPECT_TRUE(m.phases[2].blocks.empty());  // "total" has none
  EXPECT_NE(format_monte_carlo({m}).find("uav1 pos"), std::string::npos);
}

TEST(MonteCarlo, RunsWithDifferentStepsAreAnErrorNamingTheFile) {
  TempDir tmp;
  write_run(tmp.path / "r1", {6, 6, 6, 6}, 0.1, 0.1);
  write_run(tmp.path / "r2", {6, 6, 6, 6}, 0.1, 0.1);
  nlohmann::json m = nlohmann::json::parse(std::ifstream(tmp.path / "r2" / "metrics.json"));
  m["nees"]["per_step"].push_back(1.0);
  std::ofstream(tmp.path / "r2" / "metrics.json") << m.dump();
  try {
    aggregate_runs("multi", {tmp.path / "r1", tmp.path / "r2"});
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find((tmp.path / "r2" / "metrics.json").string()), std::string::npos)
        << e.what();
  }
  std::ofstream(tmp.path / "r2" / "metrics.json") << "{ not json";
  EXPECT_THROW(aggregate_runs("multi", {tmp.path / "r1", tmp.path / "r2"}), std::runtime_error);
}

TEST(MonteCarlo, PhaseMeanIntervalAndConsistentFilterReferenceFromRuns) {
  TempDir tmp;
  // 40 runs of 201 steps at 10 Hz, phases [0, 10) and [10, 20]; NEES ~ chi2(6), white in time:
  // the interval holds 6 and a consistent filter keeps a phase of 100 steps inside 95 % of them.
  const auto dirs = write_chi2_runs(tmp.path, 40, 11, [](int, int) { return 1.0; });
  const MonteCarloSummary m = aggregate_runs("multi", dirs);
  ASSERT_EQ(m.phases.size(), 3u);
  for (const auto& p : m.phases) {
    const double hw = mean_nees_halfwidth95(p.run_mean_nees);
    EXPECT_EQ(p.run_mean_nees.n, 40);
    // Each run's phase mean of ~100 chi2(6) has std sqrt(12 / 100); over 40 runs the half-width
    // is 1.96 * 0.35 / sqrt(40) = 0.11.
    EXPECT_NEAR(hw, 1.96 * std::sqrt(12.0 / p.steps) / std::sqrt(40.0), 0.04) << p.name;
    EXPECT_LT(std::abs(p.run_mean_nees.mean - 6.0), 3 * hw) << p.name;
    EXPECT_NEAR(p.run_mean_nees.mean, p.mean_nees, 1e-9) << p.name;  // same steps, same runs
    EXPECT_NEAR(p.consistent_median_inside, 0.95, 0.03) << p.name;
  }
  EXPECT_NEAR(m.nees_correlation_time, 0.1, 0.1);  // white: one step
  EXPECT_GT(m.consistent_p_all_phases_at_target, 0.7);
  const std::string table = format_monte_carlo({m});
  EXPECT_NE(table.find("mean NEES [95% CI]"), std::string::npos) << table;
  write_monte_carlo({m}, tmp.path);
  const auto j = nlohmann::json::parse(std::ifstream(tmp.path / "montecarlo.json"));
  EXPECT_TRUE(j["variants"][0]["phases"][0].contains("nees_mean_ci95"));
  EXPECT_TRUE(j["variants"][0]["phases"][0]["consistent_filter"]["median_fraction_inside"].is_number());
}

TEST(MonteCarlo, PoissonBinomialCdf) {
  // Equal probabilities: the binomial. Four fair trials, at most one success: 5 / 16.
  EXPECT_NEAR(poisson_binomial_cdf({0.5, 0.5, 0.5, 0.5}, 1), 5.0 / 16.0, 1e-12);
  // {0.2, 0.7}: P(0) = 0.8 * 0.3, P(1) = 0.2 * 0.3 + 0.8 * 0.7.
  EXPECT_NEAR(poisson_binomial_cdf({0.2, 0.7}, 0), 0.24, 1e-12);
  EXPECT_NEAR(poisson_binomial_cdf({0.2, 0.7}, 1), 0.86, 1e-12);
  EXPECT_NEAR(poisson_binomial_cdf({0.2, 0.7}, 2), 1.0, 1e-12);
  EXPECT_EQ(poisson_binomial_cdf({0.2, 0.7}, -1), 0.0);
}

TEST(MonteCarlo, BatchesEachAgainstTheirOwnBounds) {
  TempDir tmp;
  // Six runs of 201 steps, NEES ~ chi2(6) white in time, in three batches of two. The second
  // batch's runs are overconfident through phase b (NEES x 5), so it fails there; the seventh
  // run is left out.
  const auto dirs = write_chi2_runs(tmp.path, 7, 5, [](int r, int k) {
    return (r == 2 || r == 3) && k >= 100 ? 5.0 : 1.0;
  });
  const BatchTest bt = test_batches("multi", dirs, 2);
  ASSERT_EQ(bt.batches.size(), 3u);
  EXPECT_EQ(bt.batch_size, 2u);
  for (std::size_t i = 0; i < 3; ++i) {
    const MonteCarloSummary m = aggregate_runs("multi", {dirs[2 * i], dirs[2 * i + 1]});
    const Batch& b = bt.batches[i];
    EXPECT_EQ(b.first, 2 * i);
    ASSERT_EQ(b.fraction_inside.size(), 2u);  // phases a and b, not "total"
    EXPECT_DOUBLE_EQ(b.fraction_inside[0], m.phases[0].fraction_inside);
    EXPECT_DOUBLE_EQ(b.fraction_inside[1], m.phases[1].fraction_inside);
    EXPECT_DOUBLE_EQ(b.consistent_p_pass, m.consistent_p_all_phases_at_target);
  }
  EXPECT_EQ(bt.batches[1].label, "runs 3-4");
  EXPECT_LT(bt.batches[1].fraction_inside[1], 0.2);  // mean 30 against bounds for 2 runs of 6 dof, [2.2, 11.7]
  EXPECT_FALSE(bt.batches[1].passed);
  int passed = 0;
  std::vector<double> p;
  for (const auto& b : bt.batches) passed += b.passed, p.push_back(b.consistent_p_pass);
  EXPECT_EQ(bt.passed, passed);
  EXPECT_NEAR(bt.consistent_expected_passes, p[0] + p[1] + p[2], 1e-12);
  EXPECT_NEAR(bt.consistent_p_at_most_passed, poisson_binomial_cdf(p, passed), 1e-12);

  MonteCarloSummary m = aggregate_runs("multi", dirs);
  m.batches = bt;
  const std::string table = format_monte_carlo({m});
  EXPECT_NE(table.find("batches of 2 runs"), std::string::npos) << table;
  write_monte_carlo({m}, tmp.path);
  const auto j = nlohmann::json::parse(std::ifstream(tmp.path / "montecarlo.json"));
  EXPECT_EQ(j["variants"][0]["batch_test"]["batches"].size(), 3u);
  EXPECT_EQ(j["variants"][0]["batch_test"]["passed"].get<int>(), passed);

  EXPECT_THROW(test_batches("multi", {dirs[0]}, 2), std::invalid_argument);
}

// A RunSet reads each metrics.json once: with the files gone afterwards, the aggregate and the
// batch test from it equal those read from the directories, and a slice is its runs' own set.
TEST(MonteCarlo, RunSetReadsEachMetricsFileOnce) {
  TempDir tmp;
  const auto dirs = write_chi2_runs(tmp.path, 6, 11, [](int r, int) { return r == 4 ? 3.0 : 1.0; });
  const MonteCarloSummary from_dirs = aggregate_runs("multi", dirs);
  const BatchTest batches_from_dirs = test_batches("multi", dirs, 2);
  const MonteCarloSummary last_two = aggregate_runs("multi", {dirs[4], dirs[5]});

  const RunSet runs(dirs);
  for (const auto& d : dirs) fs::remove(d / "metrics.json");
  ASSERT_EQ(runs.size(), 6u);
  const MonteCarloSummary m = aggregate_runs("multi", runs);
  ASSERT_EQ(m.average_nees.size(), from_dirs.average_nees.size());
  for (std::size_t k = 1; k < m.average_nees.size(); ++k)
    EXPECT_DOUBLE_EQ(m.average_nees[k], from_dirs.average_nees[k]) << k;
  ASSERT_EQ(m.phases.size(), from_dirs.phases.size());
  for (std::size_t i = 0; i < m.phases.size(); ++i)
    EXPECT_DOUBLE_EQ(m.phases[i].fraction_inside, from_dirs.phases[i].fraction_inside);

  const BatchTest bt = test_batches("multi", runs, 2);
  ASSERT_EQ(bt.batches.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i)
    for (std::size_t p = 0; p < 2; ++p)
      EXPECT_DOUBLE_EQ(bt.batches[i].fraction_inside[p], batches_from_dirs.batches[i].fraction_inside[p]);
  EXPECT_EQ(bt.passed, batches_from_dirs.passed);

  const RunSet tail = runs.slice(4, 2);
  ASSERT_EQ(tail.size(), 2u);
  EXPECT_EQ(tail.dir(0), dirs[4]);
  const MonteCarloSummary t = aggregate_runs("multi", tail);
  EXPECT_DOUBLE_EQ(t.phases[1].mean_nees, last_two.phases[1].mean_nees);
  // Run 4's NEES x 3 is in the slice: about 12 against the six runs' 8.
  EXPECT_GT(t.phases[1].mean_nees, 1.3 * m.phases[1].mean_nees);
  EXPECT_THROW(runs.slice(5, 2), std::out_of_range);

  // Reading: the missing file is named.
  try {
    RunSet again(dirs);
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find((dirs[0] / "metrics.json").string()), std::string::npos) << e.what();
  }
}

// A phase with few steps inside its bounds is explained by which side of them its NEES lies.
TEST(MonteCarlo, SummarySaysWhyAPhaseLiesOutsideItsBounds) {
  MonteCarloSummary m;
  m.label = "multi";
  m.runs = 4;
  m.dof = 18;
  m.lower = 16.0;
  m.upper = 20.0;
  MonteCarloPhase low, high, fine;
  low.name = "phase1";
  low.mean_nees = 9.0;
  low.fraction_inside = 0.0;
  high.name = "phase2";
  high.mean_nees = 40.0;
  high.fraction_inside = 0.1;
  fine.name = "phase3";
  fine.mean_nees = 18.0;
  fine.fraction_inside = 0.95;
  m.phases = {low, high, fine};
  const std::string table = format_monte_carlo({m});
  EXPECT_NE(table.find("phase1: mean NEES 9.00 lies below the bounds: the filter assumes more noise"),
            std::string::npos) << table;
  EXPECT_NE(table.find("phase2: mean NEES 40.00 lies above the bounds"), std::string::npos) << table;
  EXPECT_EQ(table.find("phase3: mean NEES"), std::string::npos) << table;
}
