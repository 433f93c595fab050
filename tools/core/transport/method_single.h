// The `single` sky method: ray-marched single scattering of the extended, limb-darkened sun plus
// the ground's first reflection (docs/sky-methods.md, "single"), and the pieces it shares with
// `ms-approx` (transport/method_ms_approx.h):
//
//   L_1(x, v) = int_0^l T(x, x_t) S_1(x_t) dt  +  T(x, x_l) (a / pi) E_g(x_l)   [ground end only]
//   S_1(y)    = sum_c sigma_s,c(y) int_disk P_c(v . w) L_sun(w) T_sun(y, w) dw
//   (Bruneton & Neyret 2008, eqs. 1-4; the sun as an extended disk as in transport/single_scattering.h)
//
// The cost of the slow quadrature (single_scattering.h) is the sun transmittance T_sun, a ray to
// the top of the atmosphere per sample, disk point and wavelength. Here:
//
// 1. ExactOpticalDepth. The coefficients are linear in altitude between the model's levels, so
//    along any ray tau(lambda) = sum_l W_l sigma_t(z_l, lambda) with geometric weights W_l (the
//    integrals of the levels' hat functions along the ray), independent of wavelength. The ray is
//    split where it crosses each level's sphere (r(s) = sqrt(p^2 + s^2), s measured from the
//    closest approach, monotone on each side); on each piece W is the integral of a linear
//    function of r(s), by 3-point Gauss-Legendre (r(s) is analytic there: the rule is exact to
//    rounding, ~1e-12 relative). This is the TransmittanceToSpace integral (sky_render.h) done
//    exactly for the piecewise-linear profile, at one geometric pass for all wavelengths.
// 2. TransmittanceTable: tau(r, mu) to the top of the atmosphere per wavelength on Bruneton's
//    parametrisation (Bruneton 2017, functions.glsl GetTransmittanceTextureUvFromRMu: x_r = rho/H,
//    x_mu = (d - d_min)/(d_max - d_min), rho = sqrt(r^2 - R^2), H = sqrt(R_top^2 - R^2), d the
//    distance to the top), nodes at both ends, bilinear interpolation of tau (not of T, so that
//    exp(-tau) keeps its curvature). Rays that hit the ground are not in the table: the caller's
//    geometric test (the sun disk point below the horizon of the sample) gives T = 0, so the
//    Earth's shadow and its penumbra are exact geometry.
// 3. The view-ray march (MarchRay): nodes where the ray crosses a ladder of altitudes
//    (z_{k+1} = z_k + max(dz_min, dz_rel z_k): fine near the ground where the aerosol's 1.2 km
//    scale height lives, coarse above), at most `max_piece_m` apart, plus the points where the
//    ray crosses the shadow boundary of each sun-disk point (the cylinder of radius R behind the
//    planet), so the source is never interpolated across the terminator. Between nodes the source
//    S is linear and the extinction constant (sigma = the piece's optical depth / length, the
//    piece's depth by 2-point Gauss-Legendre, exact for a linear coefficient):
//      int_0^D (S_0 + (S_1 - S_0) t/D) e^{-sigma t} dt
//        = D [S_0 (1 - e^{-x})/x + (S_1 - S_0)(1 - (1 + x) e^{-x})/x^2],   x = sigma D
//    (the "linear-exponential" rule; the trapezoid rule for x -> 0, bounded for optically thick
//    pieces, where a plain quadrature of e^{-tau} fails). The phase function is evaluated once per
//    ray and disk point (the scattering angle is constant along the ray).
// 4. The sun disk: `disk_rings` equal-solid-angle rings x `disk_sectors` points, each carrying
//    the exact limb-darkened radiance integral of its ring per wavelength (so the points' weights
//    sum to E_0(lambda) exactly), or a point sun (disk_rings = 0).
#pragma once

#include <array>
#include <memory>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "atmosphere/model.h"
#include "transport/sky_method.h"

namespace skybake {

// The model's coefficients copied per level ([level * n_wl + wl], m^-1) for fast evaluation,
// with the scattering components (those with a phase function).
struct LevelTables {
  explicit LevelTables(const AtmosphereModel& model);
  const AtmosphereModel& model;
  size_t nl, nw;
  std::vector<double> extinction;
  std::vector<std::vector<double>> scattering;          // per scattering component
  std::vector<const PhaseModel*> phase;                  // per scattering component
  std::vector<double> total_scattering;                  // sum over components
  // Coefficients at altitude z (linear between levels) into out[wl].
  void ExtinctionAt(double z_m, double* out) const;
};

// Optical depth of the model's medium along the ray from radius r0 (m, planet-centred) with
// direction cosine mu (to the local zenith) over [0, length] (m), for every wavelength: adds to
// tau[wl]. Exact for the piecewise-linear profile (see the file comment, 1.). The ray may pass
// below the ground; the caller decides what that means (the ground is not tested here).
void ExactOpticalDepth(const LevelTables& t, double r0, double mu, double length, double* tau);

class TransmittanceTable {
 public:
  // n_mu x n_r nodes (both >= 2), each the exact optical depth to the top of the atmosphere.
  TransmittanceTable(const LevelTables& tables, int n_mu, int n_r);
  // Optical depth to the top from radius r along cosine mu, interpolated, into tau[wl]. The
  // ray must not hit the ground (mu >= HorizonMu(r)); r is clamped to [R, R_top].
  void OpticalDepth(double r, double mu, double* tau) const;
  // Cosine of the horizon (the ray tangent to the ground) at radius r >= R.
  double HorizonMu(double r) const;
  int n_mu() const { return n_mu_; }
  int n_r() const { return n_r_; }

