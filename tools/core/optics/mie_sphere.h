// Mie scattering by one homogeneous sphere: efficiencies, asymmetry parameter and the scattering
// amplitudes S1(theta), S2(theta), for a size parameter x = 2 pi r / lambda (r the radius, lambda
// the wavelength in the surrounding medium) and a complex relative refractive index m.
//
// Conventions (Bohren & Huffman 1983, "Absorption and Scattering of Light by Small Particles",
// Wiley, chapter 4 and appendix A, "BH" below):
//   - time dependence e^{-i omega t}, so m = n + i k with k >= 0 for an absorbing sphere;
//     Wiscombe's MIEV0 and many tables write m = n - i k; their S1, S2 are the complex conjugates
//     of these (Du 2004, Table 2, prints the BH signs);
//   - S1 is the amplitude for the electric field perpendicular to the scattering plane, S2
//     parallel (BH eq. 4.74); |S1|^2 + |S2|^2 = 2 k^2 dC_sca/dOmega for unpolarised light.
//
// The Lorenz-Mie series (BH eqs. 4.53, 4.61, 4.62, 4.74, 4.88):
//   a_n = [(D_n(mx)/m + n/x) psi_n(x) - psi_{n-1}(x)] / [(D_n(mx)/m + n/x) xi_n(x) - xi_{n-1}(x)]
//   b_n = [(m D_n(mx) + n/x) psi_n(x) - psi_{n-1}(x)] / [(m D_n(mx) + n/x) xi_n(x) - xi_{n-1}(x)]
//   Q_ext = 2/x^2 sum (2n+1) Re(a_n + b_n)          Q_sca = 2/x^2 sum (2n+1)(|a_n|^2 + |b_n|^2)
//   g Q_sca = 4/x^2 sum [ n(n+2)/(n+1) Re(a_n a*_{n+1} + b_n b*_{n+1}) + (2n+1)/(n(n+1)) Re(a_n b*_n) ]
//   Q_back = 1/x^2 |sum (2n+1) (-1)^n (a_n - b_n)|^2 = 4 |S1(pi)|^2 / x^2
//   S1(mu) = sum (2n+1)/(n(n+1)) (a_n pi_n(mu) + b_n tau_n(mu)),
//   S2(mu) = sum (2n+1)/(n(n+1)) (a_n tau_n(mu) + b_n pi_n(mu))
// with the Riccati-Bessel functions psi_n(x) = x j_n(x), chi_n(x) = -x y_n(x),
// xi_n = psi_n - i chi_n = x h_n^(1)(x), the logarithmic derivative D_n(z) = psi_n'(z)/psi_n(z),
// and the angular functions pi_n = P_n^1(mu)/sin(theta), tau_n = dP_n^1(cos theta)/d theta.
//
// Numerics, and why (the source of each is named in its item):
//   - Number of terms: Wiscombe's criterion (Wiscombe 1980, Appl. Opt. 19, 1505, eq. R50 of
//     MIEV0): N = x + 4 x^(1/3) + 1 (x <= 8), x + 4.05 x^(1/3) + 2 (8 < x < 4200),
//     x + 4 x^(1/3) + 2 (x >= 4200); never fewer than 2 terms, because for a Rayleigh-size sphere
//     g comes from the interference of a_1 with a_2 and b_1 (both O(x^5)), so a single term
//     would give a wrong g however small x is.
//   - D_n(mx) by downward recurrence D_{n-1} = n/z - 1/(D_n + n/z) (BH eq. 4.89), started at
//     n = N with the exact value from Lentz's continued fraction (W. J. Lentz, Appl. Opt. 15,
//     668 (1976); evaluated with the modified Lentz algorithm). The classic start
//     "0 at max(N, |mx|) + 15" leaves Q_back wrong by 20 % at m = 1.45, x = 1000 (notes §1.2).
//     psi_n(mx) itself is never formed, so nothing overflows when Im(m) x is large.
//   - psi_n(x) upward (psi_{n+1} = (2n+1)/x psi_n - psi_{n-1}) only where it is stable, n <= x
//     (oscillatory region); above x, where psi_n decays like x^{n+1}/(2n+1)!! and the upward
//     recurrence loses every digit at small x (g 29x wrong at x = 1e-4, notes §1.3), from the
//     ratio psi_{n-1}/psi_n = D_n(x) + n/x with D_n(x) again downward from a Lentz start.
//     psi_n has no zero for n > x - 1/2 (its first zero is beyond n + 1/2), so the ratio is safe.
//   - chi_n(x) upward (it grows, the recurrence is stable).
//   - For a real m, Q_abs = 0 and Q_sca = Q_ext exactly (the two sums agree to rounding; Q_ext,
//     a linear sum, is the more accurate).
// Validity: checked against published test sets for 1e-6 <= x <= 2e4, 0.75 <= Re m <= 10,
// 0 <= Im m <= 10 (tests/optics/mie_sphere_test.cpp). Double precision throughout.
#pragma once

