#include "transport/auto_quality.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include <fmt/format.h>

#include "color/color.h"
#include "io/error.h"
#include "io/text_list.h"
#include "io/yaml.h"
#include "transport/budget.h"
#include "transport/sky_error.h"
#include "transport/sky_method.h"
#include "transport/spectral_stride.h"

namespace skybake {

namespace {

constexpr double kDeg = std::numbers::pi / 180.0;
using Sky = ChartSky;  // observer XYZ per direction

// The build + render time of `orders` per preset relative to `high`, at one stride (the time is
// linear in the wavelength count, transport/spectral_stride.h). Measured with `sky-render choose`
// on clear and cloudy3 (docs/sky-methods.md "Automatic quality", the table's seconds column): low
// 0.03 (stride 1 against the full model), medium 0.16-0.19 (stride 4 against high at stride 4).
constexpr std::array<double, kQualityCount> kPresetCost = {0.035, 0.19, 1.0};

const char* StatusName(AutoQualityCandidate::Status s) {
  switch (s) {
    case AutoQualityCandidate::Status::kChosen: return "chosen";
    case AutoQualityCandidate::Status::kRejected: return "rejected";
    case AutoQualityCandidate::Status::kDominated: return "dominated";
    case AutoQualityCandidate::Status::kNotTried: return "not-tried";
  }
  return "?";
}

// The method's skies at every sun angle at the observer's altitude (RenderChartSkies, budget.h);
// returns the build + render seconds.
double RenderSkies(const Scene& sc, const std::string& name, Quality q, int stride, const SkyDirections& D,
                   const std::vector<double>& sun_zenith_deg, std::vector<Sky>* out) {
  SkyMethodOptions mo;
  mo.quality = q;
  mo.spectral_stride = stride;
  mo.observer_altitude_m = sc.spec.observer_altitude_m;
  std::vector<std::vector<ChartSky>> skies;
  const double seconds = RenderChartSkies(sc, name, mo, {sc.spec.observer_altitude_m}, sun_zenith_deg, D, &skies);
  *out = std::move(skies[0]);
  return seconds;
}

std::string Percent(double v) { return fmt::format("{:.4g} %", 100.0 * v); }

}  // namespace

const AutoQualityCandidate& AutoQualityChoice::chosen() const {
  for (const AutoQualityCandidate& c : candidates) {
    if (c.status == AutoQualityCandidate::Status::kChosen) return c;
  }
  throw std::logic_error("AutoQualityChoice without a chosen candidate");
}

double CandidateCost(Quality quality, size_t wavelengths_run, size_t grid_wavelengths) {
  return kPresetCost[static_cast<size_t>(quality)] * static_cast<double>(wavelengths_run) /
         static_cast<double>(std::max<size_t>(grid_wavelengths, 1));
}

AutoQualityChoice ChooseQuality(const SceneOptions& so, const AutoQualityOptions& o, const ProgressFn& progress) {
  if (!FindSkyMethod(o.method)) {
    throw UsageError("--method: automatic quality needs a deterministic method (" + TextList(SkyMethodNames(), ", ") +
                     "), got '" + o.method + "'");
  }
  for (const auto& [v, what] : {std::pair{o.tolerance_rms, "--tolerance"}, std::pair{o.tolerance_max, "--max-tolerance"},
                                std::pair{o.twilight_tolerance_rms, "--twilight-tolerance"}}) {
    if (!(v > 0.0) || !std::isfinite(v)) throw UsageError(fmt::format("{}: must be a positive number, got {}", what, v));
  }
  if (o.daylight_sun_zenith_deg.empty()) throw UsageError("automatic quality: at least one daylight sun angle");
  for (double z : o.daylight_sun_zenith_deg) {
    if (!(z >= 0.0 && z < 90.0)) throw UsageError(fmt::format("automatic quality: daylight sun zenith {} deg is outside [0, 90)", z));
  }
  for (double z : o.twilight_sun_zenith_deg) {
    if (!(z >= 90.0 && z <= 180.0)) throw UsageError(fmt::format("automatic quality: twilight sun zenith {} deg is outside [90, 180]", z));
  }
  if (o.strides.empty()) throw UsageError("automatic quality: at least one spectral stride");
  for (int s : o.strides) {
    if (s < 1 || s > 64) throw UsageError(fmt::format("automatic quality: spectral stride {} is outside 1-64", s));
  }

  ReportProgress(progress, "choose: atmosphere", 0.0);
  const Scene sc = LoadScene(so, {});
  const SkyDirections D = ChartDirections();
  const ColorConfig config = ColorConfig::Load(sc.ocio_config);
  const ColorProcessor to2020 = config.Converter(XyzColorSpace(sc.observer), ocio_names::kLinearRec2020);
  const ColorProcessor toref = config.Converter(XyzColorSpace(sc.observer), ocio_names::kCieXyzD65);
  std::vector<double> suns = o.daylight_sun_zenith_deg;
  suns.insert(suns.end(), o.twilight_sun_zenith_deg.begin(), o.twilight_sun_zenith_deg.end());

  AutoQualityChoice ch;
  ch.method = o.method;
  ch.options = o;
  ch.grid_wavelengths = sc.grid.size();
  ch.files_read = sc.files_read;
  const Quality full_q = Quality::kHigh;
  const int full_stride = 1;

  // The candidates in cost order (ties: the finer preset, then the finer stride, first).
  for (int qi = 0; qi < kQualityCount; ++qi) {
    std::vector<int> strides = o.strides;
    std::sort(strides.begin(), strides.end());
    strides.erase(std::unique(strides.begin(), strides.end()), strides.end());
    for (int s : strides) {
      const Quality q = static_cast<Quality>(qi);
      if (q == full_q && s == full_stride) continue;
      AutoQualityCandidate c;
      c.quality = q;
      c.stride = s;
      c.wavelengths = sc.grid.size() > 2 ? StrideIndices(sc.grid.size(), s).size() : sc.grid.size();
      if (c.wavelengths == sc.grid.size() && s != 1) continue;  // the same model as stride 1
      c.cost = CandidateCost(q, c.wavelengths, sc.grid.size());
      ch.candidates.push_back(c);
    }
  }
  std::stable_sort(ch.candidates.begin(), ch.candidates.end(), [](const AutoQualityCandidate& a, const AutoQualityCandidate& b) {
    if (a.cost != b.cost) return a.cost < b.cost;
    if (a.quality != b.quality) return a.quality > b.quality;
    return a.stride < b.stride;
  });

  const size_t steps = ch.candidates.size() + 1;
  ReportProgress(progress, "choose: the full model", 0.0);
  std::vector<Sky> full;
  ch.full_seconds = RenderSkies(sc, o.method, full_q, full_stride, D, suns, &full);

  bool chosen = false;
  for (size_t k = 0; k < ch.candidates.size(); ++k) {
    AutoQualityCandidate& c = ch.candidates[k];
    if (chosen) break;  // the rest stay kNotTried
    const bool dominated = std::any_of(ch.candidates.begin(), ch.candidates.begin() + k, [&](const AutoQualityCandidate& r) {
      return (r.status == AutoQualityCandidate::Status::kRejected || r.status == AutoQualityCandidate::Status::kDominated) &&
             c.quality <= r.quality && c.stride >= r.stride;
    });
    if (dominated) {
      c.status = AutoQualityCandidate::Status::kDominated;
      continue;
    }
    ReportProgress(progress, fmt::format("choose: {} stride {}", QualityName(c.quality), c.stride),
                   static_cast<double>(k + 1) / steps);
    std::vector<Sky> test;
    c.seconds = RenderSkies(sc, o.method, c.quality, c.stride, D, suns, &test);
    for (size_t s = 0; s < suns.size(); ++s) {
      const SkyCompareInput in{&D, suns[s] * kDeg, 1.0, &full[s], nullptr, &test[s], &to2020, &toref};
      const SkyError e = CompareSkies(in);
      if (suns[s] < 90.0) {
        c.daylight_rms = std::max(c.daylight_rms, e.rms);
        c.daylight_max = std::max(c.daylight_max, e.max);
      } else {
        c.twilight_rms = std::max(c.twilight_rms, e.rms);
      }
    }
    const bool within = c.daylight_rms <= o.tolerance_rms && c.daylight_max <= o.tolerance_max &&
                        c.twilight_rms <= o.twilight_tolerance_rms;
    c.status = within ? AutoQualityCandidate::Status::kChosen : AutoQualityCandidate::Status::kRejected;
    chosen = within;
  }
  if (!chosen) {
    AutoQualityCandidate c;
    c.quality = full_q;
    c.stride = full_stride;
    c.wavelengths = sc.grid.size();
    c.cost = CandidateCost(full_q, c.wavelengths, sc.grid.size());
    c.status = AutoQualityCandidate::Status::kChosen;
    c.seconds = ch.full_seconds;
    ch.candidates.push_back(c);
  }
  ReportProgress(progress, "choose", 1.0);
  return ch;
}

std::string AutoQualityYaml(const AutoQualityChoice& ch) {
  const AutoQualityOptions& o = ch.options;
  auto list = [](const std::vector<double>& v) {
    std::string s;
    for (double x : v) s += (s.empty() ? "" : ", ") + FormatExact(x);
    return "[" + s + "]";
  };
  const AutoQualityCandidate& c = ch.chosen();
  std::string out =
      "# sky-render choose: the cheapest settings of the method whose sky stays within the tolerances of its full\n"
      "# model (docs/sky-methods.md \"Automatic quality\"); errors are relative luminance outside a 1 deg aureole on\n"
      "# the 91 directions of the sky chart, the worst over the sun angles.\n";
  out += fmt::format("method: {}\nquality: {}\nspectral_stride: {}\n", ch.method, QualityName(c.quality), c.stride);
  out += fmt::format("full_model: {{quality: high, spectral_stride: 1, wavelengths: {}}}\n", ch.grid_wavelengths);
  out += fmt::format("tolerance: {{daylight_rms: {}, daylight_max: {}, twilight_rms: {}}}\n", FormatExact(o.tolerance_rms),
                     FormatExact(o.tolerance_max), FormatExact(o.twilight_tolerance_rms));
  out += fmt::format("sun_zenith_deg: {{daylight: {}, twilight: {}}}\n", list(o.daylight_sun_zenith_deg), list(o.twilight_sun_zenith_deg));
  auto errors = [](const AutoQualityCandidate& k) {
    return fmt::format("daylight_rms: {:.4g}, daylight_max: {:.4g}, twilight_rms: {:.4g}", k.daylight_rms, k.daylight_max,
                       k.twilight_rms);
  };
  out += fmt::format("chosen: {{quality: {}, spectral_stride: {}, wavelengths: {}, {}}}\n", QualityName(c.quality), c.stride,
                     c.wavelengths, errors(c));
  out += "candidates:  # in the order tried (a fixed cost model, relative to the full model)\n";
  for (const AutoQualityCandidate& k : ch.candidates) {
    out += fmt::format("  - {{quality: {}, spectral_stride: {}, wavelengths: {}, cost: {:.4g}, status: {}{}}}\n", QualityName(k.quality),
                       k.stride, k.wavelengths, k.cost, StatusName(k.status), k.evaluated() ? ", " + errors(k) : "");
  }
  return out;
}

std::string AutoQualityTable(const AutoQualityChoice& ch) {
  const AutoQualityOptions& o = ch.options;
  std::string out = fmt::format(
      "{}: chosen {} at spectral stride {} (tolerances: daylight RMS {}, max {}; twilight RMS {}); full model (high, stride 1, {} "
      "wavelengths): {:.2f} s\n",
      ch.method, QualityName(ch.chosen().quality), ch.chosen().stride, Percent(o.tolerance_rms), Percent(o.tolerance_max),
      Percent(o.twilight_tolerance_rms), ch.grid_wavelengths, ch.full_seconds);
  out += fmt::format("{:<8} {:>6} {:>4} {:>7} {:>10} {:>10} {:>10} {:>8}  {}\n", "quality", "stride", "wl", "cost", "day rms %",
                     "day max %", "twi rms %", "seconds", "status");
  for (const AutoQualityCandidate& k : ch.candidates) {
    const auto pct = [&](double v) { return k.evaluated() ? fmt::format("{:.3f}", 100.0 * v) : std::string("-"); };
    out += fmt::format("{:<8} {:>6} {:>4} {:>7.3f} {:>10} {:>10} {:>10} {:>8}  {}\n", QualityName(k.quality), k.stride, k.wavelengths,
                       k.cost, pct(k.daylight_rms), pct(k.daylight_max), pct(k.twilight_rms),
                       k.seconds > 0 ? fmt::format("{:.2f}", k.seconds) : "-", StatusName(k.status));
  }
  return out;
}

AutoQualitySettings ReadAutoQualitySettings(const std::filesystem::path& path) {
  const YamlDocument doc = YamlDocument::Load(path);
  YamlMap root = doc.RootMap();
  AutoQualitySettings s;
  s.method = root.String("method", "a sky method name");
  if (!s.method.empty() && !FindSkyMethod(s.method)) {
    root.Get("method")->Error("'" + s.method + "' is not a deterministic sky method (" + TextList(SkyMethodNames(), ", ") + ")");
  }
  const std::string q = root.Choice("quality", QualityNames());
  s.quality = FindQuality(q).value_or(Quality::kHigh);
  s.stride = static_cast<int>(root.Integer("spectral_stride", 1, 64, "a spectral stride"));
  const NumberSpec fraction = NumberSpec::NonNegative("(relative)");
  std::string tolerance, measured;
  if (std::optional<YamlMap> t = root.OptionalMap("tolerance")) {
    const double a = t->Number("daylight_rms", NumberSpec::Positive("(relative)"));
    const double b = t->Number("daylight_max", NumberSpec::Positive("(relative)"));
    const double c = t->Number("twilight_rms", NumberSpec::Positive("(relative)"));
    t->Finish();
    tolerance = fmt::format("tolerance: {{daylight_rms: {}, daylight_max: {}, twilight_rms: {}}}", FormatExact(a), FormatExact(b),
                            FormatExact(c));
  } else {
    root.ErrorMissing("tolerance", "a mapping of daylight_rms, daylight_max and twilight_rms");
  }
  if (std::optional<YamlMap> c = root.OptionalMap("chosen")) {
    const std::string cq = c->Choice("quality", QualityNames());
    const int64_t cs = c->Integer("spectral_stride", 1, 64, "a spectral stride");
    c->Integer("wavelengths", 1, 100000, "a wavelength count");
    const double a = c->Number("daylight_rms", fraction);
    const double b = c->Number("daylight_max", fraction);
    const double d = c->Number("twilight_rms", fraction);
    if (!cq.empty() && !q.empty() && (cq != q || cs != s.stride)) {
      c->node().Error(fmt::format("the chosen candidate ({} stride {}) is not the file's quality and spectral_stride ({} stride {})",
                                  cq, cs, q, s.stride));
    }
    c->Finish();
    measured = fmt::format("measured: {{daylight_rms: {:.4g}, daylight_max: {:.4g}, twilight_rms: {:.4g}}}", a, b, d);
  } else {
    root.ErrorMissing("chosen", "the chosen candidate");
  }
  root.Known({"full_model", "sun_zenith_deg", "candidates"});
  root.Finish();
  doc.ThrowIfErrors();
  s.provenance = fmt::format("quality_choice: {{file: {}, quality: {}, spectral_stride: {}, {}, {}}}", path.filename().string(), q,
                             s.stride, tolerance, measured);
  return s;
}

}  // namespace skybake
