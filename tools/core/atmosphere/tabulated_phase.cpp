#include "atmosphere/tabulated_phase.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "io/csv.h"
#include "io/yaml.h"

namespace skybake {

TabulatedPhase TabulatedPhase::Load(const std::filesystem::path& file, const std::string& angle_column,
                                    const std::string& value_column) {
  CsvTable csv = CsvTable::Load(file);
  Diagnostics d;
  std::vector<double> angle = csv.Numbers(angle_column, d);
  std::vector<double> value = csv.Numbers(value_column, d);
  d.ThrowIfAny();
  const bool degrees = angle_column.size() > 4 && angle_column.compare(angle_column.size() - 4, 4, "_deg") == 0;
  const double to_rad = degrees ? std::numbers::pi / 180.0 : 1.0;
  const double end = degrees ? 180.0 : std::numbers::pi;
  std::vector<double> theta(angle.size());
  for (size_t r = 0; r < csv.rows(); ++r) {
    theta[r] = angle[r] * to_rad;
    if (r > 0 && !(angle[r] > angle[r - 1])) {
      d.Add(csv.LocOfRow(r), fmt::format("column '{}': angles must increase strictly", angle_column));
    }
    if (!(angle[r] >= 0.0 && angle[r] <= end)) {
      d.Add(csv.LocOfRow(r), fmt::format("column '{}': expected an angle from 0 to {}, got {}", angle_column,
                                         FormatExact(end), csv.cell(r, csv.ColumnIndex(angle_column))));
    }
    if (!(value[r] >= 0.0)) {
      d.Add(csv.LocOfRow(r), fmt::format("column '{}': expected a phase value >= 0, got {}", value_column,
                                         csv.cell(r, csv.ColumnIndex(value_column))));
    }
  }
  d.ThrowIfAny();
  if (csv.rows() < 2 || angle.front() != 0.0 || std::abs(angle.back() - end) > 1e-9 * end) {
    throw InputError(csv.LocOfHeader(), fmt::format("a phase table must run from 0 to {} {} (rows at both ends)",
                                                    FormatExact(end), degrees ? "deg" : "rad"));
  }
  theta.back() = std::numbers::pi;
  if (*std::max_element(value.begin(), value.end()) <= 0.0) {
    throw InputError(csv.LocOfHeader(), "column '" + value_column + "': the phase function is 0 at every angle");
  }
  return TabulatedPhase(theta, value, file.filename().string());
}

TabulatedPhase::TabulatedPhase(const std::vector<double>& theta_rad, const std::vector<double>& values, std::string name)
    : name_(std::move(name)) {
  const size_t n = theta_rad.size();
  for (size_t j = n; j-- > 0;) {
    mu_.push_back(j == 0 ? 1.0 : j == n - 1 ? -1.0 : std::cos(theta_rad[j]));
    p_.push_back(values[j]);
  }
  cdf_.assign(n, 0.0);
  for (size_t j = 1; j < n; ++j) {
    cdf_[j] = cdf_[j - 1] + 2.0 * std::numbers::pi * 0.5 * (p_[j - 1] + p_[j]) * (mu_[j] - mu_[j - 1]);
  }
  normalisation_ = 1.0 / cdf_.back();
  for (double& v : p_) v *= normalisation_;
  for (double& v : cdf_) v *= normalisation_;
  cdf_.back() = 1.0;
}

double TabulatedPhase::Eval(size_t, double mu) const {
  mu = std::clamp(mu, -1.0, 1.0);
  size_t j = static_cast<size_t>(std::upper_bound(mu_.begin(), mu_.end(), mu) - mu_.begin());
  j = std::clamp<size_t>(j, 1, mu_.size() - 1);
  const double t = (mu - mu_[j - 1]) / (mu_[j] - mu_[j - 1]);
  return p_[j - 1] + (p_[j] - p_[j - 1]) * t;
}

// Inverse CDF on the interval [mu_{j-1}, mu_j] where P = p0 + (p1 - p0) t, mu = mu_{j-1} + t dmu:
//   2 pi dmu (p0 t + (p1 - p0) t^2 / 2) = r,  r = u - cdf_{j-1},
// solved for t in [0, 1] in the cancellation-free form t = 2 c / (b + sqrt(b^2 + 4 a c)).
double TabulatedPhase::SampleMu(size_t, double u) const {
  size_t j = static_cast<size_t>(std::upper_bound(cdf_.begin(), cdf_.end(), u) - cdf_.begin());
  j = std::clamp<size_t>(j, 1, mu_.size() - 1);
  const double dmu = mu_[j] - mu_[j - 1];
  const double p0 = p_[j - 1], p1 = p_[j];
  const double c = (u - cdf_[j - 1]) / (2.0 * std::numbers::pi * dmu);
  const double a = 0.5 * (p1 - p0), b = p0;
  const double disc = std::max(0.0, b * b + 4.0 * a * c);
  const double denom = b + std::sqrt(disc);
  const double t = denom > 0.0 ? std::clamp(2.0 * c / denom, 0.0, 1.0) : 0.5;
  return std::clamp(mu_[j - 1] + t * dmu, -1.0, 1.0);
}

}  // namespace skybake
