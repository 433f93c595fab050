#include "transport/sky_method.h"

#include <algorithm>

#include <glm/geometric.hpp>

#include <fmt/format.h>

#include "io/error.h"
#include "io/text_list.h"
#include "transport/method_orders.h"
#include "transport/method_analytic.h"
#include "transport/method_ms_approx.h"
#include "transport/method_single.h"
#include "transport/orders/settings.h"
#include "transport/spectral_stride.h"

namespace skybake {

void SkyMethod::SegmentRadiance(double, double, const std::vector<std::array<double, 3>>&, const ViewSegment&,
                                std::vector<double>*) const {
  throw UsageError("--method " + Name() + " does not render view segments (fog); use orders or path");
}

namespace {

const std::vector<std::string>& NoOverrides() {
  static const std::vector<std::string> none;
  return none;
}

}  // namespace

const std::vector<SkyMethodEntry>& SkyMethodRegistry() {
  static const std::vector<SkyMethodEntry> registry = {
      {"single", false, NoOverrides,
       [](const AtmosphereModel& m, const SkyMethodOptions& o, const ProgressFn&) { return MakeSingleMethod(m, o); }},
      {"orders", true, orders::OverrideKeys, MakeOrdersMethod},
      {"ms-approx", false, NoOverrides, MakeMsApproxMethod},
      {"analytic", false, NoOverrides,
       [](const AtmosphereModel& m, const SkyMethodOptions& o, const ProgressFn&) { return MakeAnalyticMethod(m, o); }},
  };
  return registry;
}

const SkyMethodEntry* FindSkyMethod(std::string_view name) {
  for (const SkyMethodEntry& e : SkyMethodRegistry()) {
    if (name == e.name) return &e;
  }
  return nullptr;
}

std::vector<std::string> SkyMethodNames() {
  std::vector<std::string> names;
  for (const SkyMethodEntry& e : SkyMethodRegistry()) names.push_back(e.name);
  return names;
}

std::vector<std::string> SegmentMethodNames() {
  std::vector<std::string> names;
  for (const SkyMethodEntry& e : SkyMethodRegistry()) {
    if (e.segments) names.push_back(e.name);
  }
  return names;
}

void CheckOverrideKeys(const std::string& method, const std::map<std::string, int>& given,
                       const std::vector<std::string>& known) {
  for (const auto& [key, value] : given) {
    if (std::find(known.begin(), known.end(), key) != known.end()) continue;
    if (known.empty()) throw UsageError(method + " reads no expert overrides, got '" + key + "'");
    throw UsageError(method + ": unknown expert override '" + key + "' (known: " + TextList(known, ", ") + ")");
  }
}

std::unique_ptr<SkyMethod> MakeSkyMethod(const std::string& name, const AtmosphereModel& model,
                                         const SkyMethodOptions& options, const ProgressFn& progress) {
  if (options.spectral_stride < 1 || options.spectral_stride > 64) {
    throw UsageError(fmt::format("--spectral-stride: expected 1 to 64, got {}", options.spectral_stride));
  }
  const SkyMethodEntry* entry = FindSkyMethod(name);
  if (!entry) throw UsageError("--method: expected path, " + TextList(SkyMethodNames(), ", ") + "; got '" + name + "'");
  CheckOverrideKeys(entry->name, options.table_size, entry->override_keys());
  if (options.spectral_stride > 1 && model.wavelengths() > 2) return MakeSpectralStrideMethod(name, model, options, progress);
  return entry->make(model, options, progress);
}

}  // namespace skybake
