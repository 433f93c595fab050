// The decode check of lut-pack (docs/lut-pack.md, "Decode check"): the sky decoded from packed
// LUTs (lut/decoder.h; one basis sky or a weighted blend of several) against a direct render of
// the same atmosphere by sky-render on an ordinary direction grid, at sun angles of the direct
// render's choosing (typically between two slices). Luminance Y of the decoded Linear Rec.2020
// comes from OCIO (Rec.2020 -> CIE-XYZ-D65); the direct render's Y is its G channel.
//
// Figures per sun angle, over the texels of the direct render (equirectangular: solid-angle
// weighted, the exact texel solid angles of lut/directions.h):
//   relative luminance error e = (Y_decoded - Y_direct) / Y_direct;
//   RMS of e over the upper hemisphere (view zenith < 90 deg) and over the lower one, with and
//   without a cone of `sun_cone_deg` around the sun (the aureole's steep gradients);
//   the largest |e| and where it is (view zenith, azimuth from the sun, angle from the sun).
#pragma once

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "color/color.h"
#include "lut/decoder.h"

namespace skybake::lut {

struct CheckWhere {
  double error = 0.0;  // signed relative luminance error
  double view_zenith_deg = 0.0, azimuth_deg = 0.0, sun_angle_deg = 0.0;
  double y_direct = 0.0, y_decoded = 0.0;
};

struct CheckSlice {
  double sun_zenith_deg = 0.0;
  double slice_coordinate = 0.0;  // where the angle falls in the time mapping
  double rms_upper = 0.0, rms_lower = 0.0;                  // whole hemispheres
  double rms_upper_outside_cone = 0.0, rms_lower_outside_cone = 0.0;
  double mean_upper = 0.0;                                   // signed mean (bias), upper hemisphere
  CheckWhere max_upper, max_upper_outside_cone, max_lower;
  size_t texels = 0, skipped = 0;  // skipped: Y_direct <= 0
};

struct CheckResult {
  std::string direct;         // the direct render's path
  std::string direct_mapping; // its mapping description
  double sun_cone_deg = 0.0;
  std::vector<CheckSlice> slices;
  double rms_upper_all = 0.0;  // RMS over every slice's upper-hemisphere texels (solid-angle weighted)
  double rms_upper_all_outside_cone = 0.0;
  double worst_slice_rms_upper = 0.0;
};

// Reads a sky-render EXR with equirectangular or fisheye sky parts (any sun angles) and compares.
// InputError(path) if it is not such a render.
CheckResult CheckAgainstDirect(const std::vector<std::pair<const SkyLutDecoder*, double>>& luts,
                               const std::filesystem::path& direct, const ColorConfig& config, double sun_cone_deg);

}  // namespace skybake::lut
