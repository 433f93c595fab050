// The scattering-angle grid of every Mie table (docs/mie.md, "Angle grid").
//
// Size-averaged aerosol phase functions have a forward peak about 1/x rad wide (x = 2 pi r /
// lambda; 0.07 deg at x = 900, a 50 um droplet in violet light) with a diffraction tail falling
// like theta^-3, and values that span 6 to 9 decades between 0 and 180 deg
// (Wiscombe, MIEV.doc L436-456). The grid therefore is
//   theta = 0,
//   400 angles log-spaced from 0.01 deg to 5 deg (ratio 1.0157 between neighbours: ~200 points
//     inside the first diffraction minimum 3.83/x rad for any x <= 1000, and the tail resolved),
//   uniform 0.125 deg steps from 5 deg to 90 deg,
// and its mirror image about 90 deg (theta -> 180 deg - theta), 2161 angles in all.
// Why so dense near the peak: the table's interpolant (log-linear in cos theta, mie_table.h) is
// exact for a Gaussian core but overestimates a theta^-3 tail by ~(ln ratio)^2 per interval; with
// 201 log points up to 1 deg (1827 angles) the phase function of the GT7 coarse mode integrated
// to 1 + 2.9e-4, with this grid to 1 + 3.7e-5 (water cloud: 1 + 3.0e-5); tests/optics holds it
// below 1e-4. The mirror symmetry is used by the angular sums (mie_angular.h): pi_n and tau_n at
// -mu follow from their values at mu; it also puts log-spaced points near 180 deg, where the
// glory of water droplets has the same 1/x width as the forward peak.
#pragma once

#include <cstddef>
#include <vector>

namespace skybake::mie {

struct PhaseGrid {
  // Scattering angles, rad, ascending from 0 to pi; theta[size-1-j] = pi - theta[j].
  std::vector<double> theta_rad;
  // cos(theta), descending from 1 to -1 (mu[size-1-j] = -mu[j] exactly).
  std::vector<double> mu;
  // Number of angles in [0, pi/2] (the last of them is pi/2): size() = 2 half - 1.
  size_t half = 0;

  size_t size() const { return theta_rad.size(); }
  // Index of the angle pi - theta_j.
  size_t Mirror(size_t j) const { return theta_rad.size() - 1 - j; }
};

// The grid described above.
PhaseGrid StandardPhaseGrid();

// A grid from explicit angles in [0, pi/2] (ascending, starting at 0, ending at pi/2), mirrored.
PhaseGrid MirroredPhaseGrid(const std::vector<double>& half_theta_rad);

}  // namespace skybake::mie
