#include "transport/sky_method.h"

#include <algorithm>

#include <glm/geometric.hpp>

#include <fmt/format.h>

#include "io/error.h"
#include "transport/method_orders.h"
#include "transport/method_analytic.h"
#include "transport/method_ms_approx.h"
#include "transport/method_single.h"
#include "transport/spectral_stride.h"

namespace skybake {

void SkyMethod::SegmentRadiance(double, double, const std::vector<std::array<double, 3>>&, const ViewSegment&,
                                std::vector<double>*) const {
  throw UsageError("--method " + Name() + " does not render view segments (fog); use orders or path");
}

std::vector<std::string> SkyMethodNames() { return {"single", "orders", "ms-approx", "analytic"}; }

std::unique_ptr<SkyMethod> MakeSkyMethod(const std::string& name, const AtmosphereModel& model,
                                         const SkyMethodOptions& options, const ProgressFn& progress) {
  if (options.spectral_stride < 1 || options.spectral_stride > 64) {
    throw UsageError(fmt::format("--spectral-stride: expected 1 to 64, got {}", options.spectral_stride));
  }
  if (options.spectral_stride > 1 && model.wavelengths() > 2) {
    const std::vector<std::string> names = SkyMethodNames();
    const bool known = std::find(names.begin(), names.end(), name) != names.end();
    if (known) return MakeSpectralStrideMethod(name, model, options, progress);
  }
  if (name == "single") return MakeSingleMethod(model, options);
  if (name == "ms-approx") return MakeMsApproxMethod(model, options, progress);
  if (name == "analytic") return MakeAnalyticMethod(model, options);
  if (name == "orders") return MakeOrdersMethod(model, options, progress);
  std::string known;
  for (const std::string& n : SkyMethodNames()) known += (known.empty() ? "" : ", ") + n;
  throw UsageError("--method: expected path, " + known + "; got '" + name + "'");
}

}  // namespace skybake
