// The quality preset of the deterministic sky methods (docs/sky-methods.md, "Qualities"):
// one enum for the command line (sky-render --quality), pipeline.yaml (luts.quality,
// fog.quality) and every method's preset table, which is indexed by it.
#pragma once

#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace skybake {

class YamlMap;

enum class Quality { kLow, kMedium, kHigh };

inline constexpr int kQualityCount = 3;

// A method's presets, one per Quality, indexed by it: presets[Quality::kHigh].
template <typename T>
struct QualityTable {
  std::array<T, kQualityCount> by_quality;
  constexpr const T& operator[](Quality q) const { return by_quality[static_cast<size_t>(q)]; }
};

// "low", "medium", "high".
std::string QualityName(Quality q);
// The names in enum order: {"low", "medium", "high"}.
const std::vector<std::string>& QualityNames();
// "low, medium or high".
std::string QualityNamesText();

// The quality of a name; nullopt for anything else (the names are case-sensitive).
std::optional<Quality> FindQuality(std::string_view name);
// The quality of a name; UsageError "<where>: expected low, medium or high, got '<name>'".
Quality ParseQuality(std::string_view name, const std::string& where);
// The key `quality` of a pipeline.yaml mapping: `default_value` when absent; a located error
// (file:line, "expected one of 'low', 'medium' or 'high'") recorded in the map otherwise.
Quality QualityOr(YamlMap& map, Quality default_value);

}  // namespace skybake
