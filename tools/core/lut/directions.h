// Direction parametrisations of sky images (docs/sky-render.md, "Directions").
//
// Local frame at the observer: +z is the zenith, +x points to the sun's azimuth (the sun is in
// the x-z half-plane, x > 0 for a sun above or below the horizon), +y completes a right-handed
// frame. A direction is (sin(theta) cos(phi), sin(theta) sin(phi), cos(theta)) with theta the
// view zenith angle and phi the azimuth relative to the sun, counter-clockwise seen from above
// (phi = 0: towards the sun's azimuth; phi = 180 deg: away from it). Radiance is symmetric in phi.
//
//   equirectangular (full sphere): u in [0,1) -> phi = 2 pi (u - 1/2)  (the sun's azimuth in the
//     middle column), v in [0,1] -> theta = pi v (zenith at the top row, nadir at the bottom);
//   fisheye (upper hemisphere, azimuthal equidistant): centred image coordinates
//     px = 2u - 1, py = 1 - 2v, r = sqrt(px^2 + py^2) <= 1, theta = r pi/2, phi = atan2(py, px)
//     (the sun's azimuth to the right, the horizon on the unit circle; texels with r > 1 are
//     outside the mapping).
// Texel (x, y) of a W x H image has its centre at u = (x + 1/2)/W, v = (y + 1/2)/H.
// The GT7 sun-aligned mappings come with lut-pack (lut/gt7_mapping.h).
#pragma once

#include <array>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace skybake {

enum class DirectionMapping { kEquirectangular, kFisheye };

const char* DirectionMappingName(DirectionMapping m);
std::optional<DirectionMapping> ParseDirectionMapping(const std::string& name);

struct DirectionGrid {
  DirectionMapping mapping = DirectionMapping::kEquirectangular;
  int width = 64;
  int height = 32;

  // The direction of texel (x, y)'s centre; nullopt outside the mapping (fisheye corners).
  std::optional<std::array<double, 3>> TexelDirection(int x, int y) const;
  // (u, v) -> direction; nullopt outside the mapping.
  std::optional<std::array<double, 3>> Direction(double u, double v) const;
  // direction (unit) -> (u, v); nullopt for directions the mapping does not cover (fisheye:
  // below the horizon).
  std::optional<std::array<double, 2>> Uv(const std::array<double, 3>& direction) const;
  // Solid angle (sr) of texel (x, y) (exact for equirectangular; for fisheye the area element
  // sin(theta) dtheta dphi mapped by the Jacobian, evaluated at the texel centre).
  double TexelSolidAngle(int x, int y) const;
  // e.g. "equirectangular 64x32: u -> azimuth from the sun ..."; for EXR axis descriptions.
  std::string Describe() const;
};

// A direction parametrisation of a sky image that may depend on the sun's zenith angle (GT7's
// sun-aligned mapping does; equirectangular and fisheye do not). RenderSky renders through this.
class SkyMapping {
 public:
  virtual ~SkyMapping() = default;
  virtual std::string Name() const = 0;
  virtual int width() const = 0;
  virtual int height() const = 0;
  // The direction (local frame above) of texel (x, y)'s centre for a sun at `sun_zenith_rad`;
  // nullopt outside the mapping.
  virtual std::optional<std::array<double, 3>> TexelDirection(int x, int y, double sun_zenith_rad) const = 0;
  // The texel that sees the mirror image of (x, y) in the sun's vertical plane (same radiance),
  // or (x, y) itself when the mapping covers only one side.
  virtual std::array<int, 2> Mirror(int x, int y) const = 0;
  // For axis descriptions and provenance.
  virtual std::string Describe() const = 0;
};

// The sun-independent mappings as SkyMapping.
std::unique_ptr<SkyMapping> MakeStaticMapping(const DirectionGrid& grid);

// Every mapping by name ("equirectangular", "fisheye", and those registered by lut-pack such as
// "gt7"), for sky-render's --mapping; nullptr for an unknown name.
std::unique_ptr<SkyMapping> MakeSkyMapping(const std::string& name, int width, int height);
std::vector<std::string> SkyMappingNames();

}  // namespace skybake
