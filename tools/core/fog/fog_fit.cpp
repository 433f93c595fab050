#include "fog/fog_fit.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Core>
#include <fmt/format.h>
#include <unsupported/Eigen/NonLinearOptimization>

#include "fog/fog_model.h"

namespace skybake::fog {

namespace {

// The bounded parametrisation: q (unbounded) -> (ln a, p) = c + h tanh(q - kOffset). The offset
// keeps the optimiser's variables away from 0: MINPACK's first trust region is
// factor x |scaled q| (Moré 1978 §7), which collapses for a start at q = 0 (the box's centre).
constexpr double kOffset = 10.0;
struct Box {
  double ca, ha, cp, hp;
  bool fit_p;
  double LnA(double q) const { return ca + ha * std::tanh(q - kOffset); }
  double P(double q) const { return fit_p ? cp + hp * std::tanh(q - kOffset) : 0.0; }
  double DLnA(double q) const {
    const double t = std::tanh(q - kOffset);
    return ha * (1.0 - t * t);
  }
  double DP(double q) const {
    const double t = std::tanh(q - kOffset);
    return fit_p ? hp * (1.0 - t * t) : 0.0;
  }
  // Inverse (for the start); the target is kept strictly inside.
  double QOfLnA(double ln_a) const { return kOffset + std::atanh(std::clamp((ln_a - ca) / ha, -0.999999, 0.999999)); }
  double QOfP(double p) const { return fit_p ? kOffset + std::atanh(std::clamp((p - cp) / hp, -0.999999, 0.999999)) : kOffset; }
};

// The log residual ln(F / f), with F floored at the smallest normal double (F > 0 for x > 0 and a
// finite k; the floor only guards the logarithm).
double LogResidual(const FitSample& s, double a, double p, double* dlnf_dk, double* k_out) {
  const double k = DepthExponent(a, p, s.theta);
  const double F = std::max(DepthFactor(s.x, k), std::numeric_limits<double>::min());
  if (dlnf_dk) *dlnf_dk = DepthFactorDk(s.x, k) / F;
  if (k_out) *k_out = k;
  return std::log(F) - std::log(s.target);
}

struct Functor {
  typedef double Scalar;
  enum { InputsAtCompileTime = Eigen::Dynamic, ValuesAtCompileTime = Eigen::Dynamic };
  typedef Eigen::VectorXd InputType;
  typedef Eigen::VectorXd ValueType;
  typedef Eigen::MatrixXd JacobianType;

  const std::vector<FitSample>* samples;
  Box box;
  int n_inputs;

  int inputs() const { return n_inputs; }
  int values() const { return static_cast<int>(samples->size()); }

