// The layered, spherically symmetric atmosphere as the renderers see it: optical coefficients
// of each constituent on the altitude levels and the wavelength grid, their phase functions, the
// Lambertian ground and the sun (docs/atmosphere.md; Bruneton & Neyret 2008 §2.1).
//
// Coefficients are tabulated per level (the profile grid of profile-import) and wavelength, in
// m^-1, and are *linear in altitude between levels* (which is also what makes the trapezoid rule
// exact for the columns profile-import reports). Wavelengths are a discrete grid: renderers
// compute spectral radiance at these wavelengths and integrate colour with per-wavelength
// weights (spectrum/xyz.h), so the reference spectrum is defined on the same grid as every
// other method.
//
// Geometry: the planet centre is the origin; the ground is the sphere of radius bottom_radius_m
// and the top of the atmosphere the sphere of radius top_radius_m (no medium above).
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "io/interp.h"

namespace skybake {

// A phase function per wavelength (sr^-1, integral over the sphere = 1) with importance
// sampling of the scattering-angle cosine. Azimuth is uniform for every model here.
class PhaseModel {
 public:
  virtual ~PhaseModel() = default;
  virtual double Eval(size_t wl, double mu) const = 0;
  // Eval(w, mu) for w = 0 .. n-1 into out (the same values); a model whose lookup in mu does not
  // depend on the wavelength does it once (the tabulated Mie phase).
  virtual void EvalAll(double mu, size_t n, double* out) const {
    for (size_t w = 0; w < n; ++w) out[w] = Eval(w, mu);
  }
  // mu distributed as 2 pi Eval(wl, mu) from a uniform u in [0, 1).
  virtual double SampleMu(size_t wl, double u) const = 0;
  virtual std::string Name() const = 0;
};

class IsotropicPhase : public PhaseModel {
 public:
  double Eval(size_t, double) const override;
  double SampleMu(size_t, double u) const override { return 2.0 * u - 1.0; }
  std::string Name() const override { return "isotropic"; }
};

// Depolarised Rayleigh phase (optics/rayleigh.h) with gamma per wavelength.
class RayleighPhase : public PhaseModel {
 public:
  explicit RayleighPhase(std::vector<double> gamma) : gamma_(std::move(gamma)) {}
  double Eval(size_t wl, double mu) const override;
  double SampleMu(size_t wl, double u) const override;
  std::string Name() const override { return "rayleigh"; }

 private:
  std::vector<double> gamma_;
};

// Henyey-Greenstein with asymmetry g per wavelength (Henyey & Greenstein 1941):
//   P(mu) = (1 - g^2) / (4 pi (1 + g^2 - 2 g mu)^{3/2}), sampled by its closed-form inverse CDF.
class HenyeyGreensteinPhase : public PhaseModel {
 public:
  explicit HenyeyGreensteinPhase(std::vector<double> g) : g_(std::move(g)) {}
  double Eval(size_t wl, double mu) const override;
  double SampleMu(size_t wl, double u) const override;
  std::string Name() const override { return "henyey-greenstein"; }
  static double Eval(double g, double mu);
  static double SampleMu(double g, double u);

 private:
  std::vector<double> g_;
};

// Cornette & Shanks (1992), Appl. Opt. 31, 3152, eq. 4, with asymmetry parameter g per wavelength:
//   P(mu) = 3 (1 - g^2) (1 + mu^2) / (8 pi (2 + g^2) (1 + g^2 - 2 g mu)^{3/2}),
// normalised to 1 over the sphere (the aerosol phase of Bruneton 2017's reference model).
// Sampled by rejection from HG(g): P_CS / P_HG = 3/2 (1 + mu^2)/(2 + g^2) <= 3/(2 + g^2); a
// rejection loop needs a varying number of uniforms, so the one uniform u seeds a local stream
// (deterministic: the same u gives the same mu).
class CornetteShanksPhase : public PhaseModel {
 public:
  explicit CornetteShanksPhase(std::vector<double> g) : g_(std::move(g)) {}
  static double Eval(double g, double mu);
  double Eval(size_t wl, double mu) const override { return Eval(g_[wl], mu); }
  double SampleMu(size_t wl, double u) const override;
  std::string Name() const override { return "cornette-shanks"; }

