// Tileable cloud noise volumes (noise-gen): the GT7 low- and high-frequency textures and a
// Frostbite/Horizon-style RGBA shape texture, from a YAML recipe (docs/clouds.md).
//
// Sources: GT7 sky talk, "Modeling of Clouds": low frequency
// 128^3 Perlin-inverted Worley, ~5 km, normalised to zero mean "so the amount of clouds does not
// vary with the intensity of the noise"; high frequency 32^3 Worley, ~300 m. Hillaire 2016 §5.4
// ("Cloud noise") and Schneider 2015 ("The real-time
// volumetric cloudscapes of Horizon Zero Dawn", SIGGRAPH Advances): Perlin-Worley base shape and
// Worley octaves, stored as RGBA.
//
// A volume is N^3 texels covering one tile, texel (i, j, k) at the tile coordinates
// p = ((i + 1/2)/N, (j + 1/2)/N, (k + 1/2)/N) in [0,1)^3. Every channel is built from noise
// terms whose lattices have an integer number of cells per tile, so the continuous field is
// exactly periodic with period 1 on each axis and the texture wraps seamlessly (GPU REPEAT).
//
// Channel recipes (F = `frequency`, cells per tile; octave k has F L^k cells, L = `lacunarity`):
//   perlin:        P(p) = sum_k g^k n(F L^k p) / sum_k g^k                         (fBm, ~[-1, 1])
//   worley:        W(p) = sum_k w_k (1 - min(F1(F L^k p), 1)) / sum_k w_k          ([0, 1])
//                  (inverted Worley: 1 at feature points; weights w_k as given, e.g. Schneider's
//                  0.625, 0.25, 0.125, or g^k from `gain`)
//   perlin_worley: PW = W + P01 (1 - W), P01 = clamp((P + 1)/2, 0, 1)              ([0, 1])
//                  (Schneider 2015's remap(P01, 0, 1, W, 1): Perlin "dilated" by inverted Worley)
// Then every channel is normalised with the volume's `normalize`:
//   zero_mean:  v' = (v - mean) / max|v - mean|    -> mean 0, range [-1, 1], an extreme at +-1
//   min_max:    v' = (v - min) / (max - min)       -> range [0, 1] exactly
//   none:       v' = v
// Means are accumulated in double per z slice, then over slices in order: thread-independent.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "io/progress.h"
#include "io/yaml.h"

namespace skybake::noise {

struct PerlinTerm {
  int frequency = 4;   // cells per tile of the first octave
  int octaves = 1;
  int lacunarity = 2;  // integer: every octave tiles
  double gain = 0.5;   // amplitude ratio between octaves
};

struct WorleyTerm {
  int frequency = 4;
  int lacunarity = 2;
  std::vector<double> weights{1.0};  // one per octave (octaves = weights.size())
  double jitter = 1.0;               // feature point jitter in [0, 1]
};

enum class NoiseKind { kPerlin, kWorley, kPerlinWorley };

struct ChannelSpec {
  NoiseKind kind = NoiseKind::kPerlin;
  PerlinTerm perlin;  // used by kPerlin, kPerlinWorley
  WorleyTerm worley;  // used by kWorley, kPerlinWorley
  // The lowest and highest octave frequencies (cells per tile) of the channel's terms.
  int LowestFrequency() const;
  int HighestFrequency() const;
};

enum class Normalization { kNone, kMinMax, kZeroMean };
enum class VolumeFormat { kR8Unorm, kR16Sfloat, kR8G8B8A8Unorm };

struct VolumeSpec {
  std::string name;            // the file's stem (output naming, provenance)
  int resolution = 32;         // texels per side
  double tile_size_m = 1000.0; // world size of one tile (metadata for the renderer)
  uint64_t seed = 0;
  VolumeFormat format = VolumeFormat::kR8Unorm;
  Normalization normalization = Normalization::kMinMax;
  std::vector<ChannelSpec> channels;  // 1 (R8, R16F) or 4 (RGBA8)
};

const char* FormatName(VolumeFormat f);          // "r8_unorm", ...
const char* NormalizationName(Normalization n);  // "zero_mean", ...
int ChannelCount(VolumeFormat f);

// Loads and validates a volume file; every problem is reported with file:line (InputError).
VolumeSpec LoadVolumeSpec(const std::filesystem::path& path);
VolumeSpec ParseVolumeSpec(const YamlDocument& doc, const std::string& name);
// The resolved parameters as YAML (numbers in shortest round-trip form), for provenance.
std::string CanonicalVolumeYaml(const VolumeSpec& spec);

// Evaluates one channel's raw (un-normalised) value at tile coordinates p (periodic, period 1).
// The lattice tables are built once in the constructor; operator() is thread-safe.
class ChannelField {
 public:
  // `stream` separates the channels of one volume (use the channel index).
  ChannelField(const ChannelSpec& spec, uint64_t seed, uint64_t stream);
  ~ChannelField();
  ChannelField(ChannelField&&) noexcept;
  double operator()(double x, double y, double z) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

struct ChannelStats {
  double mean = 0.0;
  double min = 0.0;
  double max = 0.0;
  double stddev = 0.0;
};

// A channel-interleaved cube of float texels: index ((k N + j) N + i) C + c, x fastest.
struct Volume {
  int resolution = 0;
  int channels = 0;
  std::vector<float> values;
  size_t Index(int i, int j, int k, int c) const {
    return ((static_cast<size_t>(k) * resolution + j) * resolution + i) * channels + c;
  }
  float At(int i, int j, int k, int c) const { return values[Index(i, j, k, c)]; }
};

struct GeneratedVolume {
  Volume volume;                         // normalised values (what is stored)
  std::vector<ChannelStats> raw;         // per channel, before normalisation
  std::vector<ChannelStats> normalised;  // per channel, of the stored float field
  // The stated value range of each channel: [-1, 1] (zero_mean), [0, 1] (min_max), or the raw
  // minimum and maximum (none).
  std::vector<std::pair<double, double>> range;
};

// Evaluates every channel at every texel centre (TBB over z slices) and normalises.
// The result is identical for any thread count.
GeneratedVolume GenerateVolume(const VolumeSpec& spec, const ProgressFn& progress = {});

// Statistics of channel c (double accumulation per z slice, slices summed in order).
ChannelStats ComputeStats(const Volume& v, int c);

}  // namespace skybake::noise
