// Diffusion synthetic acceleration of the orders (Alcouffe 1977, "Diffusion synthetic acceleration
// methods for the diamond-differenced discrete-ordinates equations", Nucl. Sci. Eng. 64; with
// anisotropic scattering the transport-corrected diffusion coefficient, Morel 1982). Under a thick
// cloud the orders decay at ratios near 1 (0.955 under cloudy5's deck at 600 nm): the slow part of
// each order is nearly isotropic light diffusing through the deck, which a diffusion equation
// describes. After each transport sweep the solve takes the sweep's increment d_n (its result less
// the previous correction), solves per sun node and wavelength the 1-D diffusion equation in
// altitude for what the remaining orders would add to the scalar flux,
//   -d/dz (D dphi/dz) + sigma_a* phi = sigma_s* phi[d_n],   D = 1 / (3 sigma_tr*),
// (sigma_tr* = sigma_t* - sum_c sigma_s*_c g*_c, g* the truncated phase's mean cosine; Marshak
// conditions at the top and at the Lambertian ground), and adds kShare of the isotropic
// correction c_n = phi / (4 pi) to every cell; the next sweep transports d_n + c_n. At
// convergence the corrections vanish, so the answer is the series'; what changes is how fast the
// increments decay. docs/sky-methods.md "Accelerated orders" has the measurements behind the
// choices:
//  - isotropic only: the P1 term (3 J mu / (4 pi)) makes cloudy5's increments grow;
//  - kShare 0.7 of the correction: the whole one leaves the increments oscillating (cloudy5,
//    daylight: 23 orders; 0.7: 21, against 35 without);
//  - per sun node: a plane-parallel column, which the sky is where the sun is up; a solve whose
//    sun nodes end (the daylight part's at 93 deg) loses the light its table rays would take from
//    beyond its last node, which the diffusion does not know of, and the correction there makes
//    the increments grow (x2.3 per order at 93 deg), so the share tapers to 0 over the kTaperDeg
//    before min(last node, 93 deg): no correction in twilight, where the light runs along the
//    terminator rather than down through the column;
//  - the sun blend linear: the increments' mean sources change sign, so the plain series'
//    per-order log-linear factors (from 85 deg) do not apply to them.
// Where the plain series' blend is linear too the accelerated sky is its sky to 0.1-0.2 %. From
// 85 deg it is not: against the limit of 0.2 deg sun nodes (cloudy5, 77 directions), the plain
// series is 0.32 / 0.12 % RMS off at sun 87 / 89 deg and the accelerated one 0.53 / 1.15 % (max
// 2.2 %), the linear blend between 1 deg nodes of a sky that falls steeply; factors from the sums
// so far are worse (1.44 % at 87 deg), and a share ending at 85 deg with each increment's own
// factors 30 %. So no preset enables it (OrdersSettings::dsa_from_tau).
#pragma once

#include <vector>

#include "transport/orders/grid.h"
#include "transport/orders/kernel.h"
#include "transport/orders/medium.h"
#include "transport/orders/nodes.h"

namespace skybake::orders {

inline constexpr double kShare = 0.7;
inline constexpr double kTaperDeg = 10.0, kTaperEndDeg = 93.0;

struct DiffusionAcceleration {
  size_t nr = 0, ns = 0, nu = 0, nphi = 0, nw = 0;
  std::vector<double> weight;  // solid angle of each cell (k, q) at radius node ri [ri * nu + k] (sr)
  // Per interval i (nodes i, i + 1) and wavelength: D / dz = 1 / (3 tau_tr) [i * nw + w] (capped).
  std::vector<double> coupling;
  std::vector<double> volume;       // [ri]: the node's share of the column (m)
  std::vector<double> absorption;   // sigma_a* [ri * nw + w] (m^-1)
  std::vector<double> scattering;   // sigma_s* [ri * nw + w] (m^-1)
  std::vector<double> ground_loss;  // (1 - A) / (2 (1 + A)) per wavelength (the Marshak condition)
  std::vector<double> share;  // per sun node: the share of the correction applied (kShare, tapered)
  std::vector<float> iso;     // the correction in the tables now [(ri * ns + si) * nw + w]
};

DiffusionAcceleration MakeDiffusionAcceleration(const Medium& md, const Nodes& nodes, const KernelContext& kc);

// The column's vertical optical depth of the delta-scaled medium at the reference wavelength
// (trapezoid over the radius nodes): OrdersSettings::dsa_from_tau compares it.
double ScaledColumnDepth(const Medium& md, const Nodes& nodes);

// One step on the sweep's result L (every cell x nw): L -= the previous correction, the diffusion
// solve on the flux of what is left, L += the new correction.
void Accelerate(DiffusionAcceleration* a, Table* L);

}  // namespace skybake::orders
