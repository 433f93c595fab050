// 1-D interpolation of tabulated data, with range checks.
//
//   kLinear:    y(x) = y0 + (y1 - y0) t,            t = (x - x0) / (x1 - x0)
//   kLogLinear: y(x) = exp(ln y0 + (ln y1 - ln y0) t)  (densities: exact for exponential decay)
// Log-linear needs y > 0 at both ends of the interval; an interval with a zero end falls back
// to linear (a density that vanishes somewhere, e.g. an aerosol layer with a top). Negative
// values are rejected by the callers that load densities.
//
// Out of range: Eval() throws InternalError (callers must check); callers that accept user
// ranges use Covers() first and report a located InputError.
#pragma once

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

namespace skybake {

enum class Interpolation { kLinear, kLogLinear };

class Interpolant1D {
 public:
  Interpolant1D() = default;
  // x must be strictly increasing (checked), x.size() == y.size() >= 1.
  Interpolant1D(std::vector<double> x, std::vector<double> y, Interpolation mode);

  double Eval(double x) const;
  double operator()(double x) const { return Eval(x); }
  // True when [lo, hi] lies within the table (within a relative tolerance of 1e-12 of the span).
  bool Covers(double lo, double hi) const;
  double x_min() const { return x_.front(); }
  double x_max() const { return x_.back(); }
  const std::vector<double>& x() const { return x_; }
  const std::vector<double>& y() const { return y_; }
  Interpolation mode() const { return mode_; }

 private:
  std::vector<double> x_, y_;
  Interpolation mode_ = Interpolation::kLinear;
};

// Index i such that x[i] <= v < x[i+1] (clamped to [0, n-2]); x strictly increasing, n >= 2.
size_t FindInterval(const std::vector<double>& x, double v);

// FindInterval in O(1) for a fixed grid (the hot lookups of the deterministic sky: altitude
// levels, sun-angle and radius nodes): the interval at the lower edge of each of 4n uniform
// buckets over [x0, x_{n-1}], then a forward scan. Same answer as FindInterval (tested).
class IntervalLocator {
 public:
  IntervalLocator() = default;
  explicit IntervalLocator(const std::vector<double>& x);
  size_t Find(double v) const {
    const size_t n = x_.size();
    if (!(v > x_.front())) return 0;
    if (v >= x_.back()) return n - 2;
    const size_t b = std::min(start_.size() - 1, static_cast<size_t>((v - x_.front()) * scale_));
    size_t i = start_[b];
    while (i + 2 < n && x_[i + 1] <= v) ++i;
    return i;
  }
  const std::vector<double>& x() const { return x_; }

 private:
  std::vector<double> x_;
  std::vector<uint32_t> start_;
  double scale_ = 0.0;
};

// Integral of y over x by the trapezoid rule.
double Trapezoid(const std::vector<double>& x, const std::vector<double>& y);

}  // namespace skybake