 private:
  const LevelTables& t_;
  int n_mu_, n_r_;
  double R_, R_top_, H_;
  std::vector<double> tau_;  // [(ir * n_mu + imu) * nw + wl]
};

// A quadrature of the sun disk: directions relative to the disk centre and per-wavelength
// weights (W m^-2 nm^-1: the irradiance each point carries; they sum to E_0(lambda)).
struct SunDiskQuadrature {
  SunDiskQuadrature(const SunModel& sun, size_t n_wl, int rings, int sectors);
  struct Point {
    double cos_alpha, alpha, phi;
    std::vector<double> weight;  // per wavelength
  };
  std::vector<Point> points;
  // The world directions of the points for a sun centre direction.
  std::vector<glm::dvec3> Directions(const glm::dvec3& sun) const;
};

struct MarchSettings {
  double dz_min_m = 100.0;      // altitude ladder: smallest step
  double dz_rel = 0.1;          // ... and relative step above dz_min/dz_rel
  double max_piece_m = 20e3;    // longest piece along the ray
  int disk_rings = 1;           // 0: point sun
  int disk_sectors = 4;
  int table_mu = 256;           // transmittance table
  int table_r = 64;
};

// Everything a march needs that does not depend on the view ray: built once per method.
class SingleScatteringModel {
 public:
  SingleScatteringModel(const AtmosphereModel& model, const MarchSettings& settings);
  const AtmosphereModel& model() const { return model_; }
  const LevelTables& tables() const { return tables_; }
  const TransmittanceTable& transmittance() const { return transmittance_; }
  const MarchSettings& settings() const { return settings_; }
  const SunDiskQuadrature& disk() const { return disk_; }

  // An extra source per unit length added at every node (ms-approx's multiple-scattering term):
  // given the node's altitude, cell and the cosine of the sun zenith at the node, adds
  // W m^-2 sr^-1 nm^-1 m^-1 to src[wl]. sigma_s[wl] is the node's total scattering coefficient.
  struct ExtraSource {
    virtual ~ExtraSource() = default;
    virtual void Add(double z_m, double mu_sun, const double* sigma_s, double* src) const = 0;
  };

  // Radiance (W m^-2 sr^-1 nm^-1) at x along unit v for the sun centre along unit `sun` into
  // L[wl] (overwritten): single scattering + the direct sun reflected by the ground, plus the
  // extra source when given. `sun_phase` = false replaces the phase functions by the isotropic
  // 1/(4 pi) (the multiple-scattering LUT's transfer, Hillaire 2020 eq. 5); `unit_sun` = true sets
  // E_0 = 1 at every wavelength (a transfer function). Also returns, when f_ms != nullptr, the
  // integral int T(x, x_t) sigma_s(x_t) dt per wavelength (Hillaire 2020 eq. 7 before the
  // average over directions). Thread-safe.
  struct RayOptions {
    bool sun_phase = true;
    bool unit_sun = false;
    bool ground = true;
    bool point_sun = false;           // override the disk
    const ExtraSource* extra = nullptr;
    // Overrides of the settings for this ray (<= 0: the settings').
    double dz_min_m = 0.0, dz_rel = 0.0, max_piece_m = 0.0;
  };
  void MarchRay(const glm::dvec3& x, const glm::dvec3& v, const glm::dvec3& sun, const RayOptions& options,
                double* L, double* f_ms = nullptr) const;

  // The nodes of a ray (for tests): distances from x.
  std::vector<double> Nodes(const glm::dvec3& x, const glm::dvec3& v, const std::vector<glm::dvec3>& sun_dirs,
                            double length, const RayOptions& options) const;

 private:
  const AtmosphereModel& model_;
  MarchSettings settings_;
  LevelTables tables_;
  TransmittanceTable transmittance_;
  SunDiskQuadrature disk_;
  std::vector<double> ladder_;  // altitude ladder (m)
};

// The `single` method (sky_method.h): the low / medium / high presets of MarchSettings
// (docs/sky-methods.md lists them and their measured errors).
std::unique_ptr<SkyMethod> MakeSingleMethod(const AtmosphereModel& model, const SkyMethodOptions& options);

// The presets, indexed by quality, and their YAML for provenance.
const QualityTable<MarchSettings>& SingleMarchPresets();
MarchSettings SingleMarchSettings(Quality quality);
std::string DescribeMarchSettings(const MarchSettings& settings);

// The geometry of a ray inside the atmosphere: distance to the ground (infinity if it misses)
// and to the top of the atmosphere (0 if outside and missing).
struct RayExtent {
  double ground = 0.0, top = 0.0;
  bool hits_ground = false;
  double length() const { return hits_ground ? ground : top; }
};
RayExtent ExtentOf(const AtmosphereModel& model, const glm::dvec3& x, const glm::dvec3& v);

}  // namespace skybake
