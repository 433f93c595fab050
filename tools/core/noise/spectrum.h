// Power spectra of periodic fields, to check where a noise puts its energy.
//
// For a periodic field f on an N^3 grid over one tile, the discrete Fourier transform
//   F(k) = sum_x f(x) exp(-2 pi i k . x / N),   k in {-N/2 .. N/2 - 1}^3 (cycles per tile),
// and the radial energy spectrum (the "shell" spectrum of turbulence, Pope 2000 §6.5)
//   E(m) = sum_{k : round(|k|) = m} |F(k) - F_mean(k)|^2,   m = 0 .. N/2
// (the mean is removed first, so E(0) = 0). E(m) is the variance carried by wavenumbers of
// magnitude ~m cycles per tile; by Parseval sum_m E(m) = N^3 sum_x (f - mean)^2 over the
// shells that fit (|k| <= N/2 + 1/2). A noise built from lattice cells of F per tile should
// have its E peak near m ~ F.
#pragma once

#include <complex>
#include <vector>

namespace skybake::noise {

// In-place radix-2 Cooley-Tukey FFT of a power-of-two length (Cooley & Tukey 1965), forward
// sign exp(-2 pi i k n / N), no scaling.
void Fft(std::vector<std::complex<double>>& a);

// The 3D DFT of an N^3 real field (x fastest), N a power of two, by FFTs along each axis.
std::vector<std::complex<double>> Fft3(const std::vector<double>& field, int n);
// The same by the definition (O(N^6)): the slow reference for tests.
std::vector<std::complex<double>> Dft3Reference(const std::vector<double>& field, int n);

// E(m) for m = 0 .. n/2 (see above) of channel `channel` of a channel-interleaved N^3 field.
std::vector<double> RadialEnergySpectrum(const std::vector<float>& values, int n, int channels, int channel);

// The shell m >= 1 with the largest E(m).
int PeakShell(const std::vector<double>& energy);

}  // namespace skybake::noise
