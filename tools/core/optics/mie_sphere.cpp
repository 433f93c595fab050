#include "optics/mie_sphere.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "io/error.h"

namespace skybake::mie {

namespace {

// Guard against an exact zero in the continued fraction or the recurrences (modified Lentz
// algorithm, Thompson & Barnett 1986, J. Comput. Phys. 64, 490).
constexpr double kTiny = 1e-300;

double Magnitude(double v) { return std::abs(v); }
double Magnitude(const Complex& v) { return std::abs(v.real()) + std::abs(v.imag()); }

// J_{nu-1}(z)/J_nu(z) by the modified Lentz algorithm. The continued fraction follows from the
// recurrence J_{nu-1} + J_{nu+1} = (2 nu/z) J_nu:
//   J_{nu-1}/J_nu = 2nu/z - J_{nu+1}/J_nu = b_0 - 1/(b_1 - 1/(b_2 - ...)),  b_k = 2(nu+k)/z.
// It converges for every z; the number of steps is about max(0, |z| - nu) plus a few tens
// (Lentz 1976, section III). Stops when a step changes the value by at most one ulp.
template <typename T>
T BesselRatio(double nu, T z, int* iterations) {
  const T inv_z = T(1.0) / z;
  T f = 2.0 * nu * inv_z;
  if (Magnitude(f) < kTiny) f = T(kTiny);
  T c = f;
  T d = T(0.0);
  const double limit = 20.0 * std::abs(z) + 10000.0;
  int k = 1;
  for (;; ++k) {
    SKYBAKE_CHECK_LT(static_cast<double>(k), limit);
    const T b = 2.0 * (nu + k) * inv_z;
    d = b - d;
    if (Magnitude(d) < kTiny) d = T(kTiny);
    d = T(1.0) / d;
    c = b - T(1.0) / c;
    if (Magnitude(c) < kTiny) c = T(kTiny);
    const T delta = c * d;
    f *= delta;
    if (std::norm(delta - T(1.0)) <= 2.3e-16 * 2.3e-16) break;  // (no square root per step)
  }
  if (iterations) *iterations = k;
  return f;
}

}  // namespace

int WiscombeTerms(double x) {
  const double c = std::cbrt(x);
  double n = 0.0;
  if (x <= 8.0) {
    n = x + 4.0 * c + 1.0;
  } else if (x < 4200.0) {
    n = x + 4.05 * c + 2.0;
  } else {
    n = x + 4.0 * c + 2.0;
  }
  return std::max(2, static_cast<int>(n));
}

Complex LogDerivativeLentz(int n, Complex z, int* iterations) {
  SKYBAKE_CHECK_GE(n, 1);
  return -static_cast<double>(n) / z + BesselRatio<Complex>(n + 0.5, z, iterations);
}

void ComputeCoefficients(double x, Complex m, MieCoefficients& out, MieWorkspace& ws) {
  ComputeCoefficients(std::span<const double>(&x, 1), m, std::span<MieCoefficients>(&out, 1), ws);
}

namespace {

// a_n, b_n of one sphere from its D_n(mx), with psi_n(x) and chi_n(x).
void CoefficientsFromLogDerivative(double x, Complex m, const std::vector<Complex>& d_mx, MieCoefficients& out,
                                   MieWorkspace& ws) {
  const int N = out.terms;
  // psi_n(x): upward while n <= x, then by ratios from D_n(x) (see the header).
  const double inv_x = 1.0 / x;
  const double sin_x = std::sin(x), cos_x = std::cos(x);
  ws.psi.resize(N + 1);
  ws.chi.resize(N + 1);
  ws.psi[0] = sin_x;
  ws.chi[0] = cos_x;
  const int n_up = std::min(N, static_cast<int>(std::floor(x)));
  double psi_prev = cos_x;  // psi_{-1}
  for (int n = 1; n <= n_up; ++n) {
    const double next = (2.0 * n - 1.0) * inv_x * ws.psi[n - 1] - psi_prev;
    psi_prev = ws.psi[n - 1];
    ws.psi[n] = next;
  }
  if (n_up < N) {
    ws.d_x.resize(N + 1);
    ws.d_x[N] = -static_cast<double>(N) * inv_x + BesselRatio<double>(N + 0.5, x, nullptr);
    for (int n = N; n > n_up + 1; --n) {
      const double nx = n * inv_x;
      ws.d_x[n - 1] = nx - 1.0 / (ws.d_x[n] + nx);
    }
    for (int n = n_up + 1; n <= N; ++n) ws.psi[n] = ws.psi[n - 1] / (ws.d_x[n] + n * inv_x);
  }
  // chi_n(x) upward from chi_{-1} = -sin x, chi_0 = cos x.
  double chi_prev = -sin_x;
  for (int n = 1; n <= N; ++n) {
    const double next = (2.0 * n - 1.0) * inv_x * ws.chi[n - 1] - chi_prev;
    chi_prev = ws.chi[n - 1];
    ws.chi[n] = next;
  }

  const Complex inv_m = 1.0 / m;
  for (int n = 1; n <= N; ++n) {
    const double nx = n * inv_x;
    const Complex xi_n(ws.psi[n], -ws.chi[n]);
    const Complex xi_nm1(ws.psi[n - 1], -ws.chi[n - 1]);
    const Complex da = d_mx[n] * inv_m + nx;
    const Complex db = m * d_mx[n] + nx;
    out.a[n - 1] = (da * ws.psi[n] - ws.psi[n - 1]) / (da * xi_n - xi_nm1);
    out.b[n - 1] = (db * ws.psi[n] - ws.psi[n - 1]) / (db * xi_n - xi_nm1);
  }
}

}  // namespace

void ComputeCoefficients(std::span<const double> xs, Complex m, std::span<MieCoefficients> outs, MieWorkspace& ws) {
  SKYBAKE_CHECK_EQ(xs.size(), outs.size());
  SKYBAKE_CHECK(std::isfinite(m.real()) && std::isfinite(m.imag()) && m.real() > 0.0 && m.imag() >= 0.0);
  const size_t count = xs.size();
  if (ws.d_mx.size() < count) ws.d_mx.resize(count);
  ws.inv_mx.resize(count);
  int n_max = 0;
  for (size_t i = 0; i < count; ++i) {
    const double x = xs[i];
    SKYBAKE_CHECK(std::isfinite(x) && x > 0.0);
    MieCoefficients& out = outs[i];
    const int N = WiscombeTerms(x);
    out.x = x;
    out.m = m;
    out.terms = N;
    out.a.resize(N);
    out.b.resize(N);
    // D_n(mx), n = N .. 0, downward from the continued-fraction value at N (BH eq. 4.89).
    const Complex z = m * x;
    ws.inv_mx[i] = 1.0 / z;
    std::vector<Complex>& d = ws.d_mx[i];
    d.resize(N + 1);
    d[N] = -static_cast<double>(N) * ws.inv_mx[i] + BesselRatio<Complex>(N + 0.5, z, &out.lentz_iterations);
    n_max = std::max(n_max, N);
  }
  for (int n = n_max; n >= 1; --n) {
    for (size_t i = 0; i < count; ++i) {
      if (n > outs[i].terms) continue;
      std::vector<Complex>& d = ws.d_mx[i];
      const Complex nz = static_cast<double>(n) * ws.inv_mx[i];
      Complex den = d[n] + nz;
      if (Magnitude(den) < kTiny) den = Complex(kTiny);
      d[n - 1] = nz - 1.0 / den;
    }
  }
  for (size_t i = 0; i < count; ++i) CoefficientsFromLogDerivative(xs[i], m, ws.d_mx[i], outs[i], ws);
}

MieEfficiencies Efficiencies(const MieCoefficients& c) {
  const int N = c.terms;
  double ext = 0.0, sca = 0.0, asym = 0.0;
  Complex back(0.0);
  for (int n = 1; n <= N; ++n) {
    const Complex& a = c.a[n - 1];
    const Complex& b = c.b[n - 1];
    const double w = 2.0 * n + 1.0;
    ext += w * (a.real() + b.real());
    sca += w * (std::norm(a) + std::norm(b));
    back += (n % 2 == 0 ? w : -w) * (a - b);
    asym += w / (static_cast<double>(n) * (n + 1.0)) * (a.real() * b.real() + a.imag() * b.imag());
    if (n < N) {
      const Complex& a1 = c.a[n];
      const Complex& b1 = c.b[n];
      asym += n * (n + 2.0) / (n + 1.0) *
              (a.real() * a1.real() + a.imag() * a1.imag() + b.real() * b1.real() + b.imag() * b1.imag());
    }
  }
  const double x2 = c.x * c.x;
  MieEfficiencies q;
  q.qext = 2.0 * ext / x2;
  const double qsca_sum = 2.0 * sca / x2;
  q.g = qsca_sum > 0.0 ? (4.0 * asym / x2) / qsca_sum : 0.0;
  if (c.m.imag() == 0.0) {
    q.qsca = q.qext;
    q.qabs = 0.0;
  } else {
    q.qsca = qsca_sum;
    q.qabs = q.qext - q.qsca;
  }
  q.gqsca = q.g * q.qsca;
  q.qback = std::norm(back) / x2;
  return q;
}

void Amplitudes(const MieCoefficients& c, std::span<const double> mu, std::vector<Complex>& s1,
                std::vector<Complex>& s2) {
  // c_n a_n and c_n b_n once (c_n = (2n+1)/(n(n+1))); then per angle the recurrences and sums.
  // The recurrence keeps its division by n: pi_n(+-1) and tau_n(+-1) then come out exactly equal
  // in magnitude, so S1(0) = S2(0) and S1(180) = -S2(180) hold to the last bit.
  std::vector<Complex> fa(c.terms), fb(c.terms);
  for (int n = 1; n <= c.terms; ++n) {
    const double f = (2.0 * n + 1.0) / (static_cast<double>(n) * (n + 1.0));
    fa[n - 1] = f * c.a[n - 1];
    fb[n - 1] = f * c.b[n - 1];
  }
  s1.assign(mu.size(), Complex(0.0));
  s2.assign(mu.size(), Complex(0.0));
  for (size_t j = 0; j < mu.size(); ++j) {
    const double u = mu[j];
    double pi_prev = 0.0, pi_n = 1.0;  // pi_0, pi_1
    Complex sum1(0.0), sum2(0.0);
    for (int n = 1; n <= c.terms; ++n) {
      const double tau_n = n * u * pi_n - (n + 1.0) * pi_prev;
      sum1 += fa[n - 1] * pi_n + fb[n - 1] * tau_n;
      sum2 += fa[n - 1] * tau_n + fb[n - 1] * pi_n;
      const double pi_next = ((2.0 * n + 1.0) * u * pi_n - (n + 1.0) * pi_prev) / n;
      pi_prev = pi_n;
      pi_n = pi_next;
    }
    s1[j] = sum1;
    s2[j] = sum2;
  }
}

MieSphereResult MieSphere(double x, Complex m, std::span<const double> mu) {
  MieWorkspace ws;
  MieCoefficients c;
  ComputeCoefficients(x, m, c, ws);
  MieSphereResult r;
  r.x = x;
  r.m = m;
  r.terms = c.terms;
  r.q = Efficiencies(c);
  r.mu.assign(mu.begin(), mu.end());
  Amplitudes(c, mu, r.s1, r.s2);
  return r;
}

double RayleighQsca(double x, Complex m) {
  const Complex m2 = m * m;
  const Complex L = (m2 - 1.0) / (m2 + 2.0);
  return 8.0 / 3.0 * std::pow(x, 4) * std::norm(L);
}

double RayleighQabs(double x, Complex m) {
  const Complex m2 = m * m;
  const Complex L = (m2 - 1.0) / (m2 + 2.0);
  return 4.0 * x * L.imag();
}

}  // namespace skybake::mie
