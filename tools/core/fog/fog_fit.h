// The fit of GT7's depth function (fog/fog_model.h): a and p of
//   Fog(dir, x) / Fog(dir, 1) = F(x, a theta^p) = (1 - exp(-a theta^p x)) / (1 - exp(-a theta^p))
// over every direction and depth of the reference fog (GT7 sky talk, "Global
// Fog Approximation": "a and p were fitted using reference fog results for all directions and
// depths"), by nonlinear least squares (Eigen's Levenberg-Marquardt, MINPACK's lmder; Moré 1978).
//
// Objective: the residual of sample i is ln(F(x_i, a theta_i^p) / f_i), f_i = Fog(x_i)/Fog(1) the
// reference's normalised fog: the relative error for small errors (ln(1 + e) = e - e^2/2 ...), but
// bounded where the model is far off (the horizon with theta = elevation, where F -> 1 while f is
// 1e-3 near the camera: relative residuals of 1000 would otherwise decide the fit).
//
// Stability (docs/fog.md, "The fit"):
//  - parameters are bounded by a smooth map, ln a = c_a + h_a tanh(q_a), p = c_p + h_p tanh(q_p),
//    so the optimiser works on an unbounded q and can never leave [a_min, a_max] x [p_min, p_max];
//  - the start is the best node of a 13 x 13 grid over the box (the cost is not convex: F saturates);
//  - F and dF/dk are evaluated in forms stable for k in [0, inf] (fog_model.h), so no NaN reaches
//    the solver; samples with f <= 0, f or theta not finite, or x outside (0, 1) are left out and
//    counted;
//  - if every sample has the same theta, p is not identifiable: it stays 0 and only a is fitted;
//  - if the optimiser ends above the grid's best cost, the grid's best is kept ("fallback").
// Deterministic: one thread, the samples in the caller's order.
#pragma once

#include <string>
#include <vector>

namespace skybake::fog {

struct FitSample {
  double theta = 1.0;   // normalised view angle, (0, 1]
  double x = 1.0;       // normalised depth, (0, 1)
  double target = 1.0;  // f = Fog(x) / Fog(1)
};

struct FitOptions {
  double a_min = 1e-4, a_max = 1e4;  // 1: k is the segment's optical depth scale (docs/fog.md)
  double p_min = -6.0, p_max = 6.0;
  int max_evaluations = 2000;
};

struct FitResult {
  double a = 1.0, p = 0.0;
  double rms_log = 0.0;       // RMS of ln(F/f) over the samples used
  size_t used = 0, rejected = 0;
  int evaluations = 0;
  bool p_fitted = true;       // false: all samples at one theta (p = 0)
  bool at_bound = false;      // a or p within 0.1 % of the box's edge
  bool fallback = false;      // the grid's best node was kept
  std::string status;         // one line for reports
};

FitResult FitDepthFactor(const std::vector<FitSample>& samples, const FitOptions& options = {});

}  // namespace skybake::fog