  void Params(const Eigen::VectorXd& q, double* a, double* p) const {
    *a = std::exp(box.LnA(q[0]));
    *p = n_inputs > 1 ? box.P(q[1]) : 0.0;
  }
  int operator()(const Eigen::VectorXd& q, Eigen::VectorXd& f) const {
    double a, p;
    Params(q, &a, &p);
    for (size_t i = 0; i < samples->size(); ++i) f[static_cast<Eigen::Index>(i)] = LogResidual((*samples)[i], a, p, nullptr, nullptr);
    return 0;
  }
  int df(const Eigen::VectorXd& q, Eigen::MatrixXd& J) const {
    double a, p;
    Params(q, &a, &p);
    for (size_t i = 0; i < samples->size(); ++i) {
      const FitSample& s = (*samples)[i];
      double g = 0.0, k = 0.0;
      LogResidual(s, a, p, &g, &k);
      // k = a theta^p: dk/d(ln a) = k, dk/dp = k ln theta (zero where k is clamped).
      const double t = std::clamp(s.theta, kThetaFloor, 1.0);
      const bool clamped = k >= kMaxExponent || k <= 0.0;
      const double dk_dlna = clamped ? 0.0 : k, dk_dp = clamped ? 0.0 : k * std::log(t);
      const Eigen::Index r = static_cast<Eigen::Index>(i);
      J(r, 0) = g * dk_dlna * box.DLnA(q[0]);
      if (n_inputs > 1) J(r, 1) = g * dk_dp * box.DP(q[1]);
    }
    return 0;
  }
};

double Cost(const std::vector<FitSample>& s, double a, double p) {
  double c = 0.0;
  for (const FitSample& x : s) {
    const double r = LogResidual(x, a, p, nullptr, nullptr);
    c += r * r;
  }
  return c;
}

}  // namespace

FitResult FitDepthFactor(const std::vector<FitSample>& samples, const FitOptions& o) {
  FitResult res;
  std::vector<FitSample> used;
  used.reserve(samples.size());
  double tmin = std::numeric_limits<double>::infinity(), tmax = 0.0;
  for (const FitSample& s : samples) {
    if (std::isfinite(s.target) && s.target > 0.0 && std::isfinite(s.theta) && s.theta > 0.0 && std::isfinite(s.x) &&
        s.x > 0.0 && s.x < 1.0) {
      used.push_back(s);
      const double t = std::clamp(s.theta, kThetaFloor, 1.0);
      tmin = std::min(tmin, t);
      tmax = std::max(tmax, t);
    }
  }
  res.used = used.size();
  res.rejected = samples.size() - used.size();
  if (used.empty()) {
    res.p_fitted = false;
    res.fallback = true;
    res.status = fmt::format("no usable samples ({} rejected: fog <= 0, not finite, or x not in (0, 1)); a = 1, p = 0 "
                             "(F = (1 - e^-x)/(1 - e^-1))", res.rejected);
    return res;
  }
  Box box;
  box.ca = 0.5 * (std::log(o.a_min) + std::log(o.a_max));
  box.ha = 0.5 * (std::log(o.a_max) - std::log(o.a_min));
  box.cp = 0.5 * (o.p_min + o.p_max);
  box.hp = 0.5 * (o.p_max - o.p_min);
  box.fit_p = std::log(tmax) - std::log(tmin) > 1e-6;  // theta must vary for p to matter
  res.p_fitted = box.fit_p;

  // Start: the best node of a 13 x 13 grid (13 x 1 when p is not fitted).
  constexpr int kGrid = 13;
  double best_cost = std::numeric_limits<double>::infinity(), best_lna = box.ca, best_p = 0.0;
  for (int i = 0; i < kGrid; ++i) {
    const double lna = std::log(o.a_min) + (std::log(o.a_max) - std::log(o.a_min)) * i / (kGrid - 1);
    for (int j = 0; j < (box.fit_p ? kGrid : 1); ++j) {
      const double p = box.fit_p ? o.p_min + (o.p_max - o.p_min) * j / (kGrid - 1) : 0.0;
      const double c = Cost(used, std::exp(lna), p);
      if (c < best_cost) {
        best_cost = c;
        best_lna = lna;
        best_p = p;
      }
    }
  }

  Functor f;
  f.samples = &used;
  f.box = box;
  f.n_inputs = box.fit_p ? 2 : 1;
  Eigen::VectorXd q(f.n_inputs);
  q[0] = box.QOfLnA(best_lna);
  if (box.fit_p) q[1] = box.QOfP(best_p);
  Eigen::LevenbergMarquardt<Functor> lm(f);
  lm.parameters.maxfev = o.max_evaluations;
  lm.parameters.xtol = 1e-12;
  lm.parameters.ftol = 1e-12;
  const Eigen::LevenbergMarquardtSpace::Status st = lm.minimize(q);
  res.evaluations = static_cast<int>(lm.nfev);
  double a = std::exp(box.LnA(q[0])), p = box.fit_p ? box.P(q[1]) : 0.0;
  double cost = std::isfinite(a) && std::isfinite(p) ? Cost(used, a, p) : std::numeric_limits<double>::infinity();
  std::string how;
  switch (st) {
    case Eigen::LevenbergMarquardtSpace::RelativeReductionTooSmall:
    case Eigen::LevenbergMarquardtSpace::RelativeErrorTooSmall:
    case Eigen::LevenbergMarquardtSpace::RelativeErrorAndReductionTooSmall:
    case Eigen::LevenbergMarquardtSpace::CosinusTooSmall:
    case Eigen::LevenbergMarquardtSpace::FtolTooSmall:
    case Eigen::LevenbergMarquardtSpace::XtolTooSmall:
    case Eigen::LevenbergMarquardtSpace::GtolTooSmall:
      how = "converged";
      break;
    case Eigen::LevenbergMarquardtSpace::TooManyFunctionEvaluation:
      how = "stopped at the evaluation limit";
      break;
    default:
      how = fmt::format("Levenberg-Marquardt status {}", static_cast<int>(st));
  }
  if (!(cost <= best_cost)) {
    res.fallback = true;
    a = std::exp(best_lna);
    p = best_p;
    cost = best_cost;
    how += "; the grid's best node was kept";
  }
  res.a = a;
  res.p = p;
  res.rms_log = std::sqrt(cost / static_cast<double>(used.size()));
  const double la = (std::log(a) - box.ca) / box.ha, lp = box.fit_p ? (p - box.cp) / box.hp : 0.0;
  res.at_bound = std::fabs(la) > 0.999 || std::fabs(lp) > 0.999;
  res.status = how + fmt::format(" after {} evaluations", res.evaluations);
  if (!box.fit_p) res.status += "; p not identifiable (one theta), kept at 0";
  if (res.at_bound) res.status += "; a parameter is at its bound";
  if (res.rejected > 0) res.status += fmt::format("; {} samples left out (fog <= 0 or not finite)", res.rejected);
  return res;
}

}  // namespace skybake::fog
