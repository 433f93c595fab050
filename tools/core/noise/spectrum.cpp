#include "noise/spectrum.h"

#include <cmath>
#include <numbers>

#include "io/error.h"

namespace skybake::noise {

namespace {
bool IsPowerOfTwo(size_t n) { return n > 0 && (n & (n - 1)) == 0; }
}  // namespace

void Fft(std::vector<std::complex<double>>& a) {
  const size_t n = a.size();
  SKYBAKE_CHECK(IsPowerOfTwo(n));
  // Bit-reversal permutation.
  for (size_t i = 1, j = 0; i < n; ++i) {
    size_t bit = n >> 1;
    for (; j & bit; bit >>= 1) j ^= bit;
    j ^= bit;
    if (i < j) std::swap(a[i], a[j]);
  }
  // Butterflies: twiddles computed directly per index (not by repeated multiplication) so the
  // rounding error does not grow with the length.
  for (size_t len = 2; len <= n; len <<= 1) {
    const double ang = -2.0 * std::numbers::pi / static_cast<double>(len);
    for (size_t k = 0; k < len / 2; ++k) {
      const std::complex<double> w(std::cos(ang * k), std::sin(ang * k));
      for (size_t i = 0; i < n; i += len) {
        const std::complex<double> u = a[i + k], v = a[i + k + len / 2] * w;
        a[i + k] = u + v;
        a[i + k + len / 2] = u - v;
      }
    }
  }
}

std::vector<std::complex<double>> Fft3(const std::vector<double>& field, int n) {
  SKYBAKE_CHECK(IsPowerOfTwo(static_cast<size_t>(n)));
  SKYBAKE_CHECK_EQ(field.size(), static_cast<size_t>(n) * n * n);
  std::vector<std::complex<double>> f(field.begin(), field.end());
  std::vector<std::complex<double>> line(n);
  const size_t N = n;
  const size_t strides[3] = {1, N, N * N};
  for (int axis = 0; axis < 3; ++axis) {
    const size_t s = strides[axis];
    for (size_t a = 0; a < N; ++a) {
      for (size_t b = 0; b < N; ++b) {
        // The line's start: the two other axes at (a, b).
        size_t base;
        if (axis == 0) base = a * N + b * N * N;
        else if (axis == 1) base = a + b * N * N;
        else base = a + b * N;
        for (size_t t = 0; t < N; ++t) line[t] = f[base + t * s];
        Fft(line);
        for (size_t t = 0; t < N; ++t) f[base + t * s] = line[t];
      }
    }
  }
  return f;
}

std::vector<std::complex<double>> Dft3Reference(const std::vector<double>& field, int n) {
  const size_t N = n;
  std::vector<std::complex<double>> out(N * N * N);
  for (size_t kz = 0; kz < N; ++kz)
    for (size_t ky = 0; ky < N; ++ky)
      for (size_t kx = 0; kx < N; ++kx) {
        std::complex<double> s = 0.0;
        for (size_t z = 0; z < N; ++z)
          for (size_t y = 0; y < N; ++y)
            for (size_t x = 0; x < N; ++x) {
              const double ph = -2.0 * std::numbers::pi * static_cast<double>((kx * x + ky * y + kz * z) % N) / n;
              s += field[(z * N + y) * N + x] * std::complex<double>(std::cos(ph), std::sin(ph));
            }
        out[(kz * N + ky) * N + kx] = s;
      }
  return out;
}

std::vector<double> RadialEnergySpectrum(const std::vector<float>& values, int n, int channels, int channel) {
  const size_t N = n, count = N * N * N;
  SKYBAKE_CHECK_EQ(values.size(), count * channels);
  std::vector<double> f(count);
  double mean = 0.0;
  for (size_t i = 0; i < count; ++i) mean += (f[i] = values[i * channels + channel]);
  mean /= static_cast<double>(count);
  for (double& v : f) v -= mean;
  const std::vector<std::complex<double>> F = Fft3(f, n);
  std::vector<double> e(N / 2 + 1, 0.0);
  auto signed_k = [&](size_t k) { return k < N / 2 ? static_cast<double>(k) : static_cast<double>(k) - n; };
  for (size_t kz = 0; kz < N; ++kz)
    for (size_t ky = 0; ky < N; ++ky)
      for (size_t kx = 0; kx < N; ++kx) {
        const double kk = std::sqrt(signed_k(kx) * signed_k(kx) + signed_k(ky) * signed_k(ky) + signed_k(kz) * signed_k(kz));
        const size_t m = static_cast<size_t>(std::lround(kk));
        if (m < e.size()) e[m] += std::norm(F[(kz * N + ky) * N + kx]);
      }
  return e;
}

int PeakShell(const std::vector<double>& energy) {
  int best = 1;
  for (size_t m = 1; m < energy.size(); ++m) {
    if (energy[m] > energy[best]) best = static_cast<int>(m);
  }
  return best;
}

}  // namespace skybake::noise
