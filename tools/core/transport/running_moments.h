// Running mean, variance and the third and fourth central moments of one Monte-Carlo estimate,
// and how well its standard error is itself known: the adaptive stop of the path tracer
// (transport/path_tracer.cpp) accepts an estimate only where both are small.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

namespace skybake {

struct RunningMoments {
  uint64_t n = 0;
  double mean = 0.0;
  double m2 = 0.0;  // sum of squared deviations from the mean
  double m3 = 0.0;  // sum of cubed deviations
  double m4 = 0.0;  // sum of fourth powers of the deviations

  // One sample. The mean and m2 follow Welford (1962); m3 and m4 the one-pass updates of
  // Pébay, "Formulas for robust, one-pass parallel computation of covariances and arbitrary-order
  // statistical moments", Sandia SAND2008-6212 (2008), eq. 2.9 with n = 1 for the new sample,
  // from the moments before the sample.
  void Add(double x) {
    const double nn = static_cast<double>(n + 1);
    const double delta = x - mean;
    const double dn = delta / nn;
    const double term = delta * dn * (nn - 1.0);
    m4 += term * dn * dn * (nn * nn - 3.0 * nn + 3.0) + 6.0 * dn * dn * m2 - 4.0 * dn * m3;
    m3 += term * dn * (nn - 2.0) - 3.0 * dn * m2;
    mean += delta / nn;
    m2 += delta * (x - mean);
    ++n;
  }

  double Variance() const { return n > 1 ? m2 / static_cast<double>(n - 1) : 0.0; }
  double StdErr() const { return n > 0 ? std::sqrt(Variance() / static_cast<double>(n)) : 0.0; }

  // Relative standard error of the standard error itself. The sample variance s^2 of n samples
  // has Var(s^2) = (mu4 - sigma^4 (n - 3) / (n - 1)) / n (e.g. Cramér, "Mathematical Methods of
  // Statistics", 1946, §27.4), so with the kurtosis kappa = mu4 / sigma^4 its relative standard
  // error is sqrt((kappa - (n - 3)/(n - 1)) / n), and by the delta method that of s (and of the
  // standard error s / sqrt n) is half of it. A Gaussian (kappa = 3) needs n = 50 for 10 %; a
  // heavy-tailed estimate (a strongly forward-peaked phase function seen through next-event
  // estimation: kappa of 10^3 and more) needs tens of thousands of paths before its error bar
  // means what it says. 0 where the samples do not vary (a constant estimate is exact);
  // infinite below 4 samples.
  double StdErrRelativeUncertainty() const {
    if (n < 4) return std::numeric_limits<double>::infinity();
    if (m2 <= 0.0) return 0.0;
    const double nd = static_cast<double>(n);
    const double kappa = nd * m4 / (m2 * m2);
    const double var_rel = (kappa - (nd - 3.0) / (nd - 1.0)) / nd;
    return 0.5 * std::sqrt(std::max(var_rel, 0.0));
  }
};

}  // namespace skybake
