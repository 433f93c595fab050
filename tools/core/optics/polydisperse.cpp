#include "optics/polydisperse.h"

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <numbers>
#include <optional>

#include "io/error.h"
#include "io/yaml.h"

namespace skybake::mie {

namespace {

constexpr double kPi = std::numbers::pi;

struct Sums {
  double ext = 0.0, sca = 0.0, abs = 0.0, gsca = 0.0;
};

// Quadrature node: ln r and the weight of every mode at it (trapezoid weight x sum f_i n_i).
struct Node {
  double u, w;
};

// Solid-angle weights of the grid (trapezoid in mu), for the L1 distance of phase functions.
std::vector<double> SolidAngleWeights(const PhaseGrid& grid) {
  const size_t n = grid.size();
  std::vector<double> w(n, 0.0);
  for (size_t j = 0; j + 1 < n; ++j) {
    const double h = kPi * (grid.mu[j] - grid.mu[j + 1]);  // 2 pi * half the interval
    w[j] += h;
    w[j + 1] += h;
  }
  return w;
}

struct Domain {
  double u_lo, u_hi;
};

// Upper tail mass beyond h of N(c, s) (erfc, accurate far out).
double TailAbove(double h, double c, double s) { return 0.5 * std::erfc((h - c) / (s * std::numbers::sqrt2)); }

// Smallest h in [a, b] with the mass of N(c, s) above h at most eps times its mass inside [a, b]
// (bisection; b if no smaller h qualifies). LowerTrim mirrors it.
double UpperTrim(double a, double b, double c, double s, double eps) {
  const double inside = TailAbove(a, c, s) - TailAbove(b, c, s);
  auto excess = [&](double h) { return TailAbove(h, c, s) - TailAbove(b, c, s) - eps * inside; };
  if (excess(a) <= 0.0) return a;
  double lo = a, hi = b;
  for (int i = 0; i < 100 && hi - lo > 1e-12 * std::max(1.0, std::abs(hi)); ++i) {
    const double mid = 0.5 * (lo + hi);
    (excess(mid) > 0.0 ? lo : hi) = mid;
  }
  return hi;
}
double LowerTrim(double a, double b, double c, double s, double eps) { return -UpperTrim(-b, -a, -c, s, eps); }

// ln(1 um / 1 m): u = ln(r / m) = ln(r / um) + kLnMicron.
const double kLnMicron = std::log(1e-6);

Domain QuadratureDomain(const SizeMode& mode, double k, const QuadratureOptions& o) {
  // A table: its whole support (the density is zero outside, and nothing inside is negligible
  // by construction).
  if (mode.IsTable()) return {mode.table->ln_r_um.front() + kLnMicron, mode.table->ln_r_um.back() + kLnMicron};
  const double s = mode.LnSigma();
  const double mu = std::log(mode.NumberMedianRadiusUm() * 1e-6);
  const double a = std::log(mode.r_min_um * 1e-6), b = std::log(mode.r_max_um * 1e-6);
  const double eps = o.window_tail;
  // Geometric optics (C ~ r^2): the area-weighted log-normal, centred at mu + 2 s^2.
  const double lo = LowerTrim(a, b, mu + 2.0 * s * s, s, eps);
  double hi = UpperTrim(a, b, mu + 2.0 * s * s, s, eps);
  // Rayleigh scattering (C ~ r^6), centred at mu + 6 s^2, matters only while x < 5.
  const double hi_rayleigh = std::min(UpperTrim(a, b, mu + 6.0 * s * s, s, eps), std::log(5.0 / k));
  hi = std::max(hi, hi_rayleigh);
  if (!(hi > lo)) return {a, b};  // (cannot happen for a valid mode; keep the whole range then)
  return {lo, std::min(hi, b)};
}

// The modes sharing one refractive index, on one radius grid.
class Group {
 public:
  Group(std::complex<double> m, double k, const QuadratureOptions& o) : m_(m), k_(k), o_(o) {}

