#include "noise/volume.h"

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

// ---------------------------------------------------------------------------- names

const char* FormatName(VolumeFormat f) {
  switch (f) {
    case VolumeFormat::kR8Unorm: return "r8_unorm";
    case VolumeFormat::kR16Sfloat: return "r16_sfloat";
    case VolumeFormat::kR8G8B8A8Unorm: return "rgba8_unorm";
  }
  return "?";
}

const char* NormalizationName(Normalization n) {
  switch (n) {
    case Normalization::kNone: return "none";
    case Normalization::kMinMax: return "min_max";
    case Normalization::kZeroMean: return "zero_mean";
  }
  return "?";
}

int ChannelCount(VolumeFormat f) { return f == VolumeFormat::kR8G8B8A8Unorm ? 4 : 1; }

namespace {
int OctaveFrequency(int f, int lacunarity, int octave) {
  int64_t v = f;
  for (int k = 0; k < octave; ++k) v *= lacunarity;
  return static_cast<int>(std::min<int64_t>(v, std::numeric_limits<int>::max()));
}
const char* KindName(NoiseKind k) {
  switch (k) {
    case NoiseKind::kPerlin: return "perlin";
    case NoiseKind::kWorley: return "worley";
    case NoiseKind::kPerlinWorley: return "perlin_worley";
  }
  return "?";
}
}  // namespace

int ChannelSpec::LowestFrequency() const {
  switch (kind) {
    case NoiseKind::kPerlin: return perlin.frequency;
    case NoiseKind::kWorley: return worley.frequency;
    case NoiseKind::kPerlinWorley: return std::min(perlin.frequency, worley.frequency);
  }
  return 0;
}

int ChannelSpec::HighestFrequency() const {
  const int p = OctaveFrequency(perlin.frequency, perlin.lacunarity, perlin.octaves - 1);
  const int w = OctaveFrequency(worley.frequency, worley.lacunarity, static_cast<int>(worley.weights.size()) - 1);
  switch (kind) {
    case NoiseKind::kPerlin: return p;
    case NoiseKind::kWorley: return w;
    case NoiseKind::kPerlinWorley: return std::max(p, w);
  }
  return 0;
}

// ---------------------------------------------------------------------------- YAML

namespace {

constexpr int64_t kMaxFrequency = 256;  // cells per tile; also bounded by Nyquist below

NumberSpec GainSpec() {
  NumberSpec s;
  s.min = 0.0;
  s.min_inclusive = false;
  s.max = 1.0;
  s.description = "a number in (0, 1] (amplitude ratio between octaves)";
  return s;
}

PerlinTerm ParsePerlin(YamlMap m) {
  PerlinTerm t;
  t.frequency = static_cast<int>(m.Integer("frequency", 1, kMaxFrequency, "an integer number of cells per tile from 1 to 256", 4));
  t.octaves = static_cast<int>(m.IntegerOr("octaves", 1, 12, "an integer from 1 to 12", 1));
  t.lacunarity = static_cast<int>(m.IntegerOr("lacunarity", 2, 8, "an integer from 2 to 8 (so that every octave tiles)", 2));
  t.gain = m.NumberOr("gain", GainSpec(), 0.5);
  m.Finish();
  return t;
}

WorleyTerm ParseWorley(YamlMap m) {
  WorleyTerm t;
  t.frequency = static_cast<int>(m.Integer("frequency", 1, kMaxFrequency, "an integer number of cells per tile from 1 to 256", 4));
  t.lacunarity = static_cast<int>(m.IntegerOr("lacunarity", 2, 8, "an integer from 2 to 8 (so that every octave tiles)", 2));
  t.jitter = m.NumberOr("jitter", NumberSpec::Range(0.0, 1.0), 1.0);
  // Octave weights: an explicit list, or `octaves` + `gain` (w_k = gain^k).
  const std::string which = m.AtMostOneOf({"weights", "octaves"});
  if (which == "weights") {
    std::vector<double> w = m.NumberList("weights", NumberSpec::Positive());
    if (w.size() > 12) m.Get("weights")->Error("at most 12 octaves");
    if (!w.empty()) t.weights = w;
    m.Known({"gain"});
    if (m.Has("gain")) m.Get("gain")->Error("give either 'weights' or 'gain' (with 'octaves'), not both");
  } else {
    const int octaves = static_cast<int>(m.IntegerOr("octaves", 1, 12, "an integer from 1 to 12", 1));
    const double gain = m.NumberOr("gain", GainSpec(), 0.5);
    t.weights.clear();
    for (int k = 0; k < octaves; ++k) t.weights.push_back(std::pow(gain, k));
  }
  m.Finish();
  return t;
}

}  // namespace

