#include "eval/check.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>

#include "eval/montecarlo.hpp"
#include "eval/paired.hpp"

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

// mean: Welch's 95 % interval of now's mean minus the baseline's; a side with one value borrows
// the other side's spread (the same filter on other seeds).
void judge_mean(const BaselineEntry& e, const Sample& now, CheckRow& row, const std::string& where) {
  Sample ref{e.reference, e.n > 1 ? e.std * e.std : kNaN, e.n};
  double dof_a = ref.n - 1, dof_b = now.n - 1;
  if (!std::isfinite(ref.var)) ref.var = now.var, dof_a = dof_b;
  Sample b = now;
  if (!std::isfinite(b.var)) b.var = ref.var, dof_b = dof_a;
  if (!std::isfinite(ref.var) || dof_a < 1)
    throw CheckInputError(fmt::format("{}: rule mean needs the spread of at least two seeds, in the baseline "
                                      "(std, n) or in the results; use rel or abs for a single run", where));
  const double va = ref.var / ref.n, vb = b.var / b.n, se = std::sqrt(va + vb);
  const double dof = se > 0 ? (va + vb) * (va + vb) / (va * va / dof_a + vb * vb / dof_b) : dof_a + dof_b;
  const double q = student_t_quantile(0.975, std::max(1.0, dof));
  const double d = now.mean - ref.mean, lo = d - q * se, hi = d + q * se, margin = e.tolerance * std::abs(ref.mean);
  row.verdict = judge_interval(lo, hi, margin, -margin, e.better);
  row.detail = fmt::format("mean of {} seeds {:.6g} against {:.6g} (std {:.4g}, n {}): difference {}, 95% CI "
                           "[{}, {}] (Welch, {:.1f} dof); a regression when the CI lies beyond {}{:.4g}",
                           now.n, now.mean, ref.mean, e.std, e.n, signed_num(d), signed_num(lo), signed_num(hi), dof,
                           worse_sign(e.better), margin);
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
  const std::string limit = e.better == Better::kHigher  ? fmt::format("below {:.4g}", 1 / up)
                            : e.better == Better::kLower ? fmt::format("above {:.4g}", up)
                                                         : fmt::format("outside [{:.4g}, {:.4g}]", 1 / up, up);
  row.verdict = judge_interval(r.ratio_lo, r.ratio_hi, up, 1 / up, e.better);
  row.detail = fmt::format("{} seeds in common: ratio now/baseline {:.4g}, 95% CI [{:.4g}, {:.4g}] (geometric mean); "
                           "{}; a regression when the CI lies {}", p.a.size(), r.ratio, r.ratio_lo, r.ratio_hi,
                           p.counts(e.better), limit);
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
  const auto positive = [](const std::vector<double>& v) {
    return std::all_of(v.begin(), v.end(), [](double x) { return x > 0; });
  };
  if (positive(p.a) && positive(p.b)) judge_ratio(e, p, row);
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
  if (e.rule == Rule::kMean) judge_mean(e, now, row, where);
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
