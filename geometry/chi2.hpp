// Chi-square distribution: CDF and quantile, for the innovation gates of slam/ and the NEES
// bounds of eval/ (docs/design.md, evaluation). Regularised incomplete gamma as in Numerical Recipes §6.2.
#pragma once

namespace wingman::geometry {

// Regularised lower incomplete gamma P(a, x).
double gamma_p(double a, double x);
// P(X <= x) for X ~ chi^2 with k degrees of freedom.
double chi2_cdf(double x, double k);
// x with chi2_cdf(x, k) = p, for p in (0, 1).
double chi2_quantile(double p, double k);

}  // namespace wingman::geometry
