// Polydisperse Mie optics: integrals of single-sphere cross sections and scattering intensities
// over the modes (log-normal or tabulated) of a particle type, per wavelength, and the Mie table built from them.
//
// Per mode (number distribution n(u) du over u = ln r, normalised to one particle inside
// [r_min, r_max]; particle_type.h), with k = 2 pi / lambda and x = k r:
//   <C_ext> = int pi r^2 Q_ext(x, m) n(u) du       (same for sca, abs; g C_sca with g Q_sca)
//   <dC_sca/dOmega>(theta) = int i(theta; x, m) / k^2 n(u) du,   i = (|S1|^2 + |S2|^2)/2
// Modes combine by number fraction f_i (Wiscombe, MIEV.doc L345-371: integrate cross sections and
// intensities, never Q, albedo, g or the normalised P; Mishchenko, Travis & Lacis 2002, eqs 5.242-5.250):
//   <C> = sum f_i <C>_i,  omega = <C_sca>/<C_ext>,  g = sum f_i <g C_sca>_i / <C_sca>,
//   P(theta) = sum f_i <dC_sca/dOmega>_i / <C_sca>    (integral 1 over the sphere).
//
// Radius quadrature (docs/mie.md, "Radius quadrature"):
//   - modes with the same refractive index share one radius grid: each node (one Mie
//     evaluation) serves every such mode, weighted by sum_i f_i n_i(u);
//   - a mode's domain: the part of [ln r_min, ln r_max] outside which the weights that the cross
//     sections can have hold less than 1e-10 of their mass inside [r_min, r_max]: r^2 n(r)
//     (geometric optics, C <= Q_max pi r^2), and r^6 n(r) (Rayleigh scattering, C ~ x^4 pi r^2)
//     as long as x < 5 (beyond, Q is bounded and the r^2 bound rules); absorption (~ r^3) lies
//     between. Each is a log-normal with the same s, centred at ln r_g + p s^2 (Hatch-Choate),
//     so the cut-offs follow from erfc. The normalisation uses the full [r_min, r_max] (erf);
//   - a tabulated mode's domain is its table's [r_1, r_n], its pieces the table's intervals (the
//     density is linear in ln r on each, size_table.h), so the trapezoid meets no kink inside
//     a panel;
//   - pieces: the union of every mode's partition of its domain into pieces of width <= s/2;
//     each piece lies wholly inside or outside each mode's domain, so a truncated mode is the
//     exact composite trapezoid on its own domain. Piece p gets n_p = max(1, ceil(Delta x_p / 2))
//     intervals at level 0 (Delta x_p its size-parameter span): the spacing adapts to the size
//     parameter, at most 2 in x and s/2 in u;
//   - panels: consecutive pieces joined until a panel spans at least 0.05 in u (a table's fine
//     intervals, slivers between two modes' boundaries): a panel is refined as one and holds
//     one pair of Gram matrices, so the panels' number bounds the memory;
//   - each panel has its own level; a refinement halves its intervals (nested: only the new
//     midpoints are computed, T_L = T_{L-1}/2 + h_L sum f(new)). Every panel starts at the level
//     where its spacing is at most 0.5 in x (2 nodes per ripple period or more, so that
//     under-sampled ripple cannot look converged), and at least 2;
//   - each panel keeps its own sums and Gram matrices (mie_angular.h), so its change at its last
//     refinement is known for every integral: for the phase function the L1 change of its
//     intensities, int |I_L - I_{L-1}| dOmega / C_sca, on a check grid (every 16th angle of the
//     table's grid, mirrored); its error estimate is max(|last change|, |change before| / 2),
//     which a change that happens to be small at one level does not hide;
//   - converged when, for the mixture's C_ext, C_sca, C_abs (relative to C_ext), g C_sca
//     (relative to C_sca) and phase function (L1 distance int |P - P'| dOmega), both
//       the change between the mixture and the mixture with every panel one level coarser
//       (P' from those coarser sums) is less than `tolerance` (1e-4), and
//       the sum over the panels of their estimates is less than 3 `tolerance`
//     (the second bound keeps a cancellation between panels from passing for convergence; the
//     factor 3 is measured, docs/mie.md). Until then, the panel whose refinement removes the
//     most of the estimate of the integral furthest from its bounds per operation (new nodes and
//     one check evaluation, each ~ its terms^2) is refined: the spacing follows where the
//     integrand has weight, not only the size parameter.
//     The criterion is on the integrals the table stores (the mixture's), not on each mode:
//     a mode holding 5 % of the extinction needs only 2e-3 of its own.
#pragma once

