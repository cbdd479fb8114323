#include "eval/regression/check.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <optional>

#include "eval/stats/montecarlo.hpp"
#include "eval/stats/paired.hpp"

namespace wingman::eval {
namespace {

namespace fs = std::filesystem;

// An interval [lo, hi] for "now minus (or over) the reference", judged against the margins `up`
// and `down` around no change (0 for a difference, 1 for a ratio): a regression lies wholly
// beyond the margin on the worse side, so it must exceed both seed noise and the tolerance.
Verdict judge_interval(double lo, double hi, double up, double down, Better better) {
  const bool above = lo > up, below = hi < down;
  switch (better) {
    case Better::kLower: return above ? Verdict::kFail : below ? Verdict::kImproved : Verdict::kPass;
    case Better::kHigher: return below ? Verdict::kFail : above ? Verdict::kImproved : Verdict::kPass;
    case Better::kEither: return above || below ? Verdict::kFail : Verdict::kPass;
  }
  return Verdict::kPass;
}

std::string signed_num(double v) { return fmt::format("{:+.4g}", v); }

// The sign of a worse change: "+" when lower is better, "-" when higher is, "+/-" for either.
const char* worse_sign(Better b) { return b == Better::kLower ? "+" : b == Better::kHigher ? "-" : "+/-"; }

// Where a ratio's interval must lie for a regression.
std::string ratio_limit(const BaselineEntry& e) {
  const double up = 1 + e.tolerance;
  if (e.better == Better::kHigher) return fmt::format("below {:.4g}", 1 / up);
  if (e.better == Better::kLower) return fmt::format("above {:.4g}", up);
  return fmt::format("outside [{:.4g}, {:.4g}]", 1 / up, up);
}

std::string rule_text(const BaselineEntry& e) {
  const char* side = worse_sign(e.better);
  switch (e.rule) {
    case Rule::kMax: return fmt::format("max {:.4g}", e.limit);
    case Rule::kMin: return fmt::format("min {:.4g}", e.limit);
    case Rule::kRel: return fmt::format("rel {}{:.4g}%", side, 100 * e.tolerance);
    case Rule::kAbs: return fmt::format("abs {}{:.4g}", side, e.tolerance);
    case Rule::kMean: return fmt::format("mean {}{:.4g}%", side, 100 * e.tolerance);
    case Rule::kPaired: return fmt::format("paired {}{:.4g}%", side, 100 * e.tolerance);
  }
  return "?";
}

// max, min, rel, abs: the value (the seeds' mean) against a bound or a tolerance.
void judge_plain(const BaselineEntry& e, CheckRow& row) {
  const double v = row.now;
  if (e.rule == Rule::kMax || e.rule == Rule::kMin) {
    const bool bad = e.rule == Rule::kMax ? v > e.limit : v < e.limit;
    row.verdict = bad ? Verdict::kFail : Verdict::kPass;
    row.detail = fmt::format("{:.6g} {} the {} {:.6g}", v, bad ? "breaks" : "keeps", rule_name(e.rule), e.limit);
    return;
  }
  const double allowed = e.rule == Rule::kRel ? e.tolerance * std::abs(e.reference) : e.tolerance;
  const double d = v - e.reference;
  row.verdict = judge_interval(d, d, allowed, -allowed, e.better);
  row.detail = fmt::format("{:.6g} against {:.6g}: {} ({}), allowed {}{:.4g}", v, e.reference, signed_num(d),
                           std::isfinite(row.change) && row.change_relative ? fmt::format("{:+.1f}%", 100 * row.change) : "-",
                           worse_sign(e.better), allowed);
}

struct Sample {
  double mean = kNaN, var = kNaN;
  int n = 0;
};
Sample sample_of(const std::vector<double>& v) {
  const Spread s = spread_of(v);
  return {s.mean, s.n > 1 ? s.std * s.std : kNaN, s.n};
}

// Welch's 95 % interval of mean(b) - mean(a) from two samples' means, variances and sizes; a
// side with one value borrows the other side's variance, and the interval then has that side's
// degrees of freedom. nullopt when neither side has a spread.
struct Interval {
  double d = 0, lo = 0, hi = 0, dof = 0;
};
std::optional<Interval> welch(Sample a, Sample b) {
  double dof_a = a.n - 1, dof_b = b.n - 1;
  const bool borrowed = !std::isfinite(a.var) || !std::isfinite(b.var);
  if (!std::isfinite(a.var)) a.var = b.var, dof_a = dof_b;
  if (!std::isfinite(b.var)) b.var = a.var, dof_b = dof_a;
  if (!std::isfinite(a.var) || dof_a < 1) return std::nullopt;
  const double va = a.var / a.n, vb = b.var / b.n, se = std::sqrt(va + vb);
  const double dof = borrowed ? std::min(dof_a, dof_b)
                     : se > 0 ? (va + vb) * (va + vb) / (va * va / dof_a + vb * vb / dof_b)
                              : dof_a + dof_b;
  const double q = student_t_quantile(0.975, std::max(1.0, dof)), d = b.mean - a.mean;
  return Interval{d, d - q * se, d + q * se, dof};
}

// Whether a ratio (or a log) of these values means something.
bool all_positive(const std::vector<double>& v) {
  return std::all_of(v.begin(), v.end(), [](double x) { return x > 0; });
}

Sample log_sample(const std::vector<double>& v) {
  std::vector<double> logs;
  for (double x : v) logs.push_back(std::log(x));
  return sample_of(logs);
}

// mean: the seeds' mean against the baseline's by Welch's interval. With every value > 0 and the
// baseline's per-seed values, on the logs (errors and the NEES are skewed; their logs are close
// to normal): the geometric-mean ratio against 1 + tolerance, as the paired rule judges it.
void judge_mean(const BaselineEntry& e, const std::vector<double>& values, CheckRow& row, const std::string& where) {
  std::vector<double> ref, now;
  for (const auto& [seed, v] : e.per_seed) ref.push_back(v);
  for (double v : values)
    if (std::isfinite(v)) now.push_back(v);
  const bool logs = ref.size() >= 2 && all_positive(ref) && all_positive(now);
  const Sample a = logs ? log_sample(ref) : Sample{e.reference, e.n > 1 ? e.std * e.std : kNaN, e.n};
  const Sample b = logs ? log_sample(now) : sample_of(now);
  const auto ci = welch(a, b);
  if (!ci)
    throw CheckInputError(fmt::format("{}: rule mean needs the spread of at least two seeds, in the baseline "
                                      "(per_seed, or std and n) or in the results; use rel or abs for a single run", where));
  const std::string seeds = fmt::format("{} seed{} against {}", now.size(), now.size() == 1 ? "" : "s", e.n);
  if (logs) {
    const double up = 1 + e.tolerance;
    row.verdict = judge_interval(std::exp(ci->lo), std::exp(ci->hi), up, 1 / up, e.better);
    row.detail = fmt::format("{}: geometric-mean ratio now/baseline {:.4g}, 95% CI [{:.4g}, {:.4g}] (Welch on the "
                             "logs, {:.1f} dof); a regression when the CI lies {}", seeds, std::exp(ci->d),
                             std::exp(ci->lo), std::exp(ci->hi), ci->dof, ratio_limit(e));
    return;
  }
  const double margin = e.tolerance * std::abs(a.mean);
  row.verdict = judge_interval(ci->lo, ci->hi, margin, -margin, e.better);
  row.detail = fmt::format("{}: mean {:.6g} against {:.6g}, difference {}, 95% CI [{}, {}] (Welch, {:.1f} dof); a "
                           "regression when the CI lies beyond {}{:.4g}", seeds, b.mean, a.mean, signed_num(ci->d),
                           signed_num(ci->lo), signed_num(ci->hi), ci->dof, worse_sign(e.better), margin);
}

// The seeds' values of a paired comparison and the sign test over the seeds that changed.
struct Pairs {
  std::vector<double> a, b;  // baseline, now; the same seed at the same index
  int worse = 0, better = 0;
  double sign_p = 1.0;
  std::string counts(Better direction) const {
    return fmt::format("{} on {} of {} seeds that changed (sign test p = {:.3g})",
                       direction == Better::kEither ? "higher" : "worse", worse, worse + better, sign_p);
  }
};

// paired, all values > 0: the geometric-mean ratio and its interval against 1 + tolerance.
void judge_ratio(const BaselineEntry& e, const Pairs& p, CheckRow& row) {
  const PairedRow r = compare_values(p.a, p.b);
  const double up = 1 + e.tolerance;
  row.verdict = judge_interval(r.ratio_lo, r.ratio_hi, up, 1 / up, e.better);
  row.detail = fmt::format("{} seeds in common: ratio now/baseline {:.4g}, 95% CI [{:.4g}, {:.4g}] (geometric mean); "
                           "{}; a regression when the CI lies {}", p.a.size(), r.ratio, r.ratio_lo, r.ratio_hi,
                           p.counts(e.better), ratio_limit(e));
}

// paired with a value <= 0 (a ratio means nothing): the mean difference and its t interval.
void judge_difference(const BaselineEntry& e, const Pairs& p, CheckRow& row) {
  std::vector<double> d(p.a.size());
  for (std::size_t i = 0; i < d.size(); ++i) d[i] = p.b[i] - p.a[i];
  const Spread s = spread_of(d);
  const double half = student_t_quantile(0.975, s.n - 1) * s.std / std::sqrt(s.n);
  const double margin = e.tolerance * std::abs(spread_of(p.a).mean);
  row.verdict = judge_interval(s.mean - half, s.mean + half, margin, -margin, e.better);
  row.detail = fmt::format("{} seeds in common: mean difference now - baseline {}, 95% CI [{}, {}]; {}; a regression "
                           "when the CI lies beyond {}{:.4g}", p.a.size(), signed_num(s.mean), signed_num(s.mean - half),
                           signed_num(s.mean + half), p.counts(e.better), worse_sign(e.better), margin);
}

// paired: seed by seed on the seeds both sides have.
void judge_paired(const BaselineEntry& e, const std::vector<double>& values, const std::vector<std::uint64_t>& seeds,
                  CheckRow& row, const std::string& where) {
  Pairs p;
  for (std::size_t i = 0; i < seeds.size(); ++i)
    if (auto it = e.per_seed.find(seeds[i]); it != e.per_seed.end() && std::isfinite(values[i]))
      p.a.push_back(it->second), p.b.push_back(values[i]);
  if (p.a.size() < 2)
    throw CheckInputError(fmt::format("{}: rule paired needs two seeds that both the baseline's per_seed and the "
                                      "results have; they share {} (results: seeds {}); use rule mean for other seeds",
                                      where, p.a.size(), fmt::join(seeds, ", ")));
  const bool lower = e.better != Better::kHigher;
  for (std::size_t i = 0; i < p.a.size(); ++i)
    if (p.b[i] != p.a[i]) ++((p.b[i] > p.a[i]) == lower ? p.worse : p.better);
  if (p.worse + p.better > 0) p.sign_p = sign_test_p(p.worse, p.worse + p.better);
  if (all_positive(p.a) && all_positive(p.b)) judge_ratio(e, p, row);
  else judge_difference(e, p, row);
}

}  // namespace

const char* verdict_name(Verdict v) {
  switch (v) {
    case Verdict::kPass: return "pass";
    case Verdict::kImproved: return "improved";
    case Verdict::kWarn: return "WARN";
    case Verdict::kFail: return "FAIL";
  }
  return "?";
}

CheckRow check_metric(const BaselineEntry& e, const std::vector<double>& values,
                      const std::vector<std::uint64_t>& seeds, const fs::path& baseline_file) {
  const std::string where = fmt::format("{}:{}: metric {}", baseline_file.string(), e.line, e.metric);
  CheckRow row;
  row.metric = e.metric;
  row.line = e.line;
  row.reference = e.reference;
  row.rule = rule_text(e);
  const Sample now = sample_of(values);
  row.now = now.mean;
  row.change_relative = e.reference != 0;
  row.change = row.change_relative ? (now.mean - e.reference) / std::abs(e.reference) : now.mean - e.reference;
  if (now.n == 0) {
    row.verdict = e.warn_only ? Verdict::kWarn : Verdict::kFail;
    row.detail = "the results have no value for it (null: an empty set of steps, or a filter that broke down)";
    return row;
  }
  if (e.rule == Rule::kMean) judge_mean(e, values, row, where);
  else if (e.rule == Rule::kPaired) judge_paired(e, values, seeds, row, where);
  else judge_plain(e, row);
  if (row.verdict == Verdict::kFail && e.warn_only) row.verdict = Verdict::kWarn;
  return row;
}

CheckReport check_against_baseline(const MetricSet& results, const Baseline& baseline) {
  if (!baseline.scenario.empty() && !results.scenario.empty() && baseline.scenario != results.scenario)
    throw CheckInputError(fmt::format("{}: a baseline of scenario '{}', but {} holds scenario '{}'",
                                      baseline.file.string(), baseline.scenario, results.dir.string(), results.scenario));
  for (const BaselineEntry& e : baseline.entries)
    if (!results.has(e.metric))
      throw CheckInputError(fmt::format("{}:{}: metric {}: {} has no such metric{}", baseline.file.string(), e.line,
                                        e.metric, results.dir.string(),
                                        results.monte_carlo == (baseline.kind == "montecarlo") ? ""
                                            : fmt::format(" (the baseline is of a {} directory)", baseline.kind)));
  CheckReport r;
  r.results = results.dir;
  r.baseline = baseline.file;
  for (const BaselineEntry& e : baseline.entries)
    r.rows.push_back(check_metric(e, results.values.at(e.metric), results.seeds, baseline.file));
  for (const std::string& failure : results.failures) {
    CheckRow row;
    row.metric = "failed_run";
    row.rule = "none allowed";
    row.detail = failure;
    row.verdict = Verdict::kFail;
    r.rows.push_back(row);
  }
  for (const CheckRow& row : r.rows) {
    r.failed += row.verdict == Verdict::kFail;
    r.warned += row.verdict == Verdict::kWarn;
  }
  return r;
}

}  // namespace wingman::eval
