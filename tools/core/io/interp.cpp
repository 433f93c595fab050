#include "io/interp.h"

#include <algorithm>
#include <cmath>

#include "io/error.h"

namespace skybake {

Interpolant1D::Interpolant1D(std::vector<double> x, std::vector<double> y, Interpolation mode)
    : x_(std::move(x)), y_(std::move(y)), mode_(mode) {
  SKYBAKE_CHECK_EQ(x_.size(), y_.size());
  SKYBAKE_CHECK_GE(x_.size(), size_t{1});
  for (size_t i = 1; i < x_.size(); ++i) SKYBAKE_CHECK_LT(x_[i - 1], x_[i]);
}

size_t FindInterval(const std::vector<double>& x, double v) {
  SKYBAKE_CHECK_GE(x.size(), size_t{2});
  auto it = std::upper_bound(x.begin(), x.end(), v);
  size_t i = it == x.begin() ? 0 : static_cast<size_t>(it - x.begin()) - 1;
  return std::min(i, x.size() - 2);
}

IntervalLocator::IntervalLocator(const std::vector<double>& x) : x_(x) {
  SKYBAKE_CHECK_GE(x.size(), size_t{2});
  for (size_t i = 1; i < x.size(); ++i) SKYBAKE_CHECK_LT(x[i - 1], x[i]);
  const size_t nb = 4 * x.size();
  scale_ = static_cast<double>(nb) / (x.back() - x.front());
  start_.resize(nb);
  // The interval of each bucket's lower edge (FindInterval's answer, by one sweep: the rays of the
  // deterministic sky build one locator per view ray), minus one: v in bucket b may round to
  // just under the edge.
  size_t i = 0;
  for (size_t b = 0; b < nb; ++b) {
    const double edge = x.front() + static_cast<double>(b) / scale_;
    while (i + 2 < x.size() && x[i + 1] <= edge) ++i;
    start_[b] = static_cast<uint32_t>(i > 0 ? i - 1 : 0);
  }
}

bool Interpolant1D::Covers(double lo, double hi) const {
  double span = std::max(1.0, std::abs(x_.back() - x_.front()));
  double tol = 1e-12 * span;
  return lo >= x_.front() - tol && hi <= x_.back() + tol;
}

double Interpolant1D::Eval(double v) const {
  if (!Covers(v, v)) {
    detail::CheckFailed(__FILE__, __LINE__,
                        "interpolation outside the table: " + std::to_string(v) + " not in [" +
                            std::to_string(x_.front()) + ", " + std::to_string(x_.back()) + "]");
  }
  if (x_.size() == 1) return y_[0];
  size_t i = FindInterval(x_, v);
  double t = (v - x_[i]) / (x_[i + 1] - x_[i]);
  t = std::clamp(t, 0.0, 1.0);
  double y0 = y_[i], y1 = y_[i + 1];
  if (mode_ == Interpolation::kLogLinear && y0 > 0.0 && y1 > 0.0) {
    return std::exp(std::log(y0) + (std::log(y1) - std::log(y0)) * t);
  }
  return y0 + (y1 - y0) * t;
}

double Trapezoid(const std::vector<double>& x, const std::vector<double>& y) {
  SKYBAKE_CHECK_EQ(x.size(), y.size());
  double s = 0.0;
  for (size_t i = 1; i < x.size(); ++i) s += 0.5 * (y[i] + y[i - 1]) * (x[i] - x[i - 1]);
  return s;
}

}  // namespace skybake
