#include "lut/directions.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "lut/gt7_mapping.h"

namespace skybake {

namespace {
constexpr double kPi = std::numbers::pi;
}

const char* DirectionMappingName(DirectionMapping m) {
  return m == DirectionMapping::kFisheye ? "fisheye" : "equirectangular";
}

std::optional<DirectionMapping> ParseDirectionMapping(const std::string& name) {
  if (name == "equirectangular") return DirectionMapping::kEquirectangular;
  if (name == "fisheye") return DirectionMapping::kFisheye;
  return std::nullopt;
}

std::optional<std::array<double, 3>> DirectionGrid::Direction(double u, double v) const {
  double theta = 0.0, phi = 0.0;
  if (mapping == DirectionMapping::kEquirectangular) {
    phi = 2.0 * kPi * (u - 0.5);
    theta = kPi * v;
  } else {
    const double px = 2.0 * u - 1.0, py = 1.0 - 2.0 * v;
    const double r = std::sqrt(px * px + py * py);
    if (r > 1.0) return std::nullopt;
    theta = r * kPi / 2.0;
    phi = std::atan2(py, px);
  }
  return std::array<double, 3>{std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
}

std::optional<std::array<double, 3>> DirectionGrid::TexelDirection(int x, int y) const {
  return Direction((x + 0.5) / width, (y + 0.5) / height);
}

std::optional<std::array<double, 2>> DirectionGrid::Uv(const std::array<double, 3>& d) const {
  const double theta = std::acos(std::clamp(d[2], -1.0, 1.0));
  const double phi = std::atan2(d[1], d[0]);
  if (mapping == DirectionMapping::kEquirectangular) {
    double u = phi / (2.0 * kPi) + 0.5;
    if (u >= 1.0) u -= 1.0;
    return std::array<double, 2>{u, theta / kPi};
  }
  if (theta > kPi / 2.0) return std::nullopt;
  const double r = theta / (kPi / 2.0);
  return std::array<double, 2>{(r * std::cos(phi) + 1.0) / 2.0, (1.0 - r * std::sin(phi)) / 2.0};
}

double DirectionGrid::TexelSolidAngle(int x, int y) const {
  if (mapping == DirectionMapping::kEquirectangular) {
    // Exact: dphi (cos theta0 - cos theta1).
    const double t0 = kPi * y / height, t1 = kPi * (y + 1) / height;
    return 2.0 * kPi / width * (std::cos(t0) - std::cos(t1));
  }
  // Fisheye: theta = r pi/2, so dOmega = sin(theta) dtheta dphi = sin(theta) (pi/2) dr dphi and
  // dpx dpy = r dr dphi -> dOmega = (pi/2) sin(theta)/r dpx dpy; a texel covers (2/W)(2/H).
  const double px = 2.0 * (x + 0.5) / width - 1.0, py = 1.0 - 2.0 * (y + 0.5) / height;
  const double r = std::sqrt(px * px + py * py);
  if (r > 1.0) return 0.0;
  const double theta = r * kPi / 2.0;
  const double jac = r > 1e-12 ? (kPi / 2.0) * std::sin(theta) / r : (kPi / 2.0) * (kPi / 2.0);
  return jac * (2.0 / width) * (2.0 / height);
}

std::string DirectionGrid::Describe() const {
  if (mapping == DirectionMapping::kEquirectangular) {
    return fmt::format(
        "equirectangular {}x{} (full sphere): u = x/W -> azimuth from the sun 2 pi (u - 1/2), v = y/H -> view zenith "
        "angle pi v; texel centres at (x + 1/2, y + 1/2)",
        width, height);
  }
  return fmt::format(
      "fisheye {}x{} (upper hemisphere, azimuthal equidistant): px = 2u - 1, py = 1 - 2v, zenith angle (pi/2) "
      "sqrt(px^2 + py^2), azimuth from the sun atan2(py, px); texel centres at (x + 1/2, y + 1/2)",
      width, height);
}

namespace {
class StaticMapping : public SkyMapping {
 public:
  explicit StaticMapping(const DirectionGrid& g) : g_(g) {}
  std::string Name() const override { return DirectionMappingName(g_.mapping); }
  int width() const override { return g_.width; }
  int height() const override { return g_.height; }
  std::optional<std::array<double, 3>> TexelDirection(int x, int y, double) const override { return g_.TexelDirection(x, y); }
  std::array<int, 2> Mirror(int x, int y) const override {
    return g_.mapping == DirectionMapping::kEquirectangular ? std::array<int, 2>{g_.width - 1 - x, y}
                                                            : std::array<int, 2>{x, g_.height - 1 - y};
  }
  std::string Describe() const override { return g_.Describe(); }

 private:
  DirectionGrid g_;
};
}  // namespace

std::unique_ptr<SkyMapping> MakeStaticMapping(const DirectionGrid& grid) { return std::make_unique<StaticMapping>(grid); }

std::unique_ptr<SkyMapping> MakeSkyMapping(const std::string& name, int width, int height) {
  if (std::optional<DirectionMapping> m = ParseDirectionMapping(name)) return MakeStaticMapping(DirectionGrid{*m, width, height});
  if (name == "gt7") return std::make_unique<gt7::Gt7SkyMapping>(width, height);  // lut-pack (lut/gt7_mapping.h)
  return nullptr;
}

std::vector<std::string> SkyMappingNames() { return {"equirectangular", "fisheye", "gt7"}; }

}  // namespace skybake