 private:
  std::vector<double> g_;
};

struct MediumComponent {
  std::string name;                          // "rayleigh", "ozone", "aerosol.<name>"
  std::shared_ptr<const PhaseModel> phase;   // null for a pure absorber
  std::vector<double> scattering;            // [level * n_wl + wl], m^-1
  std::vector<double> absorption;            // [level * n_wl + wl], m^-1
};

// The sun as seen from the top of the atmosphere: a disk of angular radius
// `angular_radius_rad` with spectral irradiance `irradiance[wl]` (W m^-2 nm^-1, normal incidence)
// and limb darkening I(mu)/I(1) = sum_k a_k mu^k (a_k per wavelength; a = {1} for a uniform disk).
struct SunModel {
  std::vector<double> irradiance;
  double angular_radius_rad = 0.5334 / 2 * 3.14159265358979323846 / 180.0;
  std::vector<std::array<double, 6>> limb_coefficients;  // per wavelength; empty = uniform

  // Solid angle of the disk, sr: 2 pi (1 - cos alpha).
  double SolidAngle() const;
  // Radiance (W m^-2 sr^-1 nm^-1) of the disk at angular distance `alpha_rad` from its centre,
  // 0 outside; normalised so that its integral over the disk equals irradiance[wl].
  double Radiance(size_t wl, double alpha_rad) const;
  // Disk-mean / centre radiance ratio for wavelength wl (1 for a uniform disk).
  double MeanOverCentre(size_t wl) const;
};

class AtmosphereModel {
 public:
  double bottom_radius_m = 6371e3;
  double top_radius_m = 6471e3;
  std::vector<double> altitude_m;     // levels, strictly increasing, first 0, last top
  std::vector<double> wavelength_nm;  // the render grid
  std::vector<MediumComponent> components;
  std::vector<double> ground_albedo;  // per wavelength, Lambertian
  SunModel sun;

  size_t levels() const { return altitude_m.size(); }
  size_t wavelengths() const { return wavelength_nm.size(); }

  // Call once after filling the tables: checks sizes and builds the totals used by Lookup.
  void Finalize();

  // Position of an altitude among the levels: interval index and weight of the upper level.
  struct Cell {
    size_t i;
    double t;
  };
  // Inline: a ray march calls it at every point (out of line it was 5-7 % of a LUT render).
  Cell Locate(double z) const {
    const size_t nl = levels();
    if (z <= altitude_m.front()) return {0, 0.0};
    if (z >= altitude_m.back()) return {nl - 2, 1.0};
    if (uniform_step_ > 0.0) {
      const size_t i = std::min(static_cast<size_t>(z / uniform_step_), nl - 2);
      return {i, std::clamp((z - altitude_m[i]) / (altitude_m[i + 1] - altitude_m[i]), 0.0, 1.0)};
    }
    const size_t i = level_locator_.Find(z);
    return {i, (z - altitude_m[i]) / (altitude_m[i + 1] - altitude_m[i])};
  }
  // Total extinction (m^-1) at a located altitude for wavelength wl.
  double Extinction(const Cell& c, size_t wl) const {
    const size_t nw = wavelengths();
    return extinction_[c.i * nw + wl] + (extinction_[(c.i + 1) * nw + wl] - extinction_[c.i * nw + wl]) * c.t;
  }
  // The extinction of wavelengths [w0, w0 + n) at once (each value as Extinction gives it).
  void Extinction(const Cell& c, size_t w0, size_t n, double* out) const {
    const size_t nw = wavelengths();
    const double* a = &extinction_[c.i * nw + w0];
    const double* b = &extinction_[(c.i + 1) * nw + w0];
    for (size_t w = 0; w < n; ++w) out[w] = a[w] + (b[w] - a[w]) * c.t;
  }
  double Scattering(const Cell& c, size_t wl) const;
  double ComponentScattering(size_t component, const Cell& c, size_t wl) const;
  // Largest total extinction over levels [lo, hi] (inclusive) for wavelength wl: a majorant
  // for any altitude between those levels (coefficients are linear between levels).
  double MaxExtinction(size_t lo, size_t hi, size_t wl) const;
  // Optical depth (exact for the piecewise-linear profile) along the vertical from altitude a to
  // b (a < b), for wavelength wl.
  double VerticalOpticalDepth(double a_m, double b_m, size_t wl) const;

 private:
  IntervalLocator level_locator_;    // levels (non-uniform grids)
  double uniform_step_ = 0.0;        // > 0: levels at i * step (the last interval may be shorter)
  std::vector<double> extinction_;  // [level * n_wl + wl]
  std::vector<double> scattering_;  // [level * n_wl + wl]
};

}  // namespace skybake
