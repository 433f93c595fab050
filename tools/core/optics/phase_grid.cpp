#include "optics/phase_grid.h"

#include <cmath>
#include <numbers>

#include "io/error.h"

namespace skybake::mie {

namespace {
constexpr double kDeg = std::numbers::pi / 180.0;
// Log-spaced part: 0.01 deg .. 5 deg with 400 points; uniform part: 5 deg .. 90 deg, 0.125 deg.
constexpr double kLogStartDeg = 0.01;
constexpr double kLogEndDeg = 5.0;
constexpr int kLogPoints = 400;
constexpr double kUniformStepDeg = 0.125;
}  // namespace

PhaseGrid MirroredPhaseGrid(const std::vector<double>& half) {
  SKYBAKE_CHECK_GE(half.size(), 2u);
  SKYBAKE_CHECK_EQ(half.front(), 0.0);
  SKYBAKE_CHECK_EQ(half.back(), std::numbers::pi / 2.0);
  for (size_t i = 1; i < half.size(); ++i) SKYBAKE_CHECK_LT(half[i - 1], half[i]);
  PhaseGrid g;
  g.half = half.size();
  const size_t n = 2 * half.size() - 1;
  g.theta_rad.resize(n);
  g.mu.resize(n);
  for (size_t j = 0; j < half.size(); ++j) {
    g.theta_rad[j] = half[j];
    g.theta_rad[n - 1 - j] = std::numbers::pi - half[j];
    // cos(pi/2) is 6e-17 in double: the 90 deg point is exactly 0 so that mu is exactly odd.
    const double mu = (j + 1 == half.size()) ? 0.0 : std::cos(half[j]);
    g.mu[j] = mu;
    g.mu[n - 1 - j] = -mu;
  }
  return g;
}

PhaseGrid StandardPhaseGrid() {
  std::vector<double> half{0.0};
  for (int i = 0; i < kLogPoints; ++i) {
    const double t = static_cast<double>(i) / (kLogPoints - 1);
    half.push_back(kLogStartDeg * std::pow(kLogEndDeg / kLogStartDeg, t) * kDeg);
  }
  half.back() = kLogEndDeg * kDeg;
  const int uniform = static_cast<int>(std::lround((90.0 - kLogEndDeg) / kUniformStepDeg));
  for (int i = 1; i <= uniform; ++i) half.push_back((kLogEndDeg + i * kUniformStepDeg) * kDeg);
  half.back() = std::numbers::pi / 2.0;
  return MirroredPhaseGrid(half);
}

}  // namespace skybake::mie
