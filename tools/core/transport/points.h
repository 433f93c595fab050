// sky-render points: every sky method evaluated at explicit geometries (docs/sky-render.md,
// "points"): a CSV of (sun zenith, view zenith, relative azimuth[, observer altitude]) in, the
// spectral radiance at chosen grid wavelengths, the same per unit extraterrestrial irradiance,
// its single-scattering part, the direct sun's transmittance and the luminance Y out.
//
//  - path: the Monte-Carlo reference. Each row has its own estimators, all from paths of the
//    row's random streams (keyed by the geometry's numbers, not the row's position, so two files
//    that share a geometry and a seed give that row the same numbers and rows of different
//    geometries are independent): the output wavelengths carried together by every path with
//    one-sample MIS over them (PathTracerSettings::wavelength_mis), their order-1 part from the
//    same paths, and Y from the colour estimator (hero wavelength over the whole grid, also with
//    MIS over its 4 wavelengths). The stopping rule covers every radiance column and Y: paths
//    are added in rounds (64, then doubling) until each standard error is below target x value
//    (or its absolute floor), at least --min-paths, at most --max-paths; or a fixed --paths.
//    Rounds are split into blocks of 64 paths, run in parallel and merged in block order
//    (Chan, Golub & LeVeque 1979's pairwise update), so the bytes do not depend on --threads.
//  - single, orders, ms-approx, analytic: the method's own view ray at the row's exact
//    direction (no texture in between). A method is built once per distinct observer altitude
//    (orders: its tables cover every sun angle and put a radius node at the observer), and
//    evaluated for the rows of that altitude in parallel.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "io/csv.h"
#include "io/progress.h"
#include "transport/sky_method.h"
#include "transport/sky_scene.h"

namespace skybake {

struct PointsOptions {
  std::string geometry;
  std::vector<double> wavelengths_nm;
  std::string method = "path";
  SkyMethodOptions method_options;  // deterministic methods
  uint64_t paths = 0;               // path: > 0 a fixed number per row (min = max); 0 adaptive
};

struct PointGeometry {
  double sun_zenith_deg = 0.0;
  double view_zenith_deg = 0.0;
  double relative_azimuth_deg = 0.0;  // 0 looks towards the sun's azimuth
  double observer_altitude_m = 0.0;
};

struct PointsInput {
  std::vector<PointGeometry> rows;
  std::string altitude_column;  // the CSV's observer altitude column ("" = none: the atmosphere's)
  std::vector<size_t> wavelengths;  // grid indices of --wavelengths-out
};

// Validates the geometry CSV's rows (sun and view zenith in 0-180 deg, relative azimuth in
// -360-360 deg, the observer altitude column, if any, in [0, top_m)); rows without an altitude
// column get `default_altitude_m`. InputError file:line for a bad row; `wavelengths` stays empty.
PointsInput ParsePointGeometries(const CsvTable& csv, double default_altitude_m, double top_m);

// Reads and validates the geometry CSV and the output wavelengths (InputError file:line for a
// bad row, UsageError for a wavelength off the grid), before any work.
PointsInput LoadPointsInput(const Scene& scene, const PointsOptions& options);

struct PointResult {
  // Per output wavelength (W m^-2 sr^-1 nm^-1; standard errors 0 for deterministic methods).
  std::vector<double> radiance, radiance_stderr;
  std::vector<double> single, single_stderr;  // the order-1 part (where the method has it)
  std::vector<double> sun_transmittance;      // observer to space towards the sun's centre
  double y_cd_m2 = 0.0, y_stderr_cd_m2 = 0.0;
  uint64_t paths = 0;
};

struct PointsResult {
  std::vector<PointResult> rows;
  bool has_single = false;
  size_t methods_built = 0;  // deterministic methods: one per distinct observer altitude
  std::string description;   // the method's resolved settings (the first one built)
};

PointsResult EvaluatePoints(const Scene& scene, const PointsOptions& options, const PointsInput& input,
                            const ProgressFn& progress);

// The random stream key of a geometry (SplitMix64 over the bit patterns of its four numbers).
uint64_t PointStreamKey(const PointGeometry& g);

// Spectral-radiance floor of the path's stopping rule: the Y floor (PathTracerSettings::
// absolute_error_floor, cd/m^2) of a flat spectrum, floor / (683 lm/W x 106.857 nm), where
// 106.857 nm is the integral of the CIE 1931 ybar (CIE 015:2004 table T.4, 1 nm sum).
double SpectralErrorFloor(double y_floor_cd_m2);

std::string PointsCsv(const Scene& scene, const PointsOptions& options, const PointsInput& input,
                      const PointsResult& result);
void WritePoints(const Scene& scene, const PointsOptions& options, const std::filesystem::path& path,
                 const ProgressFn& progress);

}  // namespace skybake
