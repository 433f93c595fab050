#include "noise/lattice.h"

#include <cmath>
#include <limits>

#include "io/error.h"
#include "noise/hash.h"

namespace skybake::noise {

namespace {

// Perlin 2002's 12 gradient directions: the midpoints of the edges of the cube [-1,1]^3.
constexpr double kGrad3[12][3] = {{1, 1, 0},  {-1, 1, 0},  {1, -1, 0}, {-1, -1, 0}, {1, 0, 1},  {-1, 0, 1},
                                  {1, 0, -1}, {-1, 0, -1}, {0, 1, 1},  {0, -1, 1},  {0, 1, -1}, {0, -1, -1}};

// 8 unit gradients at k * 45 degrees.
constexpr double kS = 0.70710678118654752440;  // 1/sqrt(2)
constexpr double kGrad2[8][2] = {{1, 0}, {kS, kS}, {0, 1}, {-kS, kS}, {-1, 0}, {-kS, -kS}, {0, -1}, {kS, -kS}};

inline int Wrap(int64_t i, int period) {
  int64_t m = i % period;
  return static_cast<int>(m < 0 ? m + period : m);
}

inline double Lerp(double a, double b, double t) { return a + t * (b - a); }

}  // namespace

// ---------------------------------------------------------------------------- gradient noise 3D

PeriodicGradientNoise3::PeriodicGradientNoise3(int period, uint64_t key) : period_(period) {
  SKYBAKE_CHECK_GE(period, 1);
  const size_t n = static_cast<size_t>(period) * period * period;
  gradient_.resize(n);
  for (int z = 0; z < period; ++z) {
    for (int y = 0; y < period; ++y) {
      for (int x = 0; x < period; ++x) {
        // 64-bit hash modulo 12: the bias is 2^64 mod 12 / 2^64 < 1e-18.
        gradient_[(static_cast<size_t>(z) * period + y) * period + x] = static_cast<uint8_t>(Hash(key, x, y, z) % 12);
      }
    }
  }
}

double PeriodicGradientNoise3::operator()(double x, double y, double z) const {
  const double fx0 = std::floor(x), fy0 = std::floor(y), fz0 = std::floor(z);
  const double fx = x - fx0, fy = y - fy0, fz = z - fz0;
  const int P = period_;
  const int x0 = Wrap(static_cast<int64_t>(fx0), P), y0 = Wrap(static_cast<int64_t>(fy0), P),
            z0 = Wrap(static_cast<int64_t>(fz0), P);
  const int x1 = x0 + 1 == P ? 0 : x0 + 1, y1 = y0 + 1 == P ? 0 : y0 + 1, z1 = z0 + 1 == P ? 0 : z0 + 1;
  auto dot = [&](int ix, int iy, int iz, double dx, double dy, double dz) {
    const double* g = kGrad3[gradient_[(static_cast<size_t>(iz) * P + iy) * P + ix]];
    return g[0] * dx + g[1] * dy + g[2] * dz;
  };
  const double n000 = dot(x0, y0, z0, fx, fy, fz), n100 = dot(x1, y0, z0, fx - 1, fy, fz);
  const double n010 = dot(x0, y1, z0, fx, fy - 1, fz), n110 = dot(x1, y1, z0, fx - 1, fy - 1, fz);
  const double n001 = dot(x0, y0, z1, fx, fy, fz - 1), n101 = dot(x1, y0, z1, fx - 1, fy, fz - 1);
  const double n011 = dot(x0, y1, z1, fx, fy - 1, fz - 1), n111 = dot(x1, y1, z1, fx - 1, fy - 1, fz - 1);
  const double u = Fade(fx), v = Fade(fy), w = Fade(fz);
  return Lerp(Lerp(Lerp(n000, n100, u), Lerp(n010, n110, u), v), Lerp(Lerp(n001, n101, u), Lerp(n011, n111, u), v), w);
}

// ---------------------------------------------------------------------------- Worley 3D

PeriodicWorley3::PeriodicWorley3(int period, double jitter, uint64_t key) : period_(period) {
  SKYBAKE_CHECK_GE(period, 1);
  SKYBAKE_CHECK(jitter >= 0.0 && jitter <= 1.0);
  point_.resize(static_cast<size_t>(period) * period * period);
  for (int z = 0; z < period; ++z) {
    for (int y = 0; y < period; ++y) {
      for (int x = 0; x < period; ++x) {
        const uint64_t h = Hash(key, x, y, z);
        const double u[3] = {UnitDouble(h), UnitDouble(Mix64(h ^ 0x1)), UnitDouble(Mix64(h ^ 0x2))};
        std::array<double, 3>& p = point_[(static_cast<size_t>(z) * period + y) * period + x];
        p = {x + 0.5 + jitter * (u[0] - 0.5), y + 0.5 + jitter * (u[1] - 0.5), z + 0.5 + jitter * (u[2] - 0.5)};
      }
    }
  }
}

double PeriodicWorley3::Search(const std::array<int, 3>& cell, const std::array<double, 3>& p, int radius) const {
  // `cell` is the unwrapped integer cell of p; neighbour (cell + o) has its point at
  // point_[wrap(cell + o)] + (cell + o - wrap(cell + o)), i.e. the periodic image next to p.
  const int P = period_;
  double best = std::numeric_limits<double>::infinity();
  for (int oz = -radius; oz <= radius; ++oz) {
    const int64_t cz = static_cast<int64_t>(cell[2]) + oz;
    const int wz = Wrap(cz, P);
    const double sz = static_cast<double>(cz - wz);
    for (int oy = -radius; oy <= radius; ++oy) {
      const int64_t cy = static_cast<int64_t>(cell[1]) + oy;
      const int wy = Wrap(cy, P);
      const double sy = static_cast<double>(cy - wy);
      for (int ox = -radius; ox <= radius; ++ox) {
        const int64_t cx = static_cast<int64_t>(cell[0]) + ox;
        const int wx = Wrap(cx, P);
        const std::array<double, 3>& q = point_[(static_cast<size_t>(wz) * P + wy) * P + wx];
        const double dx = q[0] + static_cast<double>(cx - wx) - p[0];
        const double dy = q[1] + sy - p[1];
        const double dz = q[2] + sz - p[2];
        const double d2 = dx * dx + dy * dy + dz * dz;
        if (d2 < best) best = d2;
      }
    }
  }
  return std::sqrt(best);
}

double PeriodicWorley3::F1(double x, double y, double z) const {
  const std::array<double, 3> p = {x, y, z};
  const std::array<int, 3> cell = {static_cast<int>(std::floor(x)), static_cast<int>(std::floor(y)),
                                   static_cast<int>(std::floor(z))};
  const double d = Search(cell, p, 1);
  return d <= 1.0 ? d : Search(cell, p, 2);  // exactness argument in lattice.h
}

double PeriodicWorley3::F1BruteForce(double x, double y, double z) const {
  // Reduce p into the base tile, then every point of the tile shifted by -P, 0, +P per axis.
  const double P = period_;
  const double p[3] = {x - P * std::floor(x / P), y - P * std::floor(y / P), z - P * std::floor(z / P)};
  double best = std::numeric_limits<double>::infinity();
  for (const std::array<double, 3>& q : point_) {
    for (int a = -1; a <= 1; ++a) {
      for (int b = -1; b <= 1; ++b) {
        for (int c = -1; c <= 1; ++c) {
          const double dx = q[0] + a * P - p[0], dy = q[1] + b * P - p[1], dz = q[2] + c * P - p[2];
          best = std::min(best, dx * dx + dy * dy + dz * dz);
        }
      }
    }
  }
  return std::sqrt(best);
}

// ---------------------------------------------------------------------------- gradient noise 2D

double GradientNoise2::operator()(double x, double y) const {
  const double fx0 = std::floor(x), fy0 = std::floor(y);
  const double fx = x - fx0, fy = y - fy0;
  const int64_t x0 = static_cast<int64_t>(fx0), y0 = static_cast<int64_t>(fy0);
  auto dot = [&](int64_t ix, int64_t iy, double dx, double dy) {
    const double* g = kGrad2[Hash(key_, ix, iy) & 7];
    return g[0] * dx + g[1] * dy;
  };
  const double n00 = dot(x0, y0, fx, fy), n10 = dot(x0 + 1, y0, fx - 1, fy);
  const double n01 = dot(x0, y0 + 1, fx, fy - 1), n11 = dot(x0 + 1, y0 + 1, fx - 1, fy - 1);
  const double u = Fade(fx), v = Fade(fy);
  return Lerp(Lerp(n00, n10, u), Lerp(n01, n11, u), v);
}

}  // namespace skybake::noise
