// Statistical helpers for the sampling tests: Pearson's chi-square goodness of fit with pooling of
// sparse bins, and the regularized upper incomplete gamma function for its p-value.
#pragma once
#include <cmath>
#include <string>
#include <vector>

namespace pxf::stat {

// Q(a, x) = Gamma(a, x) / Gamma(a) (Numerical Recipes: series for x < a + 1, else continued fraction).
inline double gamma_q(double a, double x) {
  if (x <= 0.0) return 1.0;
  double gln = std::lgamma(a);
  if (x < a + 1.0) {
    double sum = 1.0 / a, del = sum, ap = a;
    for (int n = 0; n < 1000; ++n) {
      ap += 1.0;
      del *= x / ap;
      sum += del;
      if (std::abs(del) < std::abs(sum) * 1e-15) break;
    }
    return 1.0 - sum * std::exp(-x + a * std::log(x) - gln);
  }
  double b = x + 1.0 - a, c = 1.0 / 1e-300, d = 1.0 / b, h = d;
  for (int i = 1; i < 1000; ++i) {
    double an = -i * (i - a);
    b += 2.0;
    d = an * d + b;
    if (std::abs(d) < 1e-300) d = 1e-300;
    c = b + an / c;
    if (std::abs(c) < 1e-300) c = 1e-300;
    d = 1.0 / d;
    double del = d * c;
    h *= del;
    if (std::abs(del - 1.0) < 1e-15) break;
  }
  return std::exp(-x + a * std::log(x) - gln) * h;
}

struct ChiSquareResult {
  double statistic = 0;
  int dof = 0;
  double p_value = 1;
  std::string problem;  // non-empty: samples where the expected density is zero, etc.
};

// Bins with expected count < min_expected are pooled into one bin (pbrt's chi2test approach).
inline ChiSquareResult chi_square(const std::vector<double>& observed, const std::vector<double>& expected,
                                  double min_expected = 5.0) {
  ChiSquareResult r;
  double pooled_obs = 0, pooled_exp = 0;
  int bins = 0;
  for (size_t i = 0; i < observed.size(); ++i) {
    if (expected[i] <= 0.0 && observed[i] > 0.0) {
      r.problem = "samples in bin " + std::to_string(i) + " where the pdf integrates to 0";
      r.p_value = 0;
      return r;
    }
    if (expected[i] < min_expected) {
      pooled_obs += observed[i];
      pooled_exp += expected[i];
      continue;
    }
    double d = observed[i] - expected[i];
    r.statistic += d * d / expected[i];
    ++bins;
  }
  if (pooled_exp > 0.0) {
    double d = pooled_obs - pooled_exp;
    r.statistic += d * d / pooled_exp;
    ++bins;
  }
  r.dof = bins - 1;
  r.p_value = r.dof > 0 ? gamma_q(0.5 * r.dof, 0.5 * r.statistic) : 1.0;
  return r;
}

}  // namespace pxf::stat
