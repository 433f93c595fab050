#include "atmosphere/simplify.h"

#include <algorithm>
#include <cmath>

#include "io/error.h"

namespace skybake {

double TrapezoidColumn(const std::vector<double>& z, const std::vector<double>& v) {
  SKYBAKE_CHECK_EQ(z.size(), v.size());
  double c = 0.0;
  for (size_t i = 0; i + 1 < z.size(); ++i) c += 0.5 * (v[i] + v[i + 1]) * (z[i + 1] - z[i]);
  return c;
}

namespace {

std::vector<double> Exponential(const std::vector<double>& z, double n0, double H) {
  std::vector<double> v(z.size());
  for (size_t i = 0; i < z.size(); ++i) v[i] = n0 * std::exp(-z[i] / H);
  return v;
}

// Fits n0 exp(-z/H) to `values` with the same trapezoid column (see the header).
std::vector<double> FitExponential(const std::vector<double>& z, const std::vector<double>& values, ProfileFit* fit) {
  const double column = TrapezoidColumn(z, values);
  const double peak = *std::max_element(values.begin(), values.end());
  fit->column = column;
  if (!(column > 0.0)) {
    fit->shape = "zero";
    return std::vector<double>(z.size(), 0.0);
  }
  double n0 = values.front(), H = 0.0;
  if (n0 >= 0.5 * peak) {
    fit->shape = "exponential";
    // trapz(n0 e^{-z/H}) increases with H from 0 to n0 * top: bisection in log H.
    if (column >= n0 * z.back()) throw InternalError("exponential fit: the column exceeds n0 x top (a profile growing with altitude)");
    double lo = 1.0, hi = 1e7;
    for (int it = 0; it < 200; ++it) {
      const double mid = std::sqrt(lo * hi);
      (TrapezoidColumn(z, Exponential(z, n0, mid)) < column ? lo : hi) = mid;
    }
    H = std::sqrt(lo * hi);
  } else {
    fit->shape = "exponential (first moment)";
    double m1 = 0.0;
    std::vector<double> zv(z.size());
    for (size_t i = 0; i < z.size(); ++i) zv[i] = z[i] * values[i];
    m1 = TrapezoidColumn(z, zv) / column;
    H = m1;
    n0 = column / TrapezoidColumn(z, Exponential(z, 1.0, H));
  }
  fit->scale_height_m = H;
  fit->ground_value = n0;
  return Exponential(z, n0, H);
}

std::vector<double> FitTent(const std::vector<double>& z, const std::vector<double>& values, ProfileFit* fit) {
  const double column = TrapezoidColumn(z, values);
  fit->column = column;
  fit->shape = "tent";
  if (!(column > 0.0)) return std::vector<double>(z.size(), 0.0);
  std::vector<double> m(z.size());
  for (size_t i = 0; i < z.size(); ++i) m[i] = z[i] * values[i];
  const double c = TrapezoidColumn(z, m) / column;
  for (size_t i = 0; i < z.size(); ++i) m[i] = (z[i] - c) * (z[i] - c) * values[i];
  const double var = TrapezoidColumn(z, m) / column;
  const double w = std::sqrt(6.0 * var);
  std::vector<double> v(z.size());
  for (size_t i = 0; i < z.size(); ++i) v[i] = std::max(0.0, 1.0 - std::abs(z[i] - c) / w);
  const double k = column / TrapezoidColumn(z, v);
  for (double& x : v) x *= k;
  fit->centre_m = c;
  fit->half_width_m = w;
  return v;
}

}  // namespace

VerticalProfiles AnalyticProfiles(const VerticalProfiles& p, std::vector<ProfileFit>* fits) {
  VerticalProfiles out = p;
  std::vector<ProfileFit> f;
  ProfileFit air;
  air.constituent = "air";
  out.air_number_density_m3 = FitExponential(p.altitude_m, p.air_number_density_m3, &air);
  f.push_back(air);
  if (p.has_ozone) {
    ProfileFit oz;
    oz.constituent = "ozone";
    out.ozone_number_density_m3 = FitTent(p.altitude_m, p.ozone_number_density_m3, &oz);
    f.push_back(oz);
  }
  for (size_t k = 0; k < p.aerosols.size(); ++k) {
    ProfileFit a;
    a.constituent = "aerosol." + p.aerosols[k].name;
    out.aerosols[k].shape_per_m = FitExponential(p.altitude_m, p.aerosols[k].shape_per_m, &a);
    f.push_back(a);
  }
  if (fits) *fits = f;
  return out;
}

}  // namespace skybake
