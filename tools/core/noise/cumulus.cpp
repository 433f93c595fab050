#include "noise/cumulus.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "noise/hash.h"
#include "noise/lattice.h"

namespace skybake::noise {

// ---------------------------------------------------------------------------- mapping

CumulusMapping::CumulusMapping(int resolution, double half_extent_m, double edge_to_centre_ratio)
    : n_(resolution), r_m_(half_extent_m), a_(std::acosh(edge_to_centre_ratio)), sinh_a_(std::sinh(a_)) {
  SKYBAKE_CHECK_GE(resolution, 1);
  SKYBAKE_CHECK_GT(half_extent_m, 0.0);
  SKYBAKE_CHECK_GE(edge_to_centre_ratio, 1.0);
}

// Below a = 1e-6 the sinh map equals the uniform map x = R u to ~a^2/6 < 1e-12 relative, and
// sinh(a u)/sinh(a) would lose digits: use the limit.
double CumulusMapping::WorldFromU(double u) const {
  return a_ < 1e-6 ? r_m_ * u : r_m_ * std::sinh(a_ * u) / sinh_a_;
}

double CumulusMapping::UFromWorld(double x_m) const {
  return a_ < 1e-6 ? x_m / r_m_ : std::asinh(x_m * sinh_a_ / r_m_) / a_;
}

double CumulusMapping::DxDu(double u) const {
  return a_ < 1e-6 ? r_m_ : r_m_ * a_ * std::cosh(a_ * u) / sinh_a_;
}

double FbmSpec::FinestCellM() const { return feature_size_m / std::pow(lacunarity, octaves - 1); }

// ---------------------------------------------------------------------------- weather field

namespace {

constexpr int kCalibrationSide = 512;   // samples per side of the calibration grid
constexpr int kQuantiles = 4096;        // CDF table: kQuantiles + 1 points
// Sample spacing in first-octave cells: the golden-ratio fraction, incommensurate with the
// lattice so the samples do not alias with it (512 x 0.618 = 316 cells per side).
constexpr double kCalibrationSpacingCells = 0.6180339887498949;

class Fbm2 {
 public:
  Fbm2(const FbmSpec& spec, uint64_t seed, uint64_t stream) : spec_(spec) {
    double sum = 0.0;
    for (int k = 0; k < spec.octaves; ++k) sum += std::pow(spec.gain, k);
    for (int k = 0; k < spec.octaves; ++k) {
      noise_.emplace_back(StreamKey(seed, stream, static_cast<uint64_t>(k)));
      amplitude_.push_back(std::pow(spec.gain, k) / sum);
      frequency_.push_back(std::pow(spec.lacunarity, k) / spec.feature_size_m);  // cells per metre
    }
  }
  double operator()(double x_m, double y_m) const {
    double v = 0.0;
    for (size_t k = 0; k < noise_.size(); ++k) v += amplitude_[k] * noise_[k](x_m * frequency_[k], y_m * frequency_[k]);
    return v;
  }
  const FbmSpec& spec() const { return spec_; }

