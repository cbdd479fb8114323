// `wingman check`: each metric of a baseline judged against a results or Monte Carlo directory
// by its rule, with the numbers behind every verdict (docs/check.md):
//   max, min     the value (a Monte Carlo directory: the seeds' mean) against a bound;
//   rel, abs     against the reference, a tolerance of tolerance × |reference| or tolerance;
//   mean         the seeds' mean against the baseline's: the 95 % Welch interval of the
//                difference, a regression when it lies entirely beyond tolerance × |reference|
//                on the worse side (so seed noise alone does not fail);
//   paired       the seeds both have, seed by seed: the geometric-mean ratio now / baseline
//                with its 95 % interval and the exact sign test (eval/stats/paired.hpp), a regression
//                when the interval lies entirely above 1 + tolerance (below 1 / (1 + tolerance)
//                for higher-is-better); with a value <= 0 the mean difference and its interval.
// `better` says which side is worse; a change beyond the tolerance on the better side is
// "improved" (it passes, and says the baseline can be tightened).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "eval/regression/baseline.hpp"
#include "eval/regression/metric_set.hpp"
#include "eval/metrics/run_record.hpp"

namespace wingman::eval {

enum class Verdict { kPass, kImproved, kWarn, kFail };
const char* verdict_name(Verdict v);

struct CheckRow {
  std::string metric;
  int line = 0;  // in the baseline
  double reference = kNaN, now = kNaN;
  double change = kNaN;  // (now - reference) / |reference|; now - reference when the reference is 0
  bool change_relative = true;
  std::string rule;    // "rel 25% (lower is better)"
  std::string detail;  // the numbers behind the verdict
  Verdict verdict = Verdict::kPass;
};

struct CheckReport {
  std::filesystem::path results, baseline;
  std::vector<CheckRow> rows;
  int failed = 0, warned = 0;
};

// One metric: `values` are the results' per-seed values, `seeds` their seeds. CheckInputError
// (naming the baseline's file, line and metric) when the rule cannot be applied: paired without
// two seeds in common, mean without a spread on either side.
CheckRow check_metric(const BaselineEntry& e, const std::vector<double>& values,
                      const std::vector<std::uint64_t>& seeds, const std::filesystem::path& baseline_file);

// Every entry of the baseline. CheckInputError, before judging anything, when the results lack
// a metric the baseline names or are of another kind than a statistical rule needs. A failed run
// (a recorded numerical failure, a Monte Carlo seed montecarlo.json lists as failed) is one more
// failing row, `failed_run`.
CheckReport check_against_baseline(const MetricSet& results, const Baseline& baseline);

// The table printed on stdout: metric, baseline, now, change, rule, verdict, then the details
// of every row that did not pass (of every row with `all_details`), and a summary line.
std::string format_check(const CheckReport& r, bool all_details = false);
// Markdown for a pull-request comment: a summary line and the same table.
std::string check_markdown(const CheckReport& r);
// JUnit XML (testsuites/testsuite/testcase, a <failure> with the numbers for each regression;
// warnings as passing testcases with <system-out>), as GitLab, Jenkins and GitHub reporters read it.
std::string check_junit(const CheckReport& r);
// JSON for scripts: {results, baseline, failed, warned, rows: [...]}.
std::string check_json(const CheckReport& r);

}  // namespace wingman::eval
