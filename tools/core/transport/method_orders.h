// `orders`: deterministic multiple scattering by successive orders on precomputed tables
// (Bruneton & Neyret 2008, "Precomputed Atmospheric Scattering", §3-4),
// rebuilt for an offline CPU baker that must be accurate at the horizon and in twilight
// (docs/sky-methods.md, "orders", has the derivation, the table layouts and the measured errors).
//
// L = L_1 + L_ms:
//  - L_1, single scattering (and the ground's reflection of the direct sun), is computed exactly
//    for every output direction: a march along the view ray with the full tabulated phase
//    functions (the Mie forward peak is never tabulated on a coarse grid), the transmittance to
//    the sun from a table averaged over the limb-darkened solar disk (which also gives the Earth's
//    shadow its penumbra).
//  - L_ms = sum_{n>=2} L_n is computed on tables over (altitude r, sun zenith, view zenith mu,
//    azimuth from the sun phi) for a *delta-scaled* medium: each aerosol phase function is
//    flattened inside a cone of `truncation_deg` around the forward direction and the removed
//    fraction f treated as unscattered (sigma_s* = (1 - f) sigma_s; Wiscombe 1977's delta-M idea
//    in Potter's (1970) truncation form), so that a few hundred directions integrate it. With
//    L_1 exact this is the "TMS" split of Nakajima & Tanaka (1988): L = L_1 + (L* - L_1*).
//    Each order: J_n = sigma_s* (x) P* applied to L_{n-1} (a matrix per altitude over the
//    direction nodes), then L_n = int T* J_n dt along every table ray plus the ground's
//    Lambertian reflection of the order-(n-1) irradiance. Orders stop when the next one adds
//    less than `tolerance` of the accumulated L_ms at the observer, or after `max_orders` (then
//    a geometric tail sum_{k>n} = L_n rho/(1-rho) is added when the ratio rho of successive
//    orders has settled).
//  - Tables: view nodes per altitude split at that altitude's horizon (mu_h = -sqrt(1-(R/r)^2))
//    and dense next to it; sun nodes dense from 80 to 110 deg; radius nodes dense near the
//    ground; one radius node at the observer. Values are linear in every coordinate except the
//    output's sun angle, which is interpolated log-linearly (twilight light decays
//    exponentially with the sun's depression). `high` solves its daylight sun nodes at its own
//    resolution and its twilight ones at medium's angular resolution, blending the two across
//    sun zenith 90-91 deg (the twilight split, orders/split.h).
// Everything is vectorised over wavelength (float, wavelength innermost).
// The implementation, one phase per file: transport/orders/ (settings, medium, sun_tables, nodes,
// rays, kernel, modal_kernel, transport, transport_split, solve, render, simd, split; method.cpp).
#pragma once

#include <memory>

#include "transport/sky_method.h"

namespace skybake {

std::unique_ptr<SkyMethod> MakeOrdersMethod(const AtmosphereModel& model, const SkyMethodOptions& options,
                                            const ProgressFn& progress);

}  // namespace skybake