 private:
  FbmSpec spec_;
  std::vector<GradientNoise2> noise_;
  std::vector<double> amplitude_;
  std::vector<double> frequency_;
};

// The empirical distribution of a stationary field: kQuantiles + 1 quantiles of a large sample.
std::vector<double> Calibrate(const Fbm2& f, double origin_x_m, double origin_y_m) {
  const int m = kCalibrationSide;
  const double step = kCalibrationSpacingCells * f.spec().feature_size_m;
  std::vector<double> s(static_cast<size_t>(m) * m);
  tbb::parallel_for(tbb::blocked_range<int>(0, m), [&](const tbb::blocked_range<int>& r) {
    for (int j = r.begin(); j != r.end(); ++j)
      for (int i = 0; i < m; ++i) s[static_cast<size_t>(j) * m + i] = f(origin_x_m + i * step, origin_y_m + j * step);
  });
  std::sort(s.begin(), s.end());
  std::vector<double> q(kQuantiles + 1);
  for (int k = 0; k <= kQuantiles; ++k) {
    q[k] = s[static_cast<size_t>(std::llround(static_cast<double>(k) * (s.size() - 1) / kQuantiles))];
  }
  return q;
}

// The piecewise-linear CDF through (q_k, k / kQuantiles), 0 below q_0 and 1 above q_K.
double Cdf(const std::vector<double>& q, double w) {
  if (w <= q.front()) return 0.0;
  if (w >= q.back()) return 1.0;
  const size_t k = static_cast<size_t>(std::upper_bound(q.begin(), q.end(), w) - q.begin());  // q[k-1] <= w < q[k]
  const double span = q[k] - q[k - 1];
  const double t = span > 0.0 ? (w - q[k - 1]) / span : 0.0;
  return (static_cast<double>(k - 1) + t) / kQuantiles;
}

}  // namespace

struct WeatherField::Impl {
  WeatherSpec spec;
  Fbm2 density;
  Fbm2 type;
  std::vector<double> density_q, type_q;
  Impl(const WeatherSpec& s) : spec(s), density(s.density, s.seed, 1), type(s.type, s.seed, 2) {}
};

WeatherField::WeatherField(const WeatherSpec& spec) : impl_(std::make_unique<Impl>(spec)) {
  // Calibration windows far from the world centre (1e7 m = 10,000 km east/west): any large window
  // of a stationary field has the same distribution; a distant one keeps the samples independent
  // of the map region the tests examine.
  impl_->density_q = Calibrate(impl_->density, 1.0e7, -1.0e7);
  impl_->type_q = Calibrate(impl_->type, -1.0e7, 1.0e7);
}
WeatherField::~WeatherField() = default;
WeatherField::WeatherField(WeatherField&&) noexcept = default;

const WeatherSpec& WeatherField::spec() const { return impl_->spec; }
double WeatherField::RawDensity(double x, double y) const { return impl_->density(x, y); }
double WeatherField::RawType(double x, double y) const { return impl_->type(x, y); }
double WeatherField::DensityQuantile(double x, double y) const { return Cdf(impl_->density_q, impl_->density(x, y)); }

double WeatherField::Density(double x, double y) const {
  const double c = impl_->spec.coverage;
  if (c <= 0.0) return 0.0;
  const double q = DensityQuantile(x, y);
  if (q <= 1.0 - c) return 0.0;
  return std::pow(std::min((q - (1.0 - c)) / c, 1.0), impl_->spec.density_exponent);
}

double WeatherField::Type(double x, double y) const { return Cdf(impl_->type_q, impl_->type(x, y)); }

// ---------------------------------------------------------------------------- YAML

namespace {

FbmSpec ParseFbm(YamlMap m, const FbmSpec& defaults) {
  FbmSpec f;
  f.feature_size_m = m.Number("feature_size_km", NumberSpec::Positive("km"), defaults.feature_size_m / 1e3) * 1e3;
  f.octaves = static_cast<int>(m.IntegerOr("octaves", 1, 12, "an integer from 1 to 12", defaults.octaves));
  f.lacunarity = m.NumberOr("lacunarity", NumberSpec::Range(1.5, 4.0), defaults.lacunarity);
  NumberSpec gain;
  gain.min = 0.0;
  gain.min_inclusive = false;
  gain.max = 1.0;
  gain.description = "a number in (0, 1] (amplitude ratio between octaves)";
  f.gain = m.NumberOr("gain", gain, defaults.gain);
  m.Finish();
  return f;
}

}  // namespace

CumulusSpec ParseCumulusSpec(const YamlDocument& doc) {
  CumulusSpec spec;
  YamlMap root = doc.RootMap();
  YamlMap map = root.Map("map");
  spec.resolution = static_cast<int>(map.Integer("resolution", 8, 4096, "an integer from 8 to 4096 (texels per side)", 256));
  spec.size_m = map.Number("size_km", NumberSpec::Positive("km"), 240.0) * 1e3;
  spec.edge_to_centre_ratio = map.NumberOr("edge_to_centre_texel_ratio", NumberSpec::Range(1.0, 100.0), 4.0);
  map.Finish();

  YamlMap w = root.Map("weather");
  spec.weather.seed = static_cast<uint64_t>(w.Integer("seed", 0, std::numeric_limits<int64_t>::max(), "a non-negative integer", 0));
  spec.weather.coverage = w.Number("coverage", NumberSpec::Range(0.0, 1.0, ""), 0.5);
  spec.weather.density_exponent = w.NumberOr("density_exponent", NumberSpec::Positive(), 1.0);
  std::optional<YamlNode> density_node = w.Get("density");
  std::optional<YamlNode> type_node = w.Get("type");
  if (density_node) spec.weather.density = ParseFbm(density_node->ToMap(), FbmSpec{});
  else w.ErrorMissing("density", "a mapping {feature_size_km, octaves, lacunarity, gain}");
  if (type_node) spec.weather.type = ParseFbm(type_node->ToMap(), FbmSpec{120e3, 2, 2.0, 0.5});
  else w.ErrorMissing("type", "a mapping {feature_size_km, octaves, lacunarity, gain}");
  w.Finish();

  std::vector<double> wind = root.NumberList("wind_m_s", NumberSpec::Range(-kMaxWindMS, kMaxWindMS, "m/s"));
  if (std::optional<YamlNode> n = root.Get("wind_m_s"); n && !wind.empty()) {
    if (wind.size() != 2) n->ErrorExpected("two numbers [east, north] in m/s");
    else spec.wind_m_s = {wind[0], wind[1]};
  }
  spec.time_s = root.NumberOr("time_s", NumberSpec::Range(-kMaxAbsTimeS, kMaxAbsTimeS, "s"), 0.0);
  root.Finish();

  // Anti-aliasing: the finest octave's cells must span two texels where texels are largest.
  if (doc.diags().empty()) {
    const CumulusMapping mapping = spec.Mapping();
    const double edge_texel_m = mapping.TexelSizeM(1.0);
    auto check = [&](const FbmSpec& f, const std::optional<YamlNode>& node, const char* what) {
      if (node && f.FinestCellM() < 2.0 * edge_texel_m) {
        node->Error(fmt::format("the finest {} octave has {} km cells, less than two texels at the map edge "
                                "(2 x {} km): it would alias; use fewer octaves, a larger feature_size_km or a "
                                "smaller edge_to_centre_texel_ratio",
                                what, FormatExact(std::round(f.FinestCellM()) / 1e3),
                                FormatExact(std::round(edge_texel_m) / 1e3)));
      }
    };
    check(spec.weather.density, density_node, "density");
    check(spec.weather.type, type_node, "type");
  }
  doc.ThrowIfErrors();
  return spec;
}

CumulusSpec LoadCumulusSpec(const std::filesystem::path& path) { return ParseCumulusSpec(YamlDocument::Load(path)); }

std::string CanonicalCumulusYaml(const CumulusSpec& s) {
  YAML::Emitter out;
  auto fbm = [&](const FbmSpec& f) {
    out << YAML::Flow << YAML::BeginMap;
    out << YAML::Key << "feature_size_km" << YAML::Value << FormatExact(f.feature_size_m / 1e3);
    out << YAML::Key << "octaves" << YAML::Value << f.octaves;
    out << YAML::Key << "lacunarity" << YAML::Value << FormatExact(f.lacunarity);
    out << YAML::Key << "gain" << YAML::Value << FormatExact(f.gain);
    out << YAML::EndMap;
  };
  out << YAML::BeginMap;
  out << YAML::Key << "map" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "resolution" << YAML::Value << s.resolution;
  out << YAML::Key << "size_km" << YAML::Value << FormatExact(s.size_m / 1e3);
  out << YAML::Key << "edge_to_centre_texel_ratio" << YAML::Value << FormatExact(s.edge_to_centre_ratio);
  out << YAML::EndMap;
  out << YAML::Key << "weather" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "seed" << YAML::Value << s.weather.seed;
  out << YAML::Key << "coverage" << YAML::Value << FormatExact(s.weather.coverage);
  out << YAML::Key << "density_exponent" << YAML::Value << FormatExact(s.weather.density_exponent);
  out << YAML::Key << "density" << YAML::Value;
  fbm(s.weather.density);
  out << YAML::Key << "type" << YAML::Value;
  fbm(s.weather.type);
  out << YAML::EndMap;
  out << YAML::Key << "wind_m_s" << YAML::Value << YAML::Flow << YAML::BeginSeq << FormatExact(s.wind_m_s[0])
      << FormatExact(s.wind_m_s[1]) << YAML::EndSeq;
  out << YAML::Key << "time_s" << YAML::Value << FormatExact(s.time_s);
  out << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

// ---------------------------------------------------------------------------- map

CumulusMap GenerateCumulusMap(const CumulusSpec& spec, const WeatherField& field, const ProgressFn& progress) {
  const CumulusMapping mapping = spec.Mapping();
  const int n = spec.resolution;
  CumulusMap map;
  map.resolution = n;
  map.values.resize(static_cast<size_t>(n) * n * 2);
  // The stationary field is sampled at p - V t (advection).
  const double shift_x = spec.wind_m_s[0] * spec.time_s, shift_y = spec.wind_m_s[1] * spec.time_s;
  std::vector<double> world(n);
  for (int i = 0; i < n; ++i) world[i] = mapping.WorldFromU(mapping.TexelCentreU(i));
  std::atomic<int> done{0};
  tbb::parallel_for(tbb::blocked_range<int>(0, n), [&](const tbb::blocked_range<int>& r) {
    for (int j = r.begin(); j != r.end(); ++j) {
      const double y = world[j] - shift_y;
      for (int i = 0; i < n; ++i) {
        const double x = world[i] - shift_x;
        const size_t idx = (static_cast<size_t>(j) * n + i) * 2;
        map.values[idx + 0] = static_cast<float>(field.Density(x, y));
        map.values[idx + 1] = static_cast<float>(field.Type(x, y));
      }
      ReportProgress(progress, "cumulus map", static_cast<double>(++done) / n);
    }
  });
  return map;
}

}  // namespace skybake::noise
