// The two noise primitives: gradient (Perlin) noise and cellular (Worley) noise, on integer
// lattices that are either periodic (tileable volumes) or unbounded (the world-space weather field).
//
// Both are pure functions of (key, position): lattice data come from noise/hash.h, never from a
// random-number generator with state.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

namespace skybake::noise {

// Perlin's fade curve s(t) = 6t^5 - 15t^4 + 10t^3 (Perlin 2002, "Improving Noise", SIGGRAPH /
// ACM TOG 21(3) 681-682, §2): s(0) = 0, s(1) = 1 and s', s'' vanish at both ends, so the noise is
// C2 across lattice faces (the 1985 curve 3t^2 - 2t^3 is only C1).
inline double Fade(double t) { return t * t * t * (t * (t * 6.0 - 15.0) + 10.0); }

// Tileable 3D gradient noise (Perlin 2002). With p in lattice units, cell corner c = floor(p) + d,
// d in {0,1}^3, and f = p - floor(p):
//   n(p) = sum_d  s~(f_x, d_x) s~(f_y, d_y) s~(f_z, d_z)  g(c) . (f - d)
// where s~(t, 0) = 1 - s(t), s~(t, 1) = s(t), and g(c) is one of Perlin's 12 gradients
// (+-1, +-1, 0), (+-1, 0, +-1), (0, +-1, +-1) chosen by hashing c modulo `period` on each axis.
// Hence n(p + period e_k) = n(p) exactly for every axis k: the noise tiles with `period` cells.
// n = 0 on every lattice point; |n| stays below about 1 (the fBm and volume code normalise
// empirically, so no bound is assumed).
class PeriodicGradientNoise3 {
 public:
  // period: cells per tile on each axis (>= 1); key: a StreamKey (noise/hash.h).
  PeriodicGradientNoise3(int period, uint64_t key);
  double operator()(double x, double y, double z) const;
  int period() const { return period_; }

 private:
  int period_;
  std::vector<uint8_t> gradient_;  // gradient index 0..11 per lattice point, period^3
};

// Tileable 3D cellular noise: F1, the distance to the nearest feature point (Worley 1996,
// "A Cellular Texture Basis Function", SIGGRAPH '96, 291-294), with exactly one feature point per
// lattice cell as in Schneider 2015 ("The real-time volumetric cloudscapes of Horizon Zero Dawn",
// SIGGRAPH Advances) and Hillaire 2016 §5.4 ("Cloud noise"):
//   point(c) = c + 1/2 + jitter (u(c) - 1/2),  u(c) uniform in [0,1)^3 hashed from c mod period,
//   F1(p)    = min_c |p - point(c)|   (lattice units; periodic: F1(p + period e_k) = F1(p)).
// Worley's original scatters a Poisson number of points per cell; one point per cell keeps the
// feature density exactly 1 per cell, which is what the tile frequency means here.
// Search: with jitter <= 1 every point lies inside its cell, so the point of p's own cell is at
// most sqrt(3) away, points two or more cells away (Chebyshev) are at least 1 away and three or
// more are at least 2 away. The 3x3x3 neighbourhood is therefore exact whenever its minimum is
// <= 1, and the 5x5x5 neighbourhood (used otherwise) is always exact.
class PeriodicWorley3 {
 public:
  // jitter in [0, 1]: 0 = points at cell centres (a regular lattice), 1 = anywhere in the cell.
  PeriodicWorley3(int period, double jitter, uint64_t key);
  double F1(double x, double y, double z) const;
  // F1 by brute force over every feature point of the tile and its 26 periodic images: the slow,
  // obviously right reference the neighbourhood search is tested against.
  double F1BruteForce(double x, double y, double z) const;
  int period() const { return period_; }

 private:
  double Search(const std::array<int, 3>& cell, const std::array<double, 3>& p, int radius) const;
  int period_;
  std::vector<std::array<double, 3>> point_;  // absolute position of the point of cell c (in [c, c+1)^3)
};

// 2D gradient noise on the unbounded integer lattice (int64 coordinates: no period short of
// 2^63 cells), for world-space fields that must not repeat. Same construction as above in 2D
// with 8 unit gradients at angles k 45 degrees (k = 0..7, hashed from the cell corner):
//   n(p) = sum_{d in {0,1}^2} s~(f_x, d_x) s~(f_y, d_y) g(c) . (f - d).
class GradientNoise2 {
 public:
  explicit GradientNoise2(uint64_t key) : key_(key) {}
  double operator()(double x, double y) const;

 private:
  uint64_t key_;
};

}  // namespace skybake::noise
