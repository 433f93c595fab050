#include "optics/rayleigh.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "io/error.h"

namespace skybake::rayleigh {

namespace {
double InverseSquareMicrons(double wavelength_nm) {
  const double l_um = wavelength_nm * 1e-3;
  return 1.0 / (l_um * l_um);
}
}  // namespace

double RefractiveIndexMinusOne(double wavelength_nm, double co2_ppm) {
  SKYBAKE_CHECK(wavelength_nm >= 200.0 && wavelength_nm <= 4000.0);
  const double s2 = InverseSquareMicrons(wavelength_nm);
  const double n300 = (8060.51 + 2480990.0 / (132.274 - s2) + 17455.7 / (39.32957 - s2)) * 1e-8;  // eq. 4
  return n300 * (1.0 + 0.54 * (co2_ppm * 1e-6 - 0.0003));                                          // eq. 19
}

double KingFactor(double wavelength_nm, double co2_ppm) {
  const double s2 = InverseSquareMicrons(wavelength_nm);
  const double f_n2 = 1.034 + 3.17e-4 * s2;                    // eq. 5
  const double f_o2 = 1.096 + 1.385e-3 * s2 + 1.448e-4 * s2 * s2;  // eq. 6
  const double f_ar = 1.00, f_co2 = 1.15;
  const double c = co2_ppm * 1e-4;  // percent by volume
  return (78.084 * f_n2 + 20.946 * f_o2 + 0.934 * f_ar + c * f_co2) / (78.084 + 20.946 + 0.934 + c);  // eq. 23
}

double DepolarizationRatio(double wavelength_nm, double co2_ppm) {
  const double f = KingFactor(wavelength_nm, co2_ppm);
  return 6.0 * (f - 1.0) / (3.0 + 7.0 * f);
}

double CrossSectionM2(double wavelength_nm, double co2_ppm) {
  const double n = 1.0 + RefractiveIndexMinusOne(wavelength_nm, co2_ppm);
  const double n2 = n * n;
  const double lambda_m = wavelength_nm * 1e-9;
  const double ns = kStandardAirNumberDensityM3;
  const double pi3 = std::numbers::pi * std::numbers::pi * std::numbers::pi;
  const double a = (n2 - 1.0) / (n2 + 2.0);
  return 24.0 * pi3 * a * a / (std::pow(lambda_m, 4) * ns * ns) * KingFactor(wavelength_nm, co2_ppm);  // eq. 2
}

double PhaseGamma(double wavelength_nm, double co2_ppm) {
  const double rho = DepolarizationRatio(wavelength_nm, co2_ppm);
  return rho / (2.0 - rho);
}

double Phase(double mu, double gamma) {
  return 3.0 / (4.0 * (1.0 + 2.0 * gamma)) * ((1.0 + 3.0 * gamma) + (1.0 - gamma) * mu * mu) /
         (4.0 * std::numbers::pi);
}

double SamplePhaseMu(double u, double gamma) {
  // CDF(mu) = 3/(8(1+2g)) [(1+3g)(mu+1) + (1-g)(mu^3+1)/3] = u  ->  mu^3 + p mu + q = 0.
  const double a = (1.0 - gamma) / 3.0, b = 1.0 + 3.0 * gamma;
  const double c = b + a - 8.0 * (1.0 + 2.0 * gamma) * u / 3.0;
  const double p = b / a, q = c / a;
  // One real root since p > 0 (Cardano).
  const double disc = std::sqrt(q * q / 4.0 + p * p * p / 27.0);
  const double mu = std::cbrt(-q / 2.0 + disc) + std::cbrt(-q / 2.0 - disc);
  return std::clamp(mu, -1.0, 1.0);
}

}  // namespace skybake::rayleigh