#include <complex>
#include <span>
#include <vector>

namespace skybake::mie {

using Complex = std::complex<double>;

// Wiscombe's number of terms N (at least 2), x > 0.
int WiscombeTerms(double x);

// D_n(z) = psi_n'(z)/psi_n(z) from Lentz's continued fraction, n >= 1, z != 0:
//   D_n(z) = -n/z + J_{n-1/2}(z)/J_{n+1/2}(z),
//   J_{nu-1}/J_nu = b_0 - 1/(b_1 - 1/(b_2 - ...)),  b_k = 2 (nu + k)/z   (nu = n + 1/2).
// `iterations`, if given, receives the number of continued-fraction steps taken.
Complex LogDerivativeLentz(int n, Complex z, int* iterations = nullptr);

// Reusable buffers so that repeated calls (one per radius in a size integral) do not allocate.
struct MieWorkspace {
  std::vector<std::vector<Complex>> d_mx;  // per sphere of a batch: D_n(mx), n = 0..N
  std::vector<Complex> inv_mx;             // per sphere of a batch: 1 / (m x)
  std::vector<double> d_x;     // D_n(x) where the ratio method is used
  std::vector<double> psi;     // psi_n(x), n = 0..N (index n)
  std::vector<double> chi;     // chi_n(x), n = 0..N
};

// The Mie coefficients a_n, b_n, n = 1..N (stored at index n - 1).
struct MieCoefficients {
  double x = 0.0;
  Complex m;
  int terms = 0;
  std::vector<Complex> a, b;
  int lentz_iterations = 0;  // continued-fraction steps for the D_n(mx) start (cost figure)
};

// Computes a_n, b_n for x > 0 and m with Re m > 0, Im m >= 0 (checked).
void ComputeCoefficients(double x, Complex m, MieCoefficients& out, MieWorkspace& ws);
// The same for several spheres of one index (out[i] for x[i]; the same bits as one at a time).
// The downward D_n(mx) recurrence is a chain of dependent complex divisions (~10 ns per term,
// most of a sphere's cost); the spheres' chains are interleaved so that their latencies overlap.
void ComputeCoefficients(std::span<const double> x, Complex m, std::span<MieCoefficients> out, MieWorkspace& ws);

// Efficiencies from coefficients (the sums above).
struct MieEfficiencies {
  double qext = 0.0, qsca = 0.0, qabs = 0.0, qback = 0.0;
  double g = 0.0;       // asymmetry parameter <cos theta>
  double gqsca = 0.0;   // g * Q_sca (what a size integral needs; g itself is 0/0 when Q_sca = 0)
};
MieEfficiencies Efficiencies(const MieCoefficients& c);

// S1, S2 at the cosines `mu` (the straightforward O(N * angles) sum with the pi_n/tau_n
// recurrences of BH eqs. 4.47: pi_n = (2n-1)/(n-1) mu pi_{n-1} - n/(n-1) pi_{n-2},
// tau_n = n mu pi_n - (n+1) pi_{n-1}, pi_0 = 0, pi_1 = 1).
void Amplitudes(const MieCoefficients& c, std::span<const double> mu, std::vector<Complex>& s1,
                std::vector<Complex>& s2);

// Everything for one sphere, the reference path used by `mie-tables sphere` and the tests.
struct MieSphereResult {
  double x = 0.0;
  Complex m;
  int terms = 0;
  MieEfficiencies q;
  std::vector<double> mu;
  std::vector<Complex> s1, s2;
};
MieSphereResult MieSphere(double x, Complex m, std::span<const double> mu = {});

// Small-particle (Rayleigh) limits for x -> 0 (BH eqs. 5.8, 5.11; L = (m^2 - 1)/(m^2 + 2)):
//   Q_sca -> 8/3 x^4 |L|^2,  Q_abs -> 4 x Im(L).
double RayleighQsca(double x, Complex m);
double RayleighQabs(double x, Complex m);

}  // namespace skybake::mie
