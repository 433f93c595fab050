// U.S. Standard Atmosphere 1976, computed from its defining constants.
//
// Source: U.S. Standard Atmosphere, 1976, NOAA-S/T 76-1562 / NASA-TM-X-74335 (USSA76), §1.2-1.3:
//  - geopotential altitude H = r0 z / (r0 + z), r0 = 6356.766 km (eq. 18);
//  - 0-84.852 km geopotential: seven layers of linear molecular-scale temperature T_M(H) with the
//    lapse rates of Table 4 (-6.5, 0, +1, +2.8, 0, -2.8, -2.0 K/km), T_M(0) = 288.15 K;
//  - hydrostatic pressure in each layer (eqs. 33a, 33b):
//      P = P_b [T_Mb / (T_Mb + L_b (H - H_b))]^(g0' M0 / (R* L_b))   (L_b != 0)
//      P = P_b exp(-g0' M0 (H - H_b) / (R* T_Mb))                     (L_b == 0)
//    with P(0) = 101325 Pa, g0' M0 / R* = 34.1631947 K/km;
//  - kinetic temperature T = T_M M/M0, with M/M0 = 1 below 80 km and the Table 8 ratios at 0.5 km
//    steps of geometric altitude from 80 to 86 km (linearly interpolated, as USSA76 prescribes);
//  - mass density rho = P M0 / (R* T_M) (eq. 42); number density n = N_A P / (R* T) (eq. 44).
// Constants (USSA76 Table 2): g0 = 9.80665 m s^-2, M0 = 28.9644 kg/kmol, R* = 8314.32 J/(kmol K),
// N_A = 6.022169e26 /kmol.
//
// Above 86 km (documented extension, docs/atmosphere.md): USSA76 itself models 86-1000 km with
// species diffusion. skybake keeps the USSA76 kinetic temperature T(z) of §1.3 (isothermal
// 186.8673 K to 91 km, the elliptical segment to 110 km, +12 K/km to 120 km, the exponential
// approach to T_inf = 1000 K above) but integrates hydrostatic equilibrium of a *well-mixed* gas
// of constant molecular mass M(86 km) with g(z) = g0 (r0/(r0+z))^2. Against the AFGL 1986 U.S.
// Standard table (which includes diffusion) the number density differs by -0.4 % at 90 km,
// -0.7 % at 100 km, -6.7 % at 110 km and -14 % at 120 km (tests/atmosphere/ussa1976_test.cpp);
// above 86 km the air holds < 6e-6 of the column, so the sky does not see the difference.
#pragma once

namespace skybake::ussa1976 {

inline constexpr double kG0 = 9.80665;          // m s^-2, USSA76 Table 2
inline constexpr double kR0 = 6356766.0;        // m, effective Earth radius for H, USSA76 eq. 18
inline constexpr double kM0 = 28.9644;          // kg/kmol, sea-level mean molecular weight
inline constexpr double kRStar = 8314.32;       // J kmol^-1 K^-1, USSA76 Table 2
inline constexpr double kNA = 6.022169e26;      // kmol^-1, Avogadro's number as defined by USSA76
inline constexpr double kP0 = 101325.0;         // Pa
inline constexpr double kT0 = 288.15;           // K
inline constexpr double kTopOfTablesM = 86000.0;  // m, geometric: end of the defined layers

struct State {
  double geopotential_altitude_m;
  double molecular_temperature_k;  // T_M
  double kinetic_temperature_k;    // T
  double pressure_pa;
  double mass_density_kg_m3;
  double number_density_m3;
  double molecular_weight_kg_kmol;  // M
};

// The state at geometric altitude z (m), 0 <= z <= 1000 km. Above 86 km: see the extension above.
State AtGeometricAltitude(double z_m);

// Geopotential altitude (m') of geometric altitude z (m), USSA76 eq. 18.
double GeopotentialAltitude(double z_m);
// Inverse of GeopotentialAltitude.
double GeometricAltitude(double h_m);

// Base of the layers (geopotential m', T_M in K, P in Pa), exposed for the continuity test.
struct LayerBase {
  double h_m;
  double lapse_k_per_m;
  double t_m_k;
  double p_pa;
};
const LayerBase* Layers(int* count);

}  // namespace skybake::ussa1976
