#include "atmosphere/ussa1976.h"

#include <array>
#include <cmath>

#include "io/error.h"

namespace skybake::ussa1976 {

namespace {

// g0' M0 / R*, in K per m' (USSA76: 34.1631947 K/km').
constexpr double kHydrostatic = kG0 * kM0 / kRStar;

// Layer bases by geopotential altitude (m') and molecular-scale lapse rates (K/m'), USSA76 Table 4.
constexpr std::array<double, 8> kBaseH = {0.0, 11000.0, 20000.0, 32000.0, 47000.0, 51000.0, 71000.0, 84852.0};
constexpr std::array<double, 7> kLapse = {-6.5e-3, 0.0, 1.0e-3, 2.8e-3, 0.0, -2.8e-3, -2.0e-3};

// M/M0 at geometric altitudes 80, 80.5, ..., 86 km, USSA76 Table 8.
constexpr std::array<double, 13> kMolecularWeightRatio = {
    1.000000, 0.999996, 0.999989, 0.999971, 0.999941, 0.999909, 0.999870,
    0.999829, 0.999786, 0.999741, 0.999694, 0.999641, 0.999579};

// The 8 layer bases, derived once from the constants by the hydrostatic equation.
struct Bases {
  std::array<LayerBase, 8> layers;
  Bases() {
    double t = kT0, p = kP0;
    for (size_t i = 0; i < 8; ++i) {
      layers[i] = {kBaseH[i], i < 7 ? kLapse[i] : 0.0, t, p};
      if (i == 7) break;
      double dh = kBaseH[i + 1] - kBaseH[i];
      double l = kLapse[i];
      double t_next = t + l * dh;
      if (l == 0.0) p *= std::exp(-kHydrostatic * dh / t);
      else p *= std::pow(t / t_next, kHydrostatic / l);
      t = t_next;
    }
  }
};
const Bases& GetBases() {
  static const Bases bases;
  return bases;
}

double MolecularWeightRatio(double z_m) {
  if (z_m <= 80000.0) return 1.0;
  double s = (z_m - 80000.0) / 500.0;
  if (s >= 12.0) return kMolecularWeightRatio[12];
  size_t i = static_cast<size_t>(s);
  double t = s - static_cast<double>(i);
  return kMolecularWeightRatio[i] + (kMolecularWeightRatio[i + 1] - kMolecularWeightRatio[i]) * t;
}

// USSA76 §1.3 kinetic temperature above 86 km (z in m).
double KineticTemperatureAbove86(double z_m) {
  const double z = z_m / 1000.0;  // km
  constexpr double kT7 = 186.8673;  // K, 86-91 km
  if (z <= 91.0) return kT7;
  if (z <= 110.0) {
    // Elliptical segment, USSA76 eq. 27: Tc = 263.1905 K, A = -76.3232 K, a = -19.9429 km.
    constexpr double kTc = 263.1905, kA = -76.3232, ka = -19.9429;
    double u = (z - 91.0) / ka;
    return kTc + kA * std::sqrt(std::max(0.0, 1.0 - u * u));
  }
  if (z <= 120.0) return 240.0 + 12.0 * (z - 110.0);  // eq. 29, L = 12 K/km from 240 K
  // eq. 31: T = T_inf - (T_inf - T10) exp(-lambda xi), xi = (z - 120)(r0 + 120)/(r0 + z).
  constexpr double kTinf = 1000.0, kT10 = 360.0, kLambda = 0.01875;  // K, K, 1/km
  const double r0 = kR0 / 1000.0;
  double xi = (z - 120.0) * (r0 + 120.0) / (r0 + z);
  return kTinf - (kTinf - kT10) * std::exp(-kLambda * xi);
}

double Gravity(double z_m) {
  double q = kR0 / (kR0 + z_m);
  return kG0 * q * q;
}

// ln(P(z) / P(86 km)) for the well-mixed extension: -int_{86}^{z} M g / (R* T) dz.
double LogPressureRatioAbove86(double z_m, double molecular_weight) {
  // 8-point Gauss-Legendre on 500 m pieces, split at the temperature breakpoints.
  static const double kX[4] = {0.1834346424956498, 0.5255324099163290, 0.7966664774136267, 0.9602898564975363};
  static const double kW[4] = {0.3626837833783620, 0.3137066458778873, 0.2223810344533745, 0.1012285362903763};
  auto integrand = [&](double z) { return molecular_weight * Gravity(z) / (kRStar * KineticTemperatureAbove86(z)); };
  double sum = 0.0;
  const double breaks[] = {91000.0, 110000.0, 120000.0};
  double a = kTopOfTablesM;
  while (a < z_m) {
    double b = std::min(z_m, a + 500.0);
    for (double br : breaks) {
      if (br > a && br < b) b = br;
    }
    double c = 0.5 * (a + b), h = 0.5 * (b - a);
    for (int k = 0; k < 4; ++k) {
      sum += kW[k] * h * (integrand(c - h * kX[k]) + integrand(c + h * kX[k]));
    }
    a = b;
  }
  return -sum;
}

}  // namespace

const LayerBase* Layers(int* count) {
  *count = 8;
  return GetBases().layers.data();
}

double GeopotentialAltitude(double z_m) { return kR0 * z_m / (kR0 + z_m); }
double GeometricAltitude(double h_m) { return kR0 * h_m / (kR0 - h_m); }

State AtGeometricAltitude(double z_m) {
  SKYBAKE_CHECK(z_m >= -5000.0 && z_m <= 1.0e6);
  State s{};
  s.geopotential_altitude_m = GeopotentialAltitude(z_m);
  if (z_m <= kTopOfTablesM) {
    const Bases& b = GetBases();
    const double h = s.geopotential_altitude_m;
    size_t i = 0;
    while (i < 6 && h >= b.layers[i + 1].h_m) ++i;
    const LayerBase& base = b.layers[i];
    const double dh = h - base.h_m;
    const double t_m = base.t_m_k + base.lapse_k_per_m * dh;
    double p;
    if (base.lapse_k_per_m == 0.0) p = base.p_pa * std::exp(-kHydrostatic * dh / base.t_m_k);
    else p = base.p_pa * std::pow(base.t_m_k / t_m, kHydrostatic / base.lapse_k_per_m);
    const double ratio = MolecularWeightRatio(z_m);
    s.molecular_temperature_k = t_m;
    s.kinetic_temperature_k = t_m * ratio;
    s.pressure_pa = p;
    s.mass_density_kg_m3 = p * kM0 / (kRStar * t_m);
    s.number_density_m3 = kNA * p / (kRStar * s.kinetic_temperature_k);
    s.molecular_weight_kg_kmol = kM0 * ratio;
    return s;
  }
  const State top = AtGeometricAltitude(kTopOfTablesM);
  const double m = top.molecular_weight_kg_kmol;
  s.kinetic_temperature_k = KineticTemperatureAbove86(z_m);
  s.molecular_temperature_k = s.kinetic_temperature_k * kM0 / m;
  s.pressure_pa = top.pressure_pa * std::exp(LogPressureRatioAbove86(z_m, m));
  s.mass_density_kg_m3 = s.pressure_pa * m / (kRStar * s.kinetic_temperature_k);
  s.number_density_m3 = kNA * s.pressure_pa / (kRStar * s.kinetic_temperature_k);
  s.molecular_weight_kg_kmol = m;
  return s;
}

}  // namespace skybake::ussa1976
