#include "optics/polydisperse.h"

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
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

// A panel spans at least this much of ln r (pieces join until it does, header): the panels'
// number bounds the memory of their Gram matrices.
constexpr double kMinPanelWidth = 0.05;

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
      Piece pc;
      pc.a = merged[i];
      pc.b = merged[i + 1];
      const double mid = 0.5 * (pc.a + pc.b);
      for (size_t j = 0; j < parts_.size(); ++j) {
        if (mid >= parts_[j].lo && mid <= parts_[j].hi) pc.active.push_back(j);
      }
      if (pc.active.empty()) continue;
      pc.x_span = k_ * (std::exp(pc.b) - std::exp(pc.a));
      pc.n0 = std::max(1, static_cast<int>(std::ceil(pc.x_span / o_.x_step_start)));
      // A piece joins the panel before it while that panel is narrower than kMinPanelWidth and
      // ends where the piece begins.
      if (!panels_.empty() && panels_.back().b == pc.a && panels_.back().b - panels_.back().a < kMinPanelWidth) {
        panels_.back().b = pc.b;
        panels_.back().x_span += pc.x_span;
        panels_.back().n0 += pc.n0;
      } else {
        panels_.push_back(Panel{pc.a, pc.b, pc.x_span, pc.n0, {}});
      }
      panels_.back().pieces.push_back(std::move(pc));
    }
    SKYBAKE_CHECK(!panels_.empty());
    x_min_ = k_ * std::exp(panels_.front().a);
    x_max_ = k_ * std::exp(panels_.back().b);
  }

  size_t panels() const { return panels_.size(); }
  // Terms of the largest sphere in panel p (what its Gram matrices need).
  int PanelTerms(size_t p) const { return WiscombeTerms(k_ * std::exp(panels_[p].b)); }
  // Mie evaluations that refining panel p from `level` to level + 1 adds.
  long NewNodes(size_t p, int level) const { return static_cast<long>(panels_[p].n0) << level; }
  // Largest spacing in size parameter of panel p's pieces at `level`.
  double XStep(size_t p, int level) const {
    double step = 0.0;
    for (const Piece& pc : panels_[p].pieces) {
      step = std::max(step, pc.x_span / static_cast<double>(static_cast<long>(pc.n0) << level));
    }
    return step;
  }

  // Nodes of panel p at level 0 (every interval end) or at level L >= 1 (the new midpoints),
  // piece by piece.
  void Nodes(size_t p_index, int level, std::vector<Node>& out) const {
    out.clear();
    for (const Piece& p : panels_[p_index].pieces) {
      const long intervals = static_cast<long>(p.n0) << level;
      const double h = (p.b - p.a) / static_cast<double>(intervals);
      if (level == 0) {
        for (long i = 0; i <= intervals; ++i) {
          const double u = i == intervals ? p.b : p.a + i * h;
          const double w = (i == 0 || i == intervals ? 0.5 * h : h) * Density(p, u);
          if (!out.empty() && out.back().u == u) out.back().w += w;  // shared piece end
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

  std::complex<double> m() const { return m_; }
  const std::string& names() const { return names_; }
  double x_min() const { return x_min_; }
  double x_max() const { return x_max_; }

 private:
  struct Part {
    double s = 0.0, mu = 0.0, scale = 0.0, lo = 0.0, hi = 0.0;
    const SizeTable* table = nullptr;  // a tabulated mode (then s, mu are unused)
  };
  // A piece of the partition: inside or outside each part's domain as a whole.
  struct Piece {
    double a, b, x_span;
    int n0;
    std::vector<size_t> active;
  };
  // A panel: consecutive pieces refined together (one level, one set of Gram matrices).
  struct Panel {
    double a, b, x_span;
    int n0;  // intervals at level 0, over its pieces
    std::vector<Piece> pieces;
  };

  // sum over the parts active in the panel of f_i n_i(u).
  double Density(const Piece& p, double u) const {
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

// One panel of one group during the refinement (header): its level, its trapezoid sums, their
// changes at its last two refinements, and its own Gram matrices with their evaluation on the
// check grid (the intensities' change, int |I_L - I_{L-1}| dOmega, is the panel's phase error).
struct PanelRun {
  size_t group = 0, panel = 0;
  int level = -1;  // -1: no node yet
  int terms = 0;
  Sums t, change, change_before;
  double l1 = 0.0, l1_before = 0.0;
  IntensityAccumulator* acc = nullptr;  // in the workspace
  std::vector<double> check, check_change;
};

// Spheres whose coefficients are computed together (mie_sphere.h: their recurrences overlap).
constexpr size_t kSpheresPerBatch = 8;

// C_ext, C_sca, C_abs, g C_sca and the phase function.
constexpr size_t kQuantities = 5;
// The bound on the sum of the panels' own estimates, in tolerances (header).
constexpr double kPanelSumFactor = 3.0;

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

// The adaptive radius quadrature of the header, in one function because the groups, their
// panels' runs, the refinement and the stopping rule share one state: the panels' sums, Gram
// matrices and check intensities, which only the final full-grid evaluation reads together.
MixtureIntegral IntegrateMixture(std::span<const MixturePart> parts, double wavelength_nm, const PhaseTables* pt,
                                 const QuadratureOptions& o, QuadratureWorkspace* workspace) {
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
  const std::vector<double> omega = with_phase ? SolidAngleWeights(pt->check_grid) : std::vector<double>();
  QuadratureWorkspace local;
  QuadratureWorkspace& space = workspace ? *workspace : local;
  std::vector<PanelRun> runs;
  for (size_t gi = 0; gi < groups.size(); ++gi) {
    for (size_t p = 0; p < groups[gi].panels(); ++p) {
      PanelRun run;
      run.group = gi;
      run.panel = p;
      run.terms = groups[gi].PanelTerms(p);
      if (with_phase) {
        run.check.assign(pt->check_grid.size(), 0.0);
        run.check_change.assign(pt->check_grid.size(), 0.0);
      }
      runs.push_back(std::move(run));
    }
  }
  if (with_phase) {
    if (space.panels.size() < runs.size()) space.panels.resize(runs.size(), IntensityAccumulator(1));
    for (size_t i = 0; i < runs.size(); ++i) {
      runs[i].acc = &space.panels[i];
      runs[i].acc->Reset(runs[i].terms);
    }
  }

  MieWorkspace ws;
  std::array<MieCoefficients, kSpheresPerBatch> c;
  std::array<double, kSpheresPerBatch> radius, x;
  std::vector<Node> nodes;
  std::vector<double> check_prev;
  // Takes a panel to its next level: T_L = T_{L-1} / 2 + h_L sum over the new midpoints (the Gram
  // matrices alike), and the changes of its sums and of its intensities on the check grid.
  auto refine = [&](PanelRun& run) {
    const Group& g = groups[run.group];
    const int level = run.level + 1;
    g.Nodes(run.panel, level, nodes);
    Sums next;
    if (level > 0) {
      next = {0.5 * run.t.ext, 0.5 * run.t.sca, 0.5 * run.t.abs, 0.5 * run.t.gsca};
      if (with_phase) run.acc->Scale(0.5);
    }
    // The check intensities: I_L = I_{L-1}/2 + the new spheres' direct sums when they are few
    // (direct: ~8 N operations per sphere and angle; an evaluation of G: ~2 N^2 per angle, at a
    // lower rate: measured, direct up to N/2 new spheres is the faster).
    const bool direct = with_phase && 2 * nodes.size() < static_cast<size_t>(run.terms);
    if (with_phase) {
      check_prev = run.check;
      if (direct && level > 0) {
        for (double& v : run.check) v *= 0.5;
      }
    }
    for (size_t first = 0; first < nodes.size(); first += kSpheresPerBatch) {
      const size_t count = std::min(kSpheresPerBatch, nodes.size() - first);
      for (size_t i = 0; i < count; ++i) {
        radius[i] = std::exp(nodes[first + i].u);
        x[i] = k * radius[i];
      }
      ComputeCoefficients(std::span<const double>(x.data(), count), g.m(), std::span<MieCoefficients>(c.data(), count), ws);
      for (size_t i = 0; i < count; ++i) {
        const double r = radius[i], w = nodes[first + i].w;
        const MieEfficiencies q = Efficiencies(c[i]);
        const double wa = w * kPi * r * r;  // weight x geometric cross section
        next.ext += wa * q.qext;
        next.sca += wa * q.qsca;
        next.abs += wa * q.qabs;
        next.gsca += wa * q.gqsca;
        if (with_phase) {
          run.acc->Add(c[i], w / (k * k));
          if (direct) AddDirectIntensities(c[i], w / (k * k), pt->check_tables, run.check);
        }
      }
    }
    result.group_radii[run.group] += static_cast<int>(nodes.size());
    result.radii += static_cast<int>(nodes.size());
    if (with_phase && !direct) run.acc->Evaluate(pt->check_tables, run.check);
    if (level > 0) {
      run.change_before = run.change;
      run.change = {next.ext - run.t.ext, next.sca - run.t.sca, next.abs - run.t.abs, next.gsca - run.t.gsca};
      run.l1_before = run.l1;
      run.l1 = 0.0;
      for (size_t j = 0; j < run.check.size(); ++j) {
        run.check_change[j] = run.check[j] - check_prev[j];
        run.l1 += omega[j] * std::abs(run.check_change[j]);
      }
    }
    run.t = next;
    run.level = level;
  };

  // Every panel to the level where its spacing is at most x_step_accept, and at least 2 (two
  // changes to estimate its error from) and min_levels.
  for (PanelRun& run : runs) {
    const Group& g = groups[run.group];
    while (run.level < 2 || run.level < o.min_levels || g.XStep(run.panel, run.level) > o.x_step_accept) {
      if (run.level >= o.max_levels) break;
      refine(run);
    }
  }

  // The two error measures of the header, per quantity (C_ext, C_sca, C_abs, g C_sca, P): the
  // change between the mixture and the mixture with every panel one level coarser (its sums less
  // its last change), and the sum over the panels of each one's own estimate.
  auto panel_estimate = [](const PanelRun& run, const Sums& total) {
    auto e = [](double now, double before) { return std::max(std::abs(now), 0.5 * std::abs(before)); };
    return std::array<double, kQuantities>{
        e(run.change.ext, run.change_before.ext) / total.ext, e(run.change.sca, run.change_before.sca) / total.sca,
        e(run.change.abs, run.change_before.abs) / total.ext, e(run.change.gsca, run.change_before.gsca) / total.sca,
        e(run.l1, run.l1_before) / total.sca};
  };
  const size_t nc = with_phase ? pt->check_grid.size() : 0;
  std::vector<double> i_now(nc), i_coarser(nc);
  Sums total;
  for (;;) {
    Sums coarser;
    total = Sums{};
    std::fill(i_now.begin(), i_now.end(), 0.0);
    std::fill(i_coarser.begin(), i_coarser.end(), 0.0);
    for (const PanelRun& run : runs) {
      total.ext += run.t.ext;
      total.sca += run.t.sca;
      total.abs += run.t.abs;
      total.gsca += run.t.gsca;
      coarser.ext += run.t.ext - run.change.ext;
      coarser.sca += run.t.sca - run.change.sca;
      coarser.abs += run.t.abs - run.change.abs;
      coarser.gsca += run.t.gsca - run.change.gsca;
      for (size_t j = 0; j < nc; ++j) {
        i_now[j] += run.check[j];
        i_coarser[j] += run.check[j] - run.check_change[j];
      }
    }
    std::array<double, kQuantities> change{std::abs(total.ext - coarser.ext) / total.ext,
                                           std::abs(total.sca - coarser.sca) / total.sca,
                                           std::abs(total.abs - coarser.abs) / total.ext,
                                           std::abs(total.gsca - coarser.gsca) / total.sca, 0.0};
    for (size_t j = 0; j < nc; ++j) change[4] += omega[j] * std::abs(i_now[j] / total.sca - i_coarser[j] / coarser.sca);
    std::array<double, kQuantities> panel_sum{};
    for (const PanelRun& run : runs) {
      const auto e = panel_estimate(run, total);
      for (size_t q = 0; q < kQuantities; ++q) panel_sum[q] += e[q];
    }
    // The quantity furthest from its bounds.
    size_t worst = 0;
    double worst_ratio = -1.0;
    for (size_t q = 0; q < kQuantities; ++q) {
      const double ratio = std::max(change[q] / o.tolerance, panel_sum[q] / (kPanelSumFactor * o.tolerance));
      if (ratio > worst_ratio) {
        worst_ratio = ratio;
        worst = q;
      }
    }
    result.change = *std::max_element(change.begin(), change.end());
    result.phase_change = change[4];
    result.panel_change_sum = *std::max_element(panel_sum.begin(), panel_sum.end());
    if (worst_ratio < 1.0) {
      result.converged = true;
      break;
    }
    // The panel whose refinement removes the most of that quantity's estimated error per
    // operation: its new nodes and one evaluation on the check grid, each ~ terms^2.
    PanelRun* best = nullptr;
    double best_score = -1.0;
    for (PanelRun& run : runs) {
      const double work = static_cast<double>(groups[run.group].NewNodes(run.panel, run.level + 1)) +
                          static_cast<double>(nc);
      const double score = panel_estimate(run, total)[worst] / (work * run.terms * run.terms);
      if (score > best_score) {
        best_score = score;
        best = &run;
      }
    }
    if (best->level >= o.max_levels) break;
    refine(*best);
  }

  for (const PanelRun& run : runs) result.levels = std::max(result.levels, run.level);
  result.cext_m2 = total.ext;
  result.csca_m2 = total.sca;
  result.cabs_m2 = total.abs;
  result.gcsca_m2 = total.gsca;
  if (with_phase) {
    int terms = 1;
    for (const PanelRun& run : runs) terms = std::max(terms, run.terms);
    IntensityAccumulator& sum = space.sum;
    sum.Reset(terms);
    for (PanelRun& run : runs) sum.AddAccumulator(*run.acc);
    result.dcsca_domega_m2_sr.assign(pt->grid.size(), 0.0);
    sum.Evaluate(pt->tables, result.dcsca_domega_m2_sr);
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
  tbb::enumerable_thread_specific<QuadratureWorkspace> workspaces;
  ReportProgress(progress, "mie", 0.0);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, nw, 1), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t w = range.begin(); w != range.end(); ++w) {
      const double wl = wavelengths[w];
      std::vector<MixturePart> parts;
      for (size_t i = 0; i < nm; ++i) parts.push_back({&type.modes[i], fraction[i], type.modes[i].index.At(wl)});
      MixtureIntegral mi = IntegrateMixture(parts, wl, &tables, options.quadrature, &workspaces.local());
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
