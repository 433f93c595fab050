// The deterministic sky methods of sky-render part 2 behind one interface, so that they render
// the same products as the path tracer and can be compared with it (docs/sky-methods.md):
//   single     ray-marched single scattering (+ the ground's first reflection)
//   orders     successive orders of scattering on precomputed tables (Bruneton & Neyret 2008)
//   ms-approx  single scattering + Hillaire (2020)'s multiple-scattering approximation
//   analytic   the Cloud Party approximation (constant-density single scattering)
// A method is built once per atmosphere (it may precompute tables) and then evaluated for any
// observer altitude, sun zenith and list of view directions.
#pragma once

#include <array>
#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "atmosphere/model.h"
#include "io/progress.h"
#include "transport/quality.h"
#include "transport/view_segment.h"

namespace skybake {

// Knobs common to the methods; each method documents which it reads. `quality` selects a
// preset (each method's preset table) that the explicit numbers override when > 0.
struct SkyMethodOptions {
  Quality quality = Quality::kMedium;
  int view_steps = 0;        // quadrature points along a view ray
  int orders = 0;            // highest scattering order (orders: stop earlier if converged)
  double order_tolerance = 0.0;  // orders: stop when an order adds less than this fraction
  // Expert overrides by key, read by the methods whose registry row lists the key (orders: its
  // OrdersOverrides, docs/sky-methods.md "Expert overrides"); any other key is a UsageError.
  std::map<std::string, int> table_size;
  // Observer altitude the tables are built for (orders puts a radius node there; other
  // altitudes are interpolated between nodes).
  double observer_altitude_m = 0.0;
  // > 1: the method runs on every k-th wavelength of the grid (and the last) and the transfer is
  // interpolated to the grid (transport/spectral_stride.h); 1: every wavelength.
  int spectral_stride = 1;
  // SegmentRadiance will be asked (fog). orders then keeps its accumulated sources J_ms at every
  // table node (one table of the solve's size, 156 MB for high under cloudy4 on 21 wavelengths);
  // without it SegmentRadiance throws UsageError and the sky's bytes are the same.
  bool segments = false;
};

class SkyMethod {
 public:
  virtual ~SkyMethod() = default;
  virtual std::string Name() const = 0;
  // The resolved settings, for provenance (YAML text).
  virtual std::string Describe() const = 0;
  // Spectral radiance (W m^-2 sr^-1 nm^-1) at the model's grid wavelengths seen from
  // `observer_altitude_m` along unit directions `dirs` (local frame: +z zenith, the sun in the
  // x-z plane at zenith angle `sun_zenith_rad`, x > 0): out[d * n_wl + wl]. The sun disk itself
  // is excluded, as in the path tracer. Const and thread-safe.
  virtual void Radiance(double observer_altitude_m, double sun_zenith_rad,
                        const std::vector<std::array<double, 3>>& dirs, std::vector<double>* out) const = 0;
  // In-scattered spectral radiance from a view segment only (transport/view_segment.h: the
  // medium at t <= t_end, no ground surface), same layout as Radiance. Methods that cannot
  // cut the view ray throw UsageError (the default).
  virtual bool SupportsSegments() const { return false; }
  // The single-scattering part of Radiance (order 1: the sun scattered once along the view ray,
  // and the ground's reflection of the direct sun), same layout; false (out untouched) where the
  // method does not separate it.
  virtual bool SingleScatteringRadiance(double observer_altitude_m, double sun_zenith_rad,
                                        const std::vector<std::array<double, 3>>& dirs, std::vector<double>* out) const {
    (void)observer_altitude_m, (void)sun_zenith_rad, (void)dirs, (void)out;
    return false;
  }
  virtual void SegmentRadiance(double observer_altitude_m, double sun_zenith_rad,
                               const std::vector<std::array<double, 3>>& dirs, const ViewSegment& segment,
                               std::vector<double>* out) const;
};

// The registry of the deterministic methods (sky_method.cpp): one row per method, in the order
// of --help. The CLI (--method), the generator's stages (luts.method, fog.method) and the budget
// take their names from it.
struct SkyMethodEntry {
  const char* name;
  // Renders view segments (SupportsSegments: fog).
  bool segments;
  // The expert override keys of SkyMethodOptions::table_size it reads (none: an empty list).
  const std::vector<std::string>& (*override_keys)();
  std::unique_ptr<SkyMethod> (*make)(const AtmosphereModel& model, const SkyMethodOptions& options,
                                     const ProgressFn& progress);
};
const std::vector<SkyMethodEntry>& SkyMethodRegistry();
// The row of a name; nullptr for an unknown one.
const SkyMethodEntry* FindSkyMethod(std::string_view name);

// Builds a method by name (a registry row); UsageError for an unknown name or a table_size key
// the method does not read. May precompute (progress reported).
std::unique_ptr<SkyMethod> MakeSkyMethod(const std::string& name, const AtmosphereModel& model,
                                         const SkyMethodOptions& options, const ProgressFn& progress);

// The registry's names ("single", "orders", "ms-approx", "analytic"), and those of the methods
// that render view segments ("orders").
std::vector<std::string> SkyMethodNames();
std::vector<std::string> SegmentMethodNames();

// UsageError "<method>: unknown expert override '<key>' (known: a, b, ...)" for the first key of
// `given` not in `known`, or "<method> reads no expert overrides, got '<key>'" when `known` is
// empty.
void CheckOverrideKeys(const std::string& method, const std::map<std::string, int>& given,
                       const std::vector<std::string>& known);

}  // namespace skybake