#include <complex>
#include <span>
#include <string>
#include <vector>

#include "io/progress.h"
#include "optics/mie_angular.h"
#include "optics/mie_table.h"
#include "optics/particle_type.h"
#include "optics/phase_grid.h"

namespace skybake::mie {

struct QuadratureOptions {
  double tolerance = 1e-4;         // relative change between levels that counts as converged
  double x_step_start = 2.0;       // level-0 spacing in size parameter, at most
  double x_step_accept = 0.5;      // convergence is accepted only at this spacing or finer
  double u_step_start_sigmas = 0.5;  // level-0 spacing in ln r, at most, in units of s
  double window_tail = 1e-10;      // the domain described above
  int max_levels = 16;
  int min_levels = 0;              // refine at least this many times (tests of convergence)
};

// The angle grid, its p_n/q_n tables, and a coarser grid (every 16th angle of [0, pi/2], and
// pi/2, mirrored) on which the phase function's convergence is checked at every refinement; the
// full grid is evaluated once, when converged. The L1 distance on the coarse grid is a trapezoid
// estimate of the same integral.
struct PhaseTables {
  PhaseGrid grid, check_grid;
  AngularTables tables, check_tables;
};
PhaseTables MakePhaseTables(const PhaseGrid& grid, int max_terms, size_t check_stride = 16);

// One component of a mixture: a mode, its number fraction in the mixture and its index at the
// wavelength.
struct MixturePart {
  const SizeMode* mode = nullptr;
  double fraction = 1.0;
  std::complex<double> m;
};

struct MixtureIntegral {
  // Per particle of the mixture (the fractions weight the parts).
  double cext_m2 = 0.0, csca_m2 = 0.0, cabs_m2 = 0.0, gcsca_m2 = 0.0;
  std::vector<double> dcsca_domega_m2_sr;  // per grid angle (empty without tables)
  int radii = 0;        // Mie evaluations in all (nodes of the final level, every group)
  std::vector<int> group_radii;  // per refractive-index group, in order of first appearance
  std::vector<std::string> group_modes;  // the modes of each group, "+"-joined
  int levels = 0;       // the finest panel's level (refinements after level 0)
  double change = 0.0;  // largest relative change against every panel one level coarser
  double phase_change = 0.0;  // its phase-function part (L1)
  double panel_change_sum = 0.0;  // largest sum over the panels of their own estimates
  double x_min = 0.0, x_max = 0.0;  // size-parameter range integrated
  bool converged = false;
};

// Scratch memory of IntegrateMixture (every panel's Gram matrices), reused by the calls of one
// thread so that a table build does not fault in fresh pages per wavelength.
struct QuadratureWorkspace {
  std::vector<IntensityAccumulator> panels;
  IntensityAccumulator sum{1};
};

// The mixture at one wavelength. `phase` may be null (no phase function then); `workspace` may be
// null (a local one then).
MixtureIntegral IntegrateMixture(std::span<const MixturePart> parts, double wavelength_nm, const PhaseTables* phase,
                                 const QuadratureOptions& options, QuadratureWorkspace* workspace = nullptr);
// One mode alone (fraction 1).
MixtureIntegral IntegrateMode(const SizeMode& mode, double wavelength_nm, std::complex<double> m,
                              const PhaseTables* phase, const QuadratureOptions& options);

// Largest size parameter a mode's quadrature reaches at a wavelength (for table sizing).
double ModeMaxSizeParameter(const SizeMode& mode, double wavelength_nm, const QuadratureOptions& options);

struct MieBuildOptions {
  QuadratureOptions quadrature;
  PhaseGrid grid = StandardPhaseGrid();
  bool fits = true;
};

struct MieBuild {
  MieTable table;
  // Per wavelength: how the integral converged (phase arrays dropped), for the report.
  std::vector<MixtureIntegral> integrals;
};

// The whole table: wavelengths in parallel (TBB), each computed independently and in a fixed
// order, so the result does not depend on the number of threads. Throws InputError when a
// wavelength is outside a mode's refractive-index table, and when a quadrature does not converge.
MieBuild BuildMieTable(const ParticleType& type, std::span<const double> wavelengths_nm,
                       const MieBuildOptions& options, const ProgressFn& progress = {});

// Text describing the modes and their derived parameters (stored in the table and the report).
std::string DescribeModes(const ParticleType& type);

}  // namespace skybake::mie
