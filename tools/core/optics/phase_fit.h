// Simple phase-function models and their best fits to a tabulated (Mie) phase function, to
// measure what a renderer loses by using them (GT7 sky talk,
// "Real Earth Atmosphere" -> "Aerosols" -> "Phase Function Approximation": HG "can never fit
// well enough ... the error would be more than 16 times in the coarse-mode forward scattering").
//
// Models (all normalised to 1 over the sphere, sr^-1; mu = cos theta):
//   Henyey-Greenstein (Henyey & Greenstein 1941, ApJ 93, 70):
//     HG(mu; g) = (1 - g^2) / (4 pi (1 + g^2 - 2 g mu)^{3/2}),   <mu> = g
//   Cornette-Shanks (Cornette & Shanks 1992, Appl. Opt. 31, 3152, eq. 8):
//     CS(mu; g) = 3 (1 - g^2)(1 + mu^2) / (8 pi (2 + g^2)(1 + g^2 - 2 g mu)^{3/2})
//     (g here is a shape parameter; <mu> of CS is 3 g (4 + g^2) / (5 (2 + g^2)))
//   dual-lobe HG: w HG(mu; g1) + (1 - w) HG(mu; g2), 0 <= w <= 1.
//
// "Best fit" minimises the RMS of the log-ratio ln(model/Mie) over scattering angle, each angle
// weighted by its share of [0, pi] (trapezoid weights in theta): every degree counts the same,
// so the fit is not dominated by the densely sampled forward and backward cones. Reported per
// model: the RMS and the maximum of |ln(model/Mie)| over the grid (a max of ln 16 = 2.77 is the
// talk's "16 times"). HG with g = the Mie asymmetry parameter (what renderers usually do) is
// reported too, without fitting.
//
// Minimisers: HG and CS are 1-D (golden-section search in atanh(g) after a coarse scan); the
// dual lobe is 3-D, Levenberg-Marquardt on (atanh g1, atanh g2, logit w) with the analytic
// Jacobian, started from the best HG and two other fixed points (deterministic).
#pragma once

#include <span>

namespace skybake::mie {

double HenyeyGreenstein(double mu, double g);
double CornetteShanks(double mu, double g);
double DualHenyeyGreenstein(double mu, double g1, double g2, double w);

struct FitError {
  double rms_log = 0.0;  // sqrt(sum w_j ln^2(model/P)) over theta, weights summing to 1
  double max_log = 0.0;  // max_j |ln(model/P)|
};

struct PhaseFits {
  double hg_g = 0.0;
  FitError hg;
  FitError hg_moment;  // HG with g = the Mie asymmetry parameter
  double cs_g = 0.0;
  FitError cs;
  double dhg_g1 = 0.0, dhg_g2 = 0.0, dhg_w = 1.0;
  FitError dhg;
};

// theta (rad, ascending 0..pi), mu = cos theta, phase > 0 (sr^-1), g_mie its asymmetry parameter.
PhaseFits FitPhaseModels(std::span<const double> theta_rad, std::span<const double> mu,
                         std::span<const double> phase, double g_mie);

// Errors of an arbitrary model given as ln(model) at the grid angles.
FitError LogRatioError(std::span<const double> theta_rad, std::span<const double> ln_model,
                       std::span<const double> ln_phase);

}  // namespace skybake::mie
