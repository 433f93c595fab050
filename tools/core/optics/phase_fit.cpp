#include "optics/phase_fit.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <vector>

#include "io/error.h"

namespace skybake::mie {

namespace {

constexpr double kPi = std::numbers::pi;
// |g| <= tanh(7) = 0.9999983: the largest asymmetry the 1-D searches and the LM consider.
constexpr double kMaxAtanh = 7.0;

// Trapezoid weights in theta over [0, pi], normalised to sum 1.
std::vector<double> ThetaWeights(std::span<const double> theta) {
  const size_t n = theta.size();
  std::vector<double> w(n, 0.0);
  for (size_t j = 0; j + 1 < n; ++j) {
    const double h = 0.5 * (theta[j + 1] - theta[j]);
    w[j] += h;
    w[j + 1] += h;
  }
  double total = 0.0;
  for (double v : w) total += v;
  for (double& v : w) v /= total;
  return w;
}


struct Data {
  std::span<const double> mu;
  std::vector<double> w, ln_p, ln_1pmu2;
};

double Objective(const Data& d, double g, bool cs) {
  const double c = cs ? std::log(3.0 * (1.0 - g * g) / (8.0 * kPi * (2.0 + g * g))) : std::log((1.0 - g * g) / (4.0 * kPi));
  double e = 0.0;
  for (size_t j = 0; j < d.mu.size(); ++j) {
    double lm = c - 1.5 * std::log(1.0 + g * g - 2.0 * g * d.mu[j]);
    if (cs) lm += d.ln_1pmu2[j];
    const double r = lm - d.ln_p[j];
    e += d.w[j] * r * r;
  }
  return e;
}

// Minimises Objective over g = tanh(a): coarse scan in a, then golden-section search.
double Fit1D(const Data& d, bool cs) {
  constexpr int kScan = 57;  // a = -7 .. 7 in steps of 0.25
  int best = 0;
  double best_e = INFINITY;
  for (int i = 0; i < kScan; ++i) {
    const double a = -kMaxAtanh + 0.25 * i;
    const double e = Objective(d, std::tanh(a), cs);
    if (e < best_e) {
      best_e = e;
      best = i;
    }
  }
  double lo = -kMaxAtanh + 0.25 * std::max(0, best - 1);
  double hi = -kMaxAtanh + 0.25 * std::min(kScan - 1, best + 1);
  const double r = (std::sqrt(5.0) - 1.0) / 2.0;
  double x1 = hi - r * (hi - lo), x2 = lo + r * (hi - lo);
  double f1 = Objective(d, std::tanh(x1), cs), f2 = Objective(d, std::tanh(x2), cs);
  while (hi - lo > 1e-9) {
    if (f1 < f2) {
      hi = x2;
      x2 = x1;
      f2 = f1;
      x1 = hi - r * (hi - lo);
      f1 = Objective(d, std::tanh(x1), cs);
    } else {
      lo = x1;
      x1 = x2;
      f1 = f2;
      x2 = lo + r * (hi - lo);
      f2 = Objective(d, std::tanh(x2), cs);
    }
  }
  return std::tanh(0.5 * (lo + hi));
}

// Dual-lobe HG by Levenberg-Marquardt (parameters a1 = atanh g1, a2 = atanh g2, c = logit w).
struct DualResult {
  double g1, g2, w, e;
};

double DualObjective(const Data& d, const std::array<double, 3>& p) {
  const double g1 = std::tanh(p[0]), g2 = std::tanh(p[1]), w = 1.0 / (1.0 + std::exp(-p[2]));
  double e = 0.0;
  for (size_t j = 0; j < d.mu.size(); ++j) {
    const double r = std::log(DualHenyeyGreenstein(d.mu[j], g1, g2, w)) - d.ln_p[j];
    e += d.w[j] * r * r;
  }
  return e;
}

DualResult FitDual(const Data& d, std::array<double, 3> p) {
  double e = DualObjective(d, p);
  double lambda = 1e-3;
  bool converged = false;
  for (int iter = 0; iter < 200 && !converged && lambda < 1e12; ++iter) {
    const double g1 = std::tanh(p[0]), g2 = std::tanh(p[1]), w = 1.0 / (1.0 + std::exp(-p[2]));
    // Normal equations J^T J and J^T r of the weighted residuals.
    double A[3][3] = {}, b[3] = {};
    for (size_t j = 0; j < d.mu.size(); ++j) {
      const double mu = d.mu[j];
      const double x1 = 1.0 + g1 * g1 - 2.0 * g1 * mu, x2 = 1.0 + g2 * g2 - 2.0 * g2 * mu;
      const double h1 = (1.0 - g1 * g1) / (4.0 * kPi * x1 * std::sqrt(x1));
      const double h2 = (1.0 - g2 * g2) / (4.0 * kPi * x2 * std::sqrt(x2));
      const double m = w * h1 + (1.0 - w) * h2;
      // dHG/dg = HG (-2g/(1-g^2) - 3 (g - mu)/x); d g/d a = 1 - g^2.
      const double dh1 = h1 * (-2.0 * g1 / (1.0 - g1 * g1) - 3.0 * (g1 - mu) / x1) * (1.0 - g1 * g1);
      const double dh2 = h2 * (-2.0 * g2 / (1.0 - g2 * g2) - 3.0 * (g2 - mu) / x2) * (1.0 - g2 * g2);
      const double jac[3] = {w * dh1 / m, (1.0 - w) * dh2 / m, (h1 - h2) * w * (1.0 - w) / m};
      const double r = std::log(m) - d.ln_p[j];
      for (int a = 0; a < 3; ++a) {
        b[a] += d.w[j] * jac[a] * r;
        for (int c = 0; c < 3; ++c) A[a][c] += d.w[j] * jac[a] * jac[c];
      }
    }
    bool improved = false;
    while (lambda < 1e12) {
      // (A + lambda diag A) delta = -b by Cholesky (3x3, positive definite with the damping).
      double M[3][3];
      for (int a = 0; a < 3; ++a) {
        for (int c = 0; c < 3; ++c) M[a][c] = A[a][c] + (a == c ? lambda * A[a][a] + 1e-300 : 0.0);
      }
      double L[3][3] = {};
      bool ok = true;
      for (int i = 0; i < 3 && ok; ++i) {
        for (int k = 0; k <= i; ++k) {
          double s = M[i][k];
          for (int q = 0; q < k; ++q) s -= L[i][q] * L[k][q];
          if (i == k) {
            if (!(s > 0.0)) ok = false;
            else L[i][i] = std::sqrt(s);
          } else {
            L[i][k] = s / L[k][k];
          }
        }
      }
      if (!ok) {
        lambda *= 10.0;
        continue;
      }
      double y[3], delta[3];
      for (int i = 0; i < 3; ++i) {
        double s = -b[i];
        for (int q = 0; q < i; ++q) s -= L[i][q] * y[q];
        y[i] = s / L[i][i];
      }
      for (int i = 2; i >= 0; --i) {
        double s = y[i];
        for (int q = i + 1; q < 3; ++q) s -= L[q][i] * delta[q];
        delta[i] = s / L[i][i];
      }
      std::array<double, 3> trial{std::clamp(p[0] + delta[0], -kMaxAtanh, kMaxAtanh),
                                  std::clamp(p[1] + delta[1], -kMaxAtanh, kMaxAtanh),
                                  std::clamp(p[2] + delta[2], -30.0, 30.0)};
      const double et = DualObjective(d, trial);
      if (et < e) {
        const double gain = (e - et) / std::max(e, 1e-300);
        p = trial;
        e = et;
        lambda = std::max(lambda / 3.0, 1e-12);
        improved = true;
        converged = gain < 1e-12;
        break;
      }
      lambda *= 4.0;
    }
    if (!improved) break;
  }
  return DualResult{std::tanh(p[0]), std::tanh(p[1]), 1.0 / (1.0 + std::exp(-p[2])), e};
}

}  // namespace

double HenyeyGreenstein(double mu, double g) {
  const double x = 1.0 + g * g - 2.0 * g * mu;
  return (1.0 - g * g) / (4.0 * kPi * x * std::sqrt(x));
}

double CornetteShanks(double mu, double g) {
  const double x = 1.0 + g * g - 2.0 * g * mu;
  return 3.0 * (1.0 - g * g) * (1.0 + mu * mu) / (8.0 * kPi * (2.0 + g * g) * x * std::sqrt(x));
}

double DualHenyeyGreenstein(double mu, double g1, double g2, double w) {
  return w * HenyeyGreenstein(mu, g1) + (1.0 - w) * HenyeyGreenstein(mu, g2);
}

FitError LogRatioError(std::span<const double> theta, std::span<const double> ln_model,
                       std::span<const double> ln_phase) {
  const std::vector<double> w = ThetaWeights(theta);
  FitError e;
  double s = 0.0;
  for (size_t j = 0; j < theta.size(); ++j) {
    const double r = ln_model[j] - ln_phase[j];
    s += w[j] * r * r;
    e.max_log = std::max(e.max_log, std::abs(r));
  }
  e.rms_log = std::sqrt(s);
  return e;
}

PhaseFits FitPhaseModels(std::span<const double> theta, std::span<const double> mu, std::span<const double> phase,
                         double g_mie) {
  SKYBAKE_CHECK_EQ(theta.size(), mu.size());
  SKYBAKE_CHECK_EQ(theta.size(), phase.size());
  Data d;
  d.mu = mu;
  d.w = ThetaWeights(theta);
  d.ln_p.resize(phase.size());
  d.ln_1pmu2.resize(phase.size());
  for (size_t j = 0; j < phase.size(); ++j) {
    SKYBAKE_CHECK_GT(phase[j], 0.0);
    d.ln_p[j] = std::log(phase[j]);
    d.ln_1pmu2[j] = std::log(1.0 + mu[j] * mu[j]);
  }
  const size_t n = theta.size();
  std::vector<double> ln_model(n);
  auto error_of = [&](auto model) {
    for (size_t j = 0; j < n; ++j) ln_model[j] = std::log(model(mu[j]));
    return LogRatioError(theta, ln_model, d.ln_p);
  };

  PhaseFits f;
  f.hg_g = Fit1D(d, false);
  f.hg = error_of([&](double u) { return HenyeyGreenstein(u, f.hg_g); });
  const double gm = std::clamp(g_mie, -std::tanh(kMaxAtanh), std::tanh(kMaxAtanh));
  f.hg_moment = error_of([&](double u) { return HenyeyGreenstein(u, gm); });
  f.cs_g = Fit1D(d, true);
  f.cs = error_of([&](double u) { return CornetteShanks(u, f.cs_g); });

  // Dual lobe: three fixed starts, the best result wins (ties: the first).
  const double a_hg = std::atanh(std::clamp(f.hg_g, -0.999, 0.999));
  const std::array<std::array<double, 3>, 3> starts{{
      {a_hg, std::atanh(-0.3), std::log(0.9 / 0.1)},
      {std::min(a_hg + 1.0, kMaxAtanh), 0.0, std::log(0.7 / 0.3)},
      {std::atanh(0.95), std::atanh(0.3), std::log(0.3 / 0.7)},
  }};
  DualResult best{0.0, 0.0, 1.0, INFINITY};
  for (const auto& s : starts) {
    DualResult r = FitDual(d, s);
    if (r.e < best.e) best = r;
  }
  if (best.g1 < best.g2) {  // the first lobe is the more forward one
    std::swap(best.g1, best.g2);
    best.w = 1.0 - best.w;
  }
  f.dhg_g1 = best.g1;
  f.dhg_g2 = best.g2;
  f.dhg_w = best.w;
  f.dhg = error_of([&](double u) { return DualHenyeyGreenstein(u, f.dhg_g1, f.dhg_g2, f.dhg_w); });
  return f;
}

}  // namespace skybake::mie
