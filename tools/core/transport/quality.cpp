#include "transport/quality.h"

#include "io/error.h"
#include "io/text_list.h"
#include "io/yaml.h"

namespace skybake {

// The one place the preset names are spelt, in enum order.
const std::vector<std::string>& QualityNames() {
  static const std::vector<std::string> names = {"low", "medium", "high"};
  return names;
}

std::string QualityName(Quality q) { return QualityNames()[static_cast<size_t>(q)]; }

std::string QualityNamesText() { return TextList(QualityNames()); }

std::optional<Quality> FindQuality(std::string_view name) {
  for (int i = 0; i < kQualityCount; ++i) {
    if (QualityNames()[i] == name) return static_cast<Quality>(i);
  }
  return std::nullopt;
}

Quality ParseQuality(std::string_view name, const std::string& where) {
  if (std::optional<Quality> q = FindQuality(name)) return *q;
  throw UsageError(where + ": expected " + QualityNamesText() + ", got '" + std::string(name) + "'");
}

Quality QualityOr(YamlMap& map, Quality default_value) {
  return FindQuality(map.ChoiceOr("quality", QualityNames(), QualityName(default_value))).value_or(default_value);
}

}  // namespace skybake