  void AddPart(const MixturePart& p) {
    const SizeMode& mode = *p.mode;
    Part part;
    if (mode.IsTable()) {
      part.table = &*mode.table;
      part.scale = p.fraction / mode.table->NumberMoment(0);
    } else {
      part.s = mode.LnSigma();
      part.mu = std::log(mode.NumberMedianRadiusUm() * 1e-6);
      part.scale = p.fraction / (std::sqrt(2.0 * kPi) * part.s * mode.NumberFractionInside());
    }
    const Domain d = QuadratureDomain(mode, k_, o_);
    SKYBAKE_CHECK_LT(d.u_lo, d.u_hi);
    part.lo = d.u_lo;
    part.hi = d.u_hi;
    parts_.push_back(part);
    names_ += (names_.empty() ? "" : "+") + mode.name;
  }

  // Panels: the union of every part's partition into pieces of width <= s/2 (a table: its
  // intervals, where the density's slope changes); panels outside every part's domain are dropped.
  void Plan() {
    std::vector<double> b;
    for (const Part& p : parts_) {
      if (p.table) {
        for (double u : p.table->ln_r_um) b.push_back(u + kLnMicron);
        continue;
      }
      const int K = std::max(1, static_cast<int>(std::ceil((p.hi - p.lo) / (o_.u_step_start_sigmas * p.s))));
      for (int i = 0; i <= K; ++i) b.push_back(i == K ? p.hi : p.lo + (p.hi - p.lo) * i / K);
    }
    std::sort(b.begin(), b.end());
    std::vector<double> merged;
    for (double v : b) {
      if (merged.empty() || v - merged.back() > 1e-12 * std::max(1.0, std::abs(v))) merged.push_back(v);
    }
    for (size_t i = 0; i + 1 < merged.size(); ++i) {
      Panel pn;
      pn.a = merged[i];
      pn.b = merged[i + 1];
      const double mid = 0.5 * (pn.a + pn.b);
      for (size_t j = 0; j < parts_.size(); ++j) {
        if (mid >= parts_[j].lo && mid <= parts_[j].hi) pn.active.push_back(j);
      }
      if (pn.active.empty()) continue;
      pn.x_span = k_ * (std::exp(pn.b) - std::exp(pn.a));
      pn.n0 = std::max(1, static_cast<int>(std::ceil(pn.x_span / o_.x_step_start)));
      panels_.push_back(pn);
    }
    SKYBAKE_CHECK(!panels_.empty());
    x_min_ = k_ * std::exp(panels_.front().a);
    x_max_ = k_ * std::exp(panels_.back().b);
  }

  // Nodes of level 0 (every interval end) or of level L >= 1 (the new midpoints).
  void Nodes(int level, std::vector<Node>& out) const {
    out.clear();
    for (const Panel& p : panels_) {
      const long intervals = static_cast<long>(p.n0) << level;
      const double h = (p.b - p.a) / static_cast<double>(intervals);
      if (level == 0) {
        for (long i = 0; i <= intervals; ++i) {
          const double u = i == intervals ? p.b : p.a + i * h;
          const double w = (i == 0 || i == intervals ? 0.5 * h : h) * Density(p, u);
          if (!out.empty() && out.back().u == u) out.back().w += w;  // shared panel end
          else out.push_back({u, w});
        }
      } else {
        for (long i = 0; i < intervals / 2; ++i) {
          const double u = p.a + (2 * i + 1) * h;
          out.push_back({u, h * Density(p, u)});
        }
      }
    }
  }

  double MaxXStep(int level) const {
    double m = 0.0;
    for (const Panel& p : panels_) m = std::max(m, p.x_span / static_cast<double>(static_cast<long>(p.n0) << level));
    return m;
  }

  std::complex<double> m() const { return m_; }
  const std::string& names() const { return names_; }
  double x_min() const { return x_min_; }
  double x_max() const { return x_max_; }

 private:
  struct Part {
    double s = 0.0, mu = 0.0, scale = 0.0, lo = 0.0, hi = 0.0;
    const SizeTable* table = nullptr;  // a tabulated mode (then s, mu are unused)
  };
  struct Panel {
    double a, b, x_span;
    int n0;
    std::vector<size_t> active;
  };

  // sum over the parts active in the panel of f_i n_i(u).
  double Density(const Panel& p, double u) const {
    double d = 0.0;
    for (size_t j : p.active) {
      const Part& part = parts_[j];
      if (part.table) {
        d += part.scale * part.table->NumberDensity(u - kLnMicron);
        continue;
      }
      const double z = (u - part.mu) / part.s;
      d += part.scale * std::exp(-0.5 * z * z);
    }
    return d;
  }

