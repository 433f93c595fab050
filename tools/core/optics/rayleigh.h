// Rayleigh scattering by air molecules: cross-section from the refractive index of air and the
// King factor, and the depolarised Rayleigh phase function.
//
// Source: B. A. Bodhaine, N. B. Wood, E. G. Dutton, J. R. Slusser, "On Rayleigh optical depth
// calculations", J. Atmos. Oceanic Technol. 16, 1854-1861 (1999):
//   (n-1)_300 10^8 = 8060.51 + 2480990/(132.274 - lambda^-2) + 17455.7/(39.32957 - lambda^-2)
//                    (eq. 4, Peck & Reeder 1972; lambda in um, 288.15 K, 1013.25 hPa, 300 ppm CO2)
//   (n-1)_CO2 = (n-1)_300 [1 + 0.54 (C_CO2 - 0.0003)]              (eq. 19; C_CO2 by volume)
//   F(N2) = 1.034 + 3.17e-4 lambda^-2                               (eq. 5, Bates 1984)
//   F(O2) = 1.096 + 1.385e-3 lambda^-2 + 1.448e-4 lambda^-4         (eq. 6, Bates 1984)
//   F(air) = (78.084 F(N2) + 20.946 F(O2) + 0.934 F(Ar) + C F(CO2)) / (78.084 + 20.946 + 0.934 + C)
//            with F(Ar) = 1.00, F(CO2) = 1.15, C = CO2 in percent   (eq. 23)
//   sigma = 24 pi^3 (n^2 - 1)^2 / (lambda^4 N_s^2 (n^2 + 2)^2) F(air)  (eq. 2)
//            N_s = 2.546899e19 cm^-3 (molecules of standard air at 288.15 K, 1013.25 hPa)
// sigma is a per-molecule cross-section: it does not depend on density (Lorentz-Lorenz), so the
// scattering coefficient at altitude z is n_air(z) sigma.
// Valid 200-4000 nm (the range of the Peck & Reeder dispersion formula, 230-1690 nm measured).
//
// Phase function with depolarisation (Chandrasekhar 1950, as used by Bucholtz 1995 eq. 12-13):
//   P(mu) = 3 / (4 (1 + 2 gamma)) [(1 + 3 gamma) + (1 - gamma) mu^2] / (4 pi),
//   gamma = rho_n / (2 - rho_n),  rho_n = 6 (F - 1) / (3 + 7 F)  (from F = (6 + 3 rho)/(6 - 7 rho)),
// normalised so that the integral over the sphere is 1 (sr^-1).
#pragma once

namespace skybake::rayleigh {

// Standard-air number density used in eq. 2, m^-3 (Bodhaine 1999: 2.546899e19 cm^-3).
inline constexpr double kStandardAirNumberDensityM3 = 2.546899e25;

double RefractiveIndexMinusOne(double wavelength_nm, double co2_ppm);
double KingFactor(double wavelength_nm, double co2_ppm);
// Depolarisation ratio rho_n from the King factor.
double DepolarizationRatio(double wavelength_nm, double co2_ppm);
// Per-molecule Rayleigh scattering cross-section, m^2.
double CrossSectionM2(double wavelength_nm, double co2_ppm);
// gamma = rho / (2 - rho), the phase function's depolarisation parameter.
double PhaseGamma(double wavelength_nm, double co2_ppm);
// Phase function (sr^-1) for the cosine of the scattering angle.
double Phase(double mu, double gamma);
// Samples mu from Phase(., gamma) by inverting its CDF exactly (a cubic, solved in closed form)
// from a uniform u in [0, 1).
double SamplePhaseMu(double u, double gamma);

}  // namespace skybake::rayleigh
