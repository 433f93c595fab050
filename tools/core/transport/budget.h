// The model budget (`sky-render budget`, docs/sky-methods.md "The model budget"): for one scene,
// which simplifications of the atmosphere model stay under a tolerance, what each costs in
// accuracy and saves in work, and which dimensions of a sky LUT can be dropped.
//
// Every item is rendered with one deterministic evaluator (default ms-approx at medium quality:
// it has multiple scattering and builds in ~1 s; any registered method can be chosen, e.g.
// `orders`) on the 91 sky directions of transport/sky_error.h at each requested sun angle, and
// compared with the full model rendered by the same evaluator, so the evaluator's own error
// cancels to first order and the difference is the simplification's. The error of an item is the
// worst over the sun angles of the sky RMS (or max, `criterion`) relative luminance error outside
// a 1 deg aureole; the colour errors are reported beside it.
//
// Simplifications: the RGB grid (680/550/440 nm); coarser spectral grids (10 and 20 nm); each
// fitted aerosol phase (HG, HG with the Mie asymmetry, Cornette-Shanks, dual-lobe HG) instead of
// the tabulated Mie phase; exponential profiles (atmosphere/simplify.h); no ozone; the orders
// capped at 1-4 (the evaluator's `orders` option: ms-approx truncates its geometric series).
// LUT dimensions (can the table omit it?):
//   altitude   the sky at the ends of the observer's altitude range against the sky at its middle
//              (one altitude for the whole range; GT7 drops altitude because its tracks vary by
//              only ~300 m: the default range is the atmosphere's observer altitude + 0..300 m);
//   azimuth    the sky against its azimuthal mean on each zenith row (a 3D LUT without the
//              sun-relative azimuth, Elek 2009's simplification);
//   sun zenith the skies at the requested sun angles against the middle one (a fixed sun).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "io/progress.h"
#include "transport/quality.h"
#include "transport/sky_error.h"
#include "transport/sky_scene.h"

namespace skybake {

struct BudgetOptions {
  std::string method = "ms-approx";
  Quality quality = Quality::kMedium;
  double tolerance = 0.01;                  // relative
  std::string criterion = "rms";            // rms | max
  std::vector<double> sun_zenith_deg = {30, 70, 85, 90, 94};
  double altitude_lo_m = -1.0, altitude_hi_m = -1.0;  // < 0: observer altitude + 0..300 m
};

struct BudgetItem {
  std::string kind;       // "simplification" | "lut-dimension"
  std::string name;       // e.g. "rgb", "phase-hg", "altitude"
  std::string setting;    // what it means, e.g. "680/550/440 nm", "0-300 m"
  SkyError worst;         // worst over the sun angles (each field its own worst)
  double worst_sun_zenith_deg = 0.0;  // where the criterion's worst was
  std::vector<std::pair<double, double>> by_sun;  // (sun zenith deg, the criterion's error) per angle
  size_t wavelengths = 0; // of the evaluated model
  double seconds = 0.0;   // build + render (measured; not written to files)
  bool within = false;
};

struct BudgetReport {
  std::string evaluator;          // the method's Describe()
  size_t baseline_wavelengths = 0;
  double baseline_seconds = 0.0;
  double tolerance = 0.0;
  std::string criterion;
  std::vector<BudgetItem> items;
  std::vector<std::filesystem::path> files_read;  // of the baseline scene (for depfiles)
};

// The skies of a deterministic method, built once from `options`, on the directions D at every
// altitude x sun zenith: observer XYZ per direction, (*out)[altitude][sun]. Returns the build +
// render seconds; `description` gets the method's Describe(). The budget's and the automatic
// quality's evaluator (transport/auto_quality.h).
using ChartSky = std::vector<std::array<double, 3>>;
double RenderChartSkies(const Scene& scene, const std::string& method, const SkyMethodOptions& options,
                        const std::vector<double>& altitudes_m, const std::vector<double>& sun_zenith_deg, const SkyDirections& D,
                        std::vector<std::vector<ChartSky>>* out, std::string* description = nullptr);

// Throws UsageError for bad options (unknown method/criterion, tolerance <= 0, an empty or
// out-of-range altitude range) and what LoadScene throws.
BudgetReport RunBudget(const SceneOptions& scene, const BudgetOptions& options, const ProgressFn& progress);

// The report as CSV (deterministic: no timings) and as a text table with the timings.
std::string BudgetCsv(const BudgetReport& report);
std::string BudgetTable(const BudgetReport& report);

// "1%", "0.5 %" or "0.01" -> 0.01; UsageError "<option>: ..." otherwise.
double ParseTolerance(const std::string& text, const std::string& option = "--tolerance");

}  // namespace skybake