VolumeSpec ParseVolumeSpec(const YamlDocument& doc, const std::string& name) {
  VolumeSpec spec;
  spec.name = name;
  YamlMap root = doc.RootMap();
  spec.resolution = static_cast<int>(root.Integer("resolution", 4, 256, "an integer from 4 to 256 (texels per side)", 32));
  spec.tile_size_m = root.Number("tile_size_km", NumberSpec::Positive("km"), 1.0) * 1e3;
  spec.seed = static_cast<uint64_t>(root.Integer("seed", 0, std::numeric_limits<int64_t>::max(), "a non-negative integer", 0));
  const std::string format = root.Choice("format", {"r8_unorm", "r16_sfloat", "rgba8_unorm"});
  if (format == "r16_sfloat") spec.format = VolumeFormat::kR16Sfloat;
  else if (format == "rgba8_unorm") spec.format = VolumeFormat::kR8G8B8A8Unorm;
  else spec.format = VolumeFormat::kR8Unorm;
  const std::string norm = root.Choice("normalize", {"zero_mean", "min_max", "none"});
  if (norm == "zero_mean") spec.normalization = Normalization::kZeroMean;
  else if (norm == "none") spec.normalization = Normalization::kNone;
  else spec.normalization = Normalization::kMinMax;
  // UNORM texels hold [0, 1]: only min_max guarantees that range (zero_mean is negative half the time).
  if (!format.empty() && !norm.empty() && spec.format != VolumeFormat::kR16Sfloat &&
      spec.normalization != Normalization::kMinMax) {
    root.Get("normalize")->Error(fmt::format("{} stores values in [0, 1]: use min_max, or format r16_sfloat for {}",
                                             format, norm));
  }

  std::vector<YamlNode> channels = root.Seq("channels");
  for (size_t c = 0; c < channels.size(); ++c) {
    YamlMap m = channels[c].ToMap("a channel recipe: {perlin: ...}, {worley: ...} or {perlin_worley: ...}");
    if (!m.valid()) continue;
    ChannelSpec ch;
    const std::string kind = m.ExactlyOneOf({"perlin", "worley", "perlin_worley"});
    if (kind == "perlin") {
      ch.kind = NoiseKind::kPerlin;
      ch.perlin = ParsePerlin(m.Map("perlin"));
    } else if (kind == "worley") {
      ch.kind = NoiseKind::kWorley;
      ch.worley = ParseWorley(m.Map("worley"));
    } else if (kind == "perlin_worley") {
      ch.kind = NoiseKind::kPerlinWorley;
      YamlMap pw = m.Map("perlin_worley");
      ch.perlin = ParsePerlin(pw.Map("perlin"));
      ch.worley = ParseWorley(pw.Map("worley"));
      pw.Finish();
    }
    m.Finish();
    // Nyquist: an octave with more than N/2 cells per tile cannot be represented by N texels.
    const int highest = ch.HighestFrequency();
    if (!kind.empty() && highest > spec.resolution / 2) {
      channels[c].Error(fmt::format("the finest octave has {} cells per tile, above the Nyquist limit of {} "
                                    "(resolution / 2): lower the frequency, octaves or lacunarity, or raise the resolution",
                                    highest, spec.resolution / 2));
    }
    spec.channels.push_back(ch);
  }
  if (std::optional<YamlNode> node = root.Get("channels"); node && node->IsSeq() && !format.empty()) {
    const int want = ChannelCount(spec.format);
    if (static_cast<int>(channels.size()) != want) {
      node->Error(fmt::format("{} needs {} channel{}, got {}", format, want, want == 1 ? "" : "s", channels.size()));
    }
  }
  root.Finish();
  doc.ThrowIfErrors();
  return spec;
}

VolumeSpec LoadVolumeSpec(const std::filesystem::path& path) {
  YamlDocument doc = YamlDocument::Load(path);
  return ParseVolumeSpec(doc, path.stem().string());
}

