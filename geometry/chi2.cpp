#include "geometry/chi2.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

namespace wingman::geometry {

namespace {
double gamma_series(double a, double x) {
  double ap = a, sum = 1.0 / a, del = sum;
  for (int n = 0; n < 1000; ++n) {
    ap += 1;
    del *= x / ap;
    sum += del;
    if (std::abs(del) < std::abs(sum) * 1e-15) break;
  }
  return sum * std::exp(-x + a * std::log(x) - std::lgamma(a));
}
double gamma_continued_fraction(double a, double x) {  // Q(a, x) by Lentz's method
  const double tiny = 1e-300;
  double b = x + 1 - a, c = 1 / tiny, d = 1 / b, h = d;
  for (int i = 1; i < 1000; ++i) {
    const double an = -i * (i - a);
    b += 2;
    d = an * d + b;
    if (std::abs(d) < tiny) d = tiny;
    c = b + an / c;
    if (std::abs(c) < tiny) c = tiny;
    d = 1 / d;
    const double del = d * c;
    h *= del;
    if (std::abs(del - 1) < 1e-15) break;
  }
  return std::exp(-x + a * std::log(x) - std::lgamma(a)) * h;
}
}  // namespace

double gamma_p(double a, double x) {
  if (x <= 0) return 0.0;
  if (x < a + 1) return gamma_series(a, x);
  return 1.0 - gamma_continued_fraction(a, x);
}

double chi2_cdf(double x, double k) { return gamma_p(k / 2, x / 2); }

double chi2_quantile(double p, double k) {
  if (!(p > 0 && p < 1) || !(k > 0)) throw std::invalid_argument("chi2_quantile: p in (0,1), k > 0");
  // Bracket, then bisect: the CDF is monotone and this runs rarely (gates are cached).
  double lo = 0, hi = std::max(1.0, k);
  while (chi2_cdf(hi, k) < p) hi *= 2;
  for (int i = 0; i < 200 && hi - lo > 1e-12 * std::max(1.0, hi); ++i) {
    const double mid = 0.5 * (lo + hi);
    (chi2_cdf(mid, k) < p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace wingman::geometry