  std::complex<double> m_;
  double k_;
  const QuadratureOptions& o_;
  std::vector<Part> parts_;
  std::vector<Panel> panels_;
  std::string names_;
  double x_min_ = 0.0, x_max_ = 0.0;
};

}  // namespace

double ModeMaxSizeParameter(const SizeMode& mode, double wavelength_nm, const QuadratureOptions& options) {
  const double k = 2.0 * kPi / (wavelength_nm * 1e-9);
  return k * std::exp(QuadratureDomain(mode, k, options).u_hi);
}

PhaseTables MakePhaseTables(const PhaseGrid& grid, int max_terms, size_t check_stride) {
  PhaseTables t;
  t.grid = grid;
  std::vector<double> half;
  for (size_t j = 0; j + 1 < grid.half; j += check_stride) half.push_back(grid.theta_rad[j]);
  half.push_back(grid.theta_rad[grid.half - 1]);
  t.check_grid = MirroredPhaseGrid(half);
  t.tables = AngularTables(t.grid, max_terms);
  t.check_tables = AngularTables(t.check_grid, max_terms);
  return t;
}

MixtureIntegral IntegrateMixture(std::span<const MixturePart> parts, double wavelength_nm, const PhaseTables* pt,
                                 const QuadratureOptions& o) {
  SKYBAKE_CHECK(!parts.empty());
  const double k = 2.0 * kPi / (wavelength_nm * 1e-9);
  // Group the parts by refractive index, in order of first appearance.
  std::vector<Group> groups;
  for (const MixturePart& p : parts) {
    auto it = std::find_if(groups.begin(), groups.end(), [&](const Group& g) { return g.m() == p.m; });
    if (it == groups.end()) {
      groups.emplace_back(p.m, k, o);
      it = groups.end() - 1;
    }
    it->AddPart(p);
  }
  MixtureIntegral result;
  result.x_min = INFINITY;
  for (Group& g : groups) {
    g.Plan();
    result.group_modes.push_back(g.names());
    result.x_min = std::min(result.x_min, g.x_min());
    result.x_max = std::max(result.x_max, g.x_max());
  }
  result.group_radii.assign(groups.size(), 0);

  const bool with_phase = pt != nullptr;
  const size_t nc = with_phase ? pt->check_grid.size() : 0;
  const std::vector<double> omega = with_phase ? SolidAngleWeights(pt->check_grid) : std::vector<double>();
  MieWorkspace ws;
  MieCoefficients c;
  std::optional<IntensityAccumulator> intensity;
  if (with_phase) intensity.emplace(pt->tables.max_terms());
  std::vector<Node> nodes;
  Sums sums;
  std::vector<double> check(nc, 0.0), check_prev;

  // Adds sum w f over the nodes of `level` of every group to `acc` and `phase`.
  auto evaluate = [&](int level, Sums& acc) {
    for (size_t gi = 0; gi < groups.size(); ++gi) {
      const Group& g = groups[gi];
      g.Nodes(level, nodes);
      for (const Node& node : nodes) {
        const double r = std::exp(node.u);
        ComputeCoefficients(k * r, g.m(), c, ws);
        const MieEfficiencies q = Efficiencies(c);
        const double wa = node.w * kPi * r * r;  // weight x geometric cross section
        acc.ext += wa * q.qext;
        acc.sca += wa * q.qsca;
        acc.abs += wa * q.qabs;
        acc.gsca += wa * q.gqsca;
        if (with_phase) intensity->Add(c, node.w / (k * k));
      }
      result.group_radii[gi] += static_cast<int>(nodes.size());
      result.radii += static_cast<int>(nodes.size());
    }
  };

  evaluate(0, sums);
  if (with_phase) intensity->Evaluate(pt->check_tables, check);
  for (int level = 1; level <= o.max_levels; ++level) {
    Sums next{0.5 * sums.ext, 0.5 * sums.sca, 0.5 * sums.abs, 0.5 * sums.gsca};
    if (with_phase) {
      check_prev = check;
      intensity->Scale(0.5);
    }
    evaluate(level, next);
    if (with_phase) intensity->Evaluate(pt->check_tables, check);
    // Largest relative change of the integrals (see the header).
    double change = std::abs(next.ext - sums.ext) / next.ext;
    change = std::max(change, std::abs(next.sca - sums.sca) / next.sca);
    change = std::max(change, std::abs(next.abs - sums.abs) / next.ext);
    change = std::max(change, std::abs(next.gsca - sums.gsca) / next.sca);
    double l1 = 0.0;
    if (with_phase) {
      for (size_t j = 0; j < nc; ++j) l1 += omega[j] * std::abs(check[j] / next.sca - check_prev[j] / sums.sca);
    }
    change = std::max(change, l1);
    double max_x_step = 0.0;
    for (const Group& g : groups) max_x_step = std::max(max_x_step, g.MaxXStep(level));
    sums = next;
    result.levels = level;
    result.change = change;
    result.phase_change = l1;
    if (level >= o.min_levels && change < o.tolerance && max_x_step <= o.x_step_accept) {
      result.converged = true;
      break;
    }
  }
  result.cext_m2 = sums.ext;
  result.csca_m2 = sums.sca;
  result.cabs_m2 = sums.abs;
  result.gcsca_m2 = sums.gsca;
  if (with_phase) {
    result.dcsca_domega_m2_sr.assign(pt->grid.size(), 0.0);
    intensity->Evaluate(pt->tables, result.dcsca_domega_m2_sr);
  }
  return result;
}

MixtureIntegral IntegrateMode(const SizeMode& mode, double wavelength_nm, std::complex<double> m,
                              const PhaseTables* phase, const QuadratureOptions& options) {
  const MixturePart part{&mode, 1.0, m};
  return IntegrateMixture(std::span<const MixturePart>(&part, 1), wavelength_nm, phase, options);
}

std::string DescribeModes(const ParticleType& type) {
  const std::vector<double> f = type.NumberFractions();
  std::string out;
  for (size_t i = 0; i < type.modes.size(); ++i) {
    const SizeMode& m = type.modes[i];
    if (m.IsTable()) {
      // Moments of the table itself: r_eff = <r^3>/<r^2>, v_eff = <r^4><r^2>/<r^3>^2 - 1
      // (Hansen & Travis 1974, eqs. 2.53-2.54).
      const SizeTable& t = *m.table;
      const double m2 = t.MomentUm(2), m3 = t.MomentUm(3), m4 = t.MomentUm(4);
      out += fmt::format(
          "- mode: {}\n  number_fraction: {:.9g}\n  size_table: \"{}\"\n  size_table_basis: {}\n  size_table_rows: {}\n"
          "  effective_radius_um: {:.9g}\n  effective_variance: {:.9g}\n  mean_radius_um: {:.9g}\n"
          "  r_min_um: {:.9g}\n  r_max_um: {:.9g}\n  mean_volume_inside_um3: {:.9g}\n  refractive_index: \"{}\"\n",
          m.name, f[i], t.file.filename().string(), t.basis == SizeBasis::kVolume ? "volume" : "number",
          t.ln_r_um.size(), m3 / m2, m4 * m2 / (m3 * m3) - 1.0, t.MomentUm(1), m.r_min_um, m.r_max_um,
          m.MeanVolumeInsideUm3(), m.index.Describe());
      continue;
    }
    out += fmt::format(
        "- mode: {}\n  number_fraction: {:.9g}\n  number_median_radius_um: {:.9g}\n  volume_median_radius_um: {:.9g}\n"
        "  effective_radius_um: {:.9g}\n  effective_variance: {:.9g}\n  mean_radius_um: {:.9g}\n  ln_sigma_g: {:.9g}\n"
        "  sigma_g: {:.9g}\n  r_min_um: {:.9g}\n  r_max_um: {:.9g}\n  fraction_of_particles_inside: {:.9g}\n"
        "  mean_volume_inside_um3: {:.9g}\n  refractive_index: \"{}\"\n",
        m.name, f[i], m.NumberMedianRadiusUm(), m.VolumeMedianRadiusUm(), m.EffectiveRadiusUm(), m.EffectiveVariance(),
        m.MeanRadiusUm(), m.LnSigma(), std::exp(m.LnSigma()), m.r_min_um, m.r_max_um, m.NumberFractionInside(),
        m.MeanVolumeInsideUm3(), m.index.Describe());
  }
  return out;
}

MieBuild BuildMieTable(const ParticleType& type, std::span<const double> wavelengths, const MieBuildOptions& options,
                       const ProgressFn& progress) {
  SKYBAKE_CHECK(!wavelengths.empty());
  SKYBAKE_CHECK(!type.modes.empty());
  for (size_t i = 1; i < wavelengths.size(); ++i) SKYBAKE_CHECK_LT(wavelengths[i - 1], wavelengths[i]);
  const double wl_min = wavelengths.front(), wl_max = wavelengths.back();
  CheckWavelengthCoverage(type, wl_min, wl_max);

  const PhaseGrid& grid = options.grid;
  const size_t nw = wavelengths.size(), na = grid.size(), nm = type.modes.size();
  int max_terms = 2;
  for (const SizeMode& mode : type.modes) {
    max_terms = std::max(max_terms, WiscombeTerms(ModeMaxSizeParameter(mode, wl_min, options.quadrature)));
  }
  const PhaseTables tables = MakePhaseTables(grid, max_terms);
  const std::vector<double> fraction = type.NumberFractions();

  MieBuild build;
  MieTable& t = build.table;
  t.particle = type.name;
  t.wavelength_nm.assign(wavelengths.begin(), wavelengths.end());
  t.theta_rad = grid.theta_rad;
  t.mu = grid.mu;
  t.cext_m2.assign(nw, 0.0);
  t.csca_m2.assign(nw, 0.0);
  t.cabs_m2.assign(nw, 0.0);
  t.ssa.assign(nw, 0.0);
  t.g.assign(nw, 0.0);
  t.phase_norm_error.assign(nw, 0.0);
  t.fits.assign(nw, PhaseFits{});
  t.phase.assign(nw, std::vector<double>(na, 0.0));
  t.mean_particle_volume_m3 = type.MeanVolumeUm3() * 1e-18;
  t.modes_text = DescribeModes(type);
  build.integrals.assign(nw, MixtureIntegral{});
  std::vector<std::optional<Diagnostic>> failures(nw);

  std::atomic<size_t> done{0};
  ReportProgress(progress, "mie", 0.0);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, nw, 1), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t w = range.begin(); w != range.end(); ++w) {
      const double wl = wavelengths[w];
      std::vector<MixturePart> parts;
      for (size_t i = 0; i < nm; ++i) parts.push_back({&type.modes[i], fraction[i], type.modes[i].index.At(wl)});
      MixtureIntegral mi = IntegrateMixture(parts, wl, &tables, options.quadrature);
      if (!mi.converged) {
        failures[w] = Diagnostic{type.modes.front().loc,
                                 fmt::format("at {} nm the radius quadrature did not converge to {:g} (last change "
                                             "{:.3g} after {} radii)",
                                             FormatExact(wl), options.quadrature.tolerance, mi.change, mi.radii)};
      }
      t.cext_m2[w] = mi.cext_m2;
      t.csca_m2[w] = mi.csca_m2;
      t.cabs_m2[w] = mi.cabs_m2;
      t.ssa[w] = mi.csca_m2 / mi.cext_m2;
      t.g[w] = mi.gcsca_m2 / mi.csca_m2;
      std::vector<double>& p = t.phase[w];
      for (size_t j = 0; j < na; ++j) p[j] = mi.dcsca_domega_m2_sr[j] / mi.csca_m2;
      const double integral = IntegratePhase(grid.mu, p);
      t.phase_norm_error[w] = integral - 1.0;
      for (double& v : p) v /= integral;
      if (options.fits) t.fits[w] = FitPhaseModels(grid.theta_rad, grid.mu, p, t.g[w]);
      mi.dcsca_domega_m2_sr.clear();
      build.integrals[w] = std::move(mi);
      ReportProgress(progress, "mie", static_cast<double>(++done) / nw);
    }
  });
  Diagnostics diags;
  for (const auto& f : failures) {
    if (f) diags.Add(f->loc, f->message);
  }
  diags.ThrowIfAny();
  t.FinishPhase();
  return build;
}

}  // namespace skybake::mie
