// lut-pack's JSON documents (docs/lut-pack.md, "Outputs" and "Decode check"): written with
// nlohmann::ordered_json (keys in a fixed order, numbers in shortest round-trip form), so the
// same inputs give the same bytes.
#pragma once

#include <map>
#include <string>

#include "lut/check.h"
#include "lut/sky_lut.h"

namespace skybake::luttool {

struct ReportContext {
  std::map<std::string, size_t> file_bytes;  // file name (in the output folder) -> size
  double budget_bytes = 0.0;
  size_t sky_texel_bytes = 0;
  std::string ocio_config;
};

std::string PackReportJson(const lut::LutSet& set, const ReportContext& ctx);
std::string CheckReportJson(const lut::CheckResult& result, const std::string& luts);

}  // namespace skybake::luttool