std::string CanonicalVolumeYaml(const VolumeSpec& spec) {
  YAML::Emitter out;
  auto perlin = [&](const PerlinTerm& t) {
    out << YAML::Flow << YAML::BeginMap;
    out << YAML::Key << "frequency" << YAML::Value << t.frequency;
    out << YAML::Key << "octaves" << YAML::Value << t.octaves;
    out << YAML::Key << "lacunarity" << YAML::Value << t.lacunarity;
    out << YAML::Key << "gain" << YAML::Value << FormatExact(t.gain);
    out << YAML::EndMap;
  };
  auto worley = [&](const WorleyTerm& t) {
    out << YAML::Flow << YAML::BeginMap;
    out << YAML::Key << "frequency" << YAML::Value << t.frequency;
    out << YAML::Key << "lacunarity" << YAML::Value << t.lacunarity;
    out << YAML::Key << "weights" << YAML::Value << YAML::Flow << YAML::BeginSeq;
    for (double w : t.weights) out << FormatExact(w);
    out << YAML::EndSeq;
    out << YAML::Key << "jitter" << YAML::Value << FormatExact(t.jitter);
    out << YAML::EndMap;
  };
  out << YAML::BeginMap;
  out << YAML::Key << "name" << YAML::Value << spec.name;
  out << YAML::Key << "resolution" << YAML::Value << spec.resolution;
  out << YAML::Key << "tile_size_km" << YAML::Value << FormatExact(spec.tile_size_m / 1e3);
  out << YAML::Key << "seed" << YAML::Value << spec.seed;
  out << YAML::Key << "format" << YAML::Value << FormatName(spec.format);
  out << YAML::Key << "normalize" << YAML::Value << NormalizationName(spec.normalization);
  out << YAML::Key << "channels" << YAML::Value << YAML::BeginSeq;
  for (const ChannelSpec& c : spec.channels) {
    out << YAML::BeginMap << YAML::Key << KindName(c.kind) << YAML::Value;
    if (c.kind == NoiseKind::kPerlin) perlin(c.perlin);
    if (c.kind == NoiseKind::kWorley) worley(c.worley);
    if (c.kind == NoiseKind::kPerlinWorley) {
      out << YAML::BeginMap << YAML::Key << "perlin" << YAML::Value;
      perlin(c.perlin);
      out << YAML::Key << "worley" << YAML::Value;
      worley(c.worley);
      out << YAML::EndMap;
    }
    out << YAML::EndMap;
  }
  out << YAML::EndSeq << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

// ---------------------------------------------------------------------------- fields

struct ChannelField::Impl {
  NoiseKind kind;
  std::vector<PeriodicGradientNoise3> perlin;  // one per octave
  std::vector<double> perlin_amplitude;        // g^k / sum g^k
  std::vector<PeriodicWorley3> worley;
  std::vector<double> worley_weight;           // w_k / sum w
};

ChannelField::ChannelField(const ChannelSpec& spec, uint64_t seed, uint64_t stream) : impl_(std::make_unique<Impl>()) {
  impl_->kind = spec.kind;
  if (spec.kind != NoiseKind::kWorley) {
    double sum = 0.0;
    for (int k = 0; k < spec.perlin.octaves; ++k) sum += std::pow(spec.perlin.gain, k);
    for (int k = 0; k < spec.perlin.octaves; ++k) {
      const int f = OctaveFrequency(spec.perlin.frequency, spec.perlin.lacunarity, k);
      impl_->perlin.emplace_back(f, StreamKey(seed, stream * 64 + 0, static_cast<uint64_t>(k)));
      impl_->perlin_amplitude.push_back(std::pow(spec.perlin.gain, k) / sum);
    }
  }
  if (spec.kind != NoiseKind::kPerlin) {
    double sum = 0.0;
    for (double w : spec.worley.weights) sum += w;
    for (size_t k = 0; k < spec.worley.weights.size(); ++k) {
      const int f = OctaveFrequency(spec.worley.frequency, spec.worley.lacunarity, static_cast<int>(k));
      impl_->worley.emplace_back(f, spec.worley.jitter, StreamKey(seed, stream * 64 + 32, k));
      impl_->worley_weight.push_back(spec.worley.weights[k] / sum);
    }
  }
}

ChannelField::~ChannelField() = default;
ChannelField::ChannelField(ChannelField&&) noexcept = default;

double ChannelField::operator()(double x, double y, double z) const {
  const Impl& m = *impl_;
  double p = 0.0;
  for (size_t k = 0; k < m.perlin.size(); ++k) {
    const double f = m.perlin[k].period();  // lattice units = tile coordinate x cells per tile
    p += m.perlin_amplitude[k] * m.perlin[k](x * f, y * f, z * f);
  }
  double w = 0.0;
  for (size_t k = 0; k < m.worley.size(); ++k) {
    const double f = m.worley[k].period();
    w += m.worley_weight[k] * (1.0 - std::min(m.worley[k].F1(x * f, y * f, z * f), 1.0));
  }
  switch (m.kind) {
    case NoiseKind::kPerlin: return p;
    case NoiseKind::kWorley: return w;
    case NoiseKind::kPerlinWorley: {
      const double p01 = std::clamp(0.5 * (p + 1.0), 0.0, 1.0);
      return w + p01 * (1.0 - w);  // remap(p01, 0, 1, w, 1)
    }
  }
  return 0.0;
}

// ---------------------------------------------------------------------------- generation

ChannelStats ComputeStats(const Volume& v, int c) {
  const int n = v.resolution;
  struct Slice {
    double sum = 0.0, min = std::numeric_limits<double>::infinity(), max = -std::numeric_limits<double>::infinity();
    double sq = 0.0;
  };
  std::vector<Slice> slices(n);
  tbb::parallel_for(tbb::blocked_range<int>(0, n), [&](const tbb::blocked_range<int>& r) {
    for (int k = r.begin(); k != r.end(); ++k) {
      Slice s;
      for (int j = 0; j < n; ++j) {
        for (int i = 0; i < n; ++i) {
          const double x = v.At(i, j, k, c);
          s.sum += x;
          s.min = std::min(s.min, x);
          s.max = std::max(s.max, x);
        }
      }
      slices[k] = s;
    }
  });
  ChannelStats st;
  st.min = std::numeric_limits<double>::infinity();
  st.max = -std::numeric_limits<double>::infinity();
  double sum = 0.0;
  for (const Slice& s : slices) {
    sum += s.sum;
    st.min = std::min(st.min, s.min);
    st.max = std::max(st.max, s.max);
  }
  const double count = static_cast<double>(n) * n * n;
  st.mean = sum / count;
  // Second pass about the mean (no catastrophic cancellation), same deterministic order.
  tbb::parallel_for(tbb::blocked_range<int>(0, n), [&](const tbb::blocked_range<int>& r) {
    for (int k = r.begin(); k != r.end(); ++k) {
      double sq = 0.0;
      for (int j = 0; j < n; ++j) {
        for (int i = 0; i < n; ++i) {
          const double d = v.At(i, j, k, c) - st.mean;
          sq += d * d;
        }
      }
      slices[k].sq = sq;
    }
  });
  double sq = 0.0;
  for (const Slice& s : slices) sq += s.sq;
  st.stddev = std::sqrt(sq / count);
  return st;
}

GeneratedVolume GenerateVolume(const VolumeSpec& spec, const ProgressFn& progress) {
  SKYBAKE_CHECK(!spec.channels.empty());
  const int n = spec.resolution;
  const int channels = static_cast<int>(spec.channels.size());
  std::vector<ChannelField> fields;
  for (int c = 0; c < channels; ++c) fields.emplace_back(spec.channels[c], spec.seed, static_cast<uint64_t>(c));

  GeneratedVolume out;
  Volume& v = out.volume;
  v.resolution = n;
  v.channels = channels;
  v.values.resize(static_cast<size_t>(n) * n * n * channels);
  std::atomic<int> done{0};
  ReportProgress(progress, "noise", 0.0);
  tbb::parallel_for(tbb::blocked_range<int>(0, n, 1), [&](const tbb::blocked_range<int>& r) {
    for (int k = r.begin(); k != r.end(); ++k) {
      const double z = (k + 0.5) / n;
      for (int j = 0; j < n; ++j) {
        const double y = (j + 0.5) / n;
        for (int i = 0; i < n; ++i) {
          const double x = (i + 0.5) / n;
          for (int c = 0; c < channels; ++c) v.values[v.Index(i, j, k, c)] = static_cast<float>(fields[c](x, y, z));
        }
      }
      ReportProgress(progress, "noise", static_cast<double>(++done) / n);
    }
  });

  for (int c = 0; c < channels; ++c) {
    const ChannelStats raw = ComputeStats(v, c);
    out.raw.push_back(raw);
    double offset = 0.0, scale = 1.0;
    std::pair<double, double> range{raw.min, raw.max};
    switch (spec.normalization) {
      case Normalization::kZeroMean:
        offset = raw.mean;
        scale = std::max(raw.max - raw.mean, raw.mean - raw.min);
        range = {-1.0, 1.0};
        break;
      case Normalization::kMinMax:
        offset = raw.min;
        scale = raw.max - raw.min;
        range = {0.0, 1.0};
        break;
      case Normalization::kNone:
        break;
    }
    if (!(scale > 0.0)) scale = 1.0;  // a constant channel stays constant (0 after the offset)
    if (spec.normalization != Normalization::kNone) {
      tbb::parallel_for(tbb::blocked_range<size_t>(0, v.values.size() / channels), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t t = r.begin(); t != r.end(); ++t) {
          float& x = v.values[t * channels + c];
          double y = (static_cast<double>(x) - offset) / scale;
          if (spec.normalization == Normalization::kMinMax) y = std::clamp(y, 0.0, 1.0);
          if (spec.normalization == Normalization::kZeroMean) y = std::clamp(y, -1.0, 1.0);
          x = static_cast<float>(y);
        }
      });
    }
    out.range.push_back(range);
    out.normalised.push_back(ComputeStats(v, c));
  }
  return out;
}

}  // namespace skybake::noise
