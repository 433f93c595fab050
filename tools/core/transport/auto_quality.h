// Automatic quality (`quality: auto` in pipeline.yaml, `sky-render choose`; docs/sky-methods.md
// "Automatic quality"): the cheapest settings of a deterministic method whose sky stays within a
// tolerance of the method's full model, for one atmosphere.
//
// Candidates are the method's quality presets (its table sizes) x spectral strides (1, 2, 4); the
// full model is the highest preset at stride 1. Every candidate and the full model are evaluated
// the way `sky-render budget` evaluates a simplification (transport/budget.h): the method built for
// the atmosphere at the observer's altitude, its sky on the 91 directions of transport/sky_error.h
// at daylight and twilight sun angles, the relative luminance error outside a 1 deg aureole.
// A candidate is within when, against the full model,
//   daylight (every sun zenith < 90 deg):  RMS <= tolerance_rms and max <= tolerance_max,
//   twilight (every sun zenith >= 90 deg): RMS <= twilight_tolerance_rms.
// The candidates are tried in the order of a fixed cost model (CandidateCost below: the preset's
// measured relative build cost x the wavelengths it runs on), not of measured times, so that the
// choice is the same bytes on every machine and at any thread count; the first within is chosen.
// A candidate no finer than a rejected one in both preset and stride is rejected without being
// built (kDominated: the error does not fall when both are coarsened); the full model is the
// fallback and has no error by definition.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "io/progress.h"
#include "transport/quality.h"
#include "transport/sky_scene.h"

namespace skybake {

struct AutoQualityOptions {
  std::string method = "orders";
  double tolerance_rms = 0.005;           // daylight RMS (relative; issue 5's 0.5 %)
  double tolerance_max = 0.02;            // daylight max (relative; issue 5's 2 %)
  double twilight_tolerance_rms = 0.03;   // twilight RMS (relative; docs/sky-methods.md's 3 % target)
  std::vector<double> daylight_sun_zenith_deg = {30, 60, 80, 88};
  std::vector<double> twilight_sun_zenith_deg = {92, 96, 100};  // to GT7's lowest slice, -10 deg
  std::vector<int> strides = {1, 2, 4};
};

struct AutoQualityCandidate {
  Quality quality = Quality::kHigh;
  int stride = 1;
  size_t wavelengths = 0;       // the method runs on (transport/spectral_stride.h)
  double cost = 0.0;            // CandidateCost, relative to the full model
  enum class Status { kChosen, kRejected, kDominated, kNotTried } status = Status::kNotTried;
  double daylight_rms = 0.0, daylight_max = 0.0, twilight_rms = 0.0;  // relative, worst over the sun angles
  double seconds = 0.0;         // measured build + render (not written to the settings file)
  // Built and compared with the full model (the errors above are measured).
  bool evaluated() const { return status == Status::kChosen || status == Status::kRejected; }
};

struct AutoQualityChoice {
  std::string method;
  AutoQualityOptions options;
  size_t grid_wavelengths = 0;
  std::vector<AutoQualityCandidate> candidates;  // in cost order; exactly one kChosen
  double full_seconds = 0.0;                      // the full model's build + render (measured)
  std::vector<std::filesystem::path> files_read;  // of the scene (for depfiles)
  const AutoQualityCandidate& chosen() const;  // its quality and stride are the choice
};

// The fixed cost model: preset build cost (relative to the highest preset, measured once and
// documented in docs/sky-methods.md "Automatic quality") x wavelengths run / grid wavelengths.
double CandidateCost(Quality quality, size_t wavelengths_run, size_t grid_wavelengths);

// Throws UsageError for bad options (unknown or non-preset method, tolerances <= 0, no sun angle
// or one on the wrong side of 90 deg, strides < 1) and what LoadScene throws.
AutoQualityChoice ChooseQuality(const SceneOptions& scene, const AutoQualityOptions& options, const ProgressFn& progress);

// The settings file `sky-render choose` writes (YAML; deterministic: no timings) and the table it
// prints (with the timings).
std::string AutoQualityYaml(const AutoQualityChoice& choice);
std::string AutoQualityTable(const AutoQualityChoice& choice);

// What `sky-render render --settings FILE` reads back: the method, preset and stride, and the
// chosen candidate's block of the file (for the render's provenance and lut-pack's report).
struct AutoQualitySettings {
  std::string method;
  Quality quality = Quality::kHigh;
  int stride = 1;
  std::string provenance;  // "quality_choice: {...}" YAML, one line
};
// Throws InputError (file:line) for a missing, malformed or inconsistent file.
AutoQualitySettings ReadAutoQualitySettings(const std::filesystem::path& path);

}  // namespace skybake
