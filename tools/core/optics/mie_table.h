// The Mie table of one particle type (outputs/mie/<type>.exr): per wavelength, the per-particle
// cross sections, single-scattering albedo, asymmetry parameter, the phase function on a fine
// angle grid with its CDF, and best-fit simple models. Written by mie-tables, read by the sky
// renderers. File layout: docs/formats.md, "Mie tables"; meaning and sources: docs/mie.md.
//
// Phase function between grid angles (the rule EvalPhase and SamplePhaseCosTheta share):
//   log-linear in mu = cos theta on each interval [mu_{j+1}, mu_j]:
//     P(mu) = P_j (P_{j+1}/P_j)^t,  t = (mu_j - mu)/(mu_j - mu_{j+1});
//   exact for a Gaussian forward peak in theta (ln P linear in 1 - mu ~ theta^2/2), positive
//   everywhere. Its integral over an interval is 2 pi (mu_j - mu_{j+1}) (P_{j+1} - P_j)/ln(P_{j+1}/P_j)
//   (the logarithmic mean), so the CDF is exact and its inverse closed-form:
//     t = ln(1 + y L)/L,  L = ln(P_{j+1}/P_j),  y = (u - F_j)/(2 pi (mu_j - mu_{j+1}) P_j).
//   The tabulated P is scaled so that this interpolant integrates to exactly 1 over the sphere
//   (the scale differs from 1 by `phase_norm_error`, below 1e-4; tests/optics).
// Between tabulated wavelengths: linear in wavelength for every quantity; the phase function
// at an intermediate wavelength is the linear blend of its two neighbours (sampled exactly by
// picking one neighbour with the blend weight; SamplePhaseCosThetaAt).
#pragma once

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "io/exr.h"
#include "optics/phase_fit.h"

namespace skybake::mie {

struct MieTable {
  std::string particle;                // particle type name
  std::vector<double> wavelength_nm;   // ascending
  // Per wavelength, per particle of the mixture (docs/mie.md, "Particle types").
  std::vector<double> cext_m2, csca_m2, cabs_m2;
  std::vector<double> ssa;   // C_sca / C_ext
  std::vector<double> g;     // asymmetry parameter <cos theta>, from the Mie series
  std::vector<double> phase_norm_error;  // (grid integral of the analytic P) - 1, before scaling
  std::vector<PhaseFits> fits;
  // Angle grid shared by all wavelengths: theta ascending 0..pi, mu = cos theta descending.
  std::vector<double> theta_rad, mu;
  // [wavelength][angle]: P in sr^-1 (integral 1 over the sphere), CDF = P(Theta <= theta_j).
  std::vector<std::vector<double>> phase, cdf;
  double mean_particle_volume_m3 = 0.0;
  std::string modes_text;  // the modes with their derived parameters (report text)

  size_t wavelengths() const { return wavelength_nm.size(); }

  // P(cos theta) at tabulated wavelength `wl`, sr^-1.
  double EvalPhase(size_t wl, double cos_theta) const;
  // The angle grid's interval of cos theta and the position in it, the same for every wavelength:
  // EvalPhase(wl, c) == EvalPhase(wl, LocatePhase(c)).
  struct PhasePoint {
    size_t j = 0;
    double t = 0.0;
  };
  PhasePoint LocatePhase(double cos_theta) const;
  double EvalPhase(size_t wl, const PhasePoint& at) const {
    const std::vector<double>& lp = ln_phase_[wl];
    return std::exp(lp[at.j] + at.t * (lp[at.j + 1] - lp[at.j]));
  }
  // cos theta distributed as EvalPhase(wl, .) (times 2 pi d mu), from u in [0, 1).
  double SamplePhaseCosTheta(size_t wl, double u) const;

  // Linear interpolation in wavelength: the two neighbours and the weight of the second.
  struct Bracket {
    size_t i0 = 0, i1 = 0;
    double t = 0.0;
  };
  Bracket BracketWavelength(double wavelength_nm) const;  // throws InternalError outside
  double Interpolate(const std::vector<double>& per_wavelength, double wavelength_nm) const;
  double EvalPhaseAt(double wavelength_nm, double cos_theta) const;
  // u_pick chooses the neighbour (u_pick < t -> the second), u samples it.
  double SamplePhaseCosThetaAt(double wavelength_nm, double u_pick, double u) const;

  // Recomputes, from `phase` and `mu`, the scale that makes every wavelength's interpolant
  // integrate to 1 (applied to `phase`), the CDF and the caches EvalPhase uses. Returns the
  // largest |scale - 1| applied.
  double FinishPhase();

 private:
  std::vector<std::vector<double>> ln_phase_;  // ln P
  std::vector<double> dmu_;                    // mu_j - mu_{j+1}
};

// Integral of the interpolant over the sphere before any scaling (2 pi sum of log-means).
double IntegratePhase(const std::vector<double>& mu, const std::vector<double>& phase);

// EXR parts of the table ("spectral" and "phase"), with provenance.
std::vector<ExrPart> MieTableParts(const MieTable& table, const Provenance& provenance);
// Writes with WriteFileIfChanged; true when the file changed.
bool WriteMieTable(const std::filesystem::path& path, const MieTable& table, const Provenance& provenance);
// Reads and validates a table; throws InputError(path) for anything that is not a Mie table.
MieTable ReadMieTable(const std::filesystem::path& path);

}  // namespace skybake::mie
