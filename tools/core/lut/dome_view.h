// The decoded sky on an upper-hemisphere equirectangular "dome": the fixed views on which the
// runtime (viewer/, the GLSL of viewer/glsl/skybake_runtime.glsl) is checked against the
// reference decoder (lut/decoder.h), written by `lut-pack decode` (docs/runtime.md "Checks").
//
// Pixel (x, y) of a W x H dome, local frame of lut/directions.h (+z zenith, +x the sun's azimuth):
//   azimuth from the sun  phi   = 2 pi (x + 1/2) / W - pi      (-pi .. pi; the sun at the centre column)
//   view zenith           theta = (pi / 2) (y + 1/2) / H       (row 0 at the zenith, row H-1 at the horizon)
//   direction = (sin theta cos phi, sin theta sin phi, cos theta)
#pragma once

#include <array>
#include <utility>
#include <vector>

#include "lut/decoder.h"

namespace skybake::lut {

std::array<double, 3> DomeDirection(int x, int y, int width, int height);

// Linear Rec.2020 radiance (cd/m^2) of the weighted blend sum_k w_k L_k (BlendRadiance) at every
// pixel of a W x H dome for a sun at zenith angle `sun_zenith_rad`: W * H * 3 floats, rows top
// to bottom.
std::vector<float> DecodeDome(const std::vector<std::pair<const SkyLutDecoder*, double>>& weighted, double sun_zenith_rad,
                              int width, int height);

}  // namespace skybake::lut
