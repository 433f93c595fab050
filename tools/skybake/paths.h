// Where products live under the outputs folder (docs/pipeline.md, "Output layout"). Every path
// here is relative to the outputs folder; stages use these so that a later stage finds an
// earlier stage's products without knowing its internals.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace skybake::paths {

// outputs/<atm>/components/profiles.yaml: the canonical profile component of an atmosphere.
inline std::filesystem::path ProfilesComponent(const std::string& atm) {
  return std::filesystem::path(atm) / "components" / "profiles.yaml";
}
// outputs/<atm>/profiles.exr: profile-import's table.
inline std::filesystem::path Profiles(const std::string& atm) {
  return std::filesystem::path(atm) / "profiles.exr";
}

// outputs/<atm>/components/render.yaml: what the renderers need besides the profiles.
inline std::filesystem::path RenderComponent(const std::string& atm) {
  return std::filesystem::path(atm) / "components" / "render.yaml";
}
// outputs/<atm>/sky.exr and sky.png: sky-render's render and preview.
inline std::filesystem::path Sky(const std::string& atm) { return std::filesystem::path(atm) / "sky.exr"; }
inline std::filesystem::path SkyPreview(const std::string& atm) { return std::filesystem::path(atm) / "sky.png"; }

// outputs/<atm>/lut_sky.exr: sky-render's render on the GT7 mappings for lut-pack.
inline std::filesystem::path LutRender(const std::string& atm) { return std::filesystem::path(atm) / "lut_sky.exr"; }
// outputs/<atm>/lut_quality.yaml: sky-render choose's settings of that render (quality: auto).
inline std::filesystem::path LutQuality(const std::string& atm) { return std::filesystem::path(atm) / "lut_quality.yaml"; }
// outputs/luts/report.json: lut-pack's report; the set's files lie beside it (LutFile).
inline std::filesystem::path LutReport() { return std::filesystem::path("luts") / "report.json"; }
inline std::filesystem::path LutFile(const std::string& name) { return std::filesystem::path("luts") / name; }
// The files lut-pack writes per basis sky and per set (tools/lut-pack/outputs.h).
inline std::vector<std::string> LutSkyFiles(const std::string& sky) {
  return {"sky_" + sky + ".ktx2", "sky_" + sky + "_array.ktx2", "sky_" + sky + ".dds", "sky_" + sky + ".exr"};
}
inline std::vector<std::string> LutSetFiles() {
  return {"transmittance.ktx2", "transmittance.dds", "sun.ktx2", "sun.dds", "ambient.ktx2", "ambient.dds", "other_luts.exr",
          "display.json", "contact_sheet.png"};
}

// outputs/<atm>/fog.exr: sky-render fog (the reference fog of the low atmosphere) for fog-fit.
inline std::filesystem::path FogRender(const std::string& atm) { return std::filesystem::path(atm) / "fog.exr"; }
// outputs/fog/fog_<sky>.json: fog-fit's parameter file; the sky's other fog products lie beside it.
inline std::filesystem::path FogParams(const std::string& sky) { return std::filesystem::path("fog") / ("fog_" + sky + ".json"); }
inline std::filesystem::path FogFile(const std::string& name) { return std::filesystem::path("fog") / name; }
// The files fog-fit writes per basis sky besides the parameter file (fog/fog_luts.h FogProductFiles).
inline std::vector<std::string> FogSkyFiles(const std::string& sky) {
  const std::string p = "fog_" + sky;
  return {p + ".ktx2",          p + "_array.ktx2",      p + ".dds",           p + "_shadowed.ktx2",
          p + "_shadowed_array.ktx2", p + "_shadowed.dds", p + "_attenuation.ktx2", p + "_attenuation.dds",
          p + "_params.ktx2",   p + ".exr",             p + "_report.json",   p + "_residuals.exr",
          p + "_residuals.png"};
}

// outputs/components/particles/<type>.yaml: the canonical component of a particle type (its
// file's stem), shared by every atmosphere that uses the type.
inline std::filesystem::path ParticleComponent(const std::string& type) {
  return std::filesystem::path("components") / "particles" / (type + ".yaml");
}
// outputs/mie/<type>.exr: mie-tables' table of a particle type (optics/mie_table.h).
inline std::filesystem::path MieTable(const std::string& type) {
  return std::filesystem::path("mie") / (type + ".exr");
}
// outputs/mie/<type>.report.json: its report (quadrature counts, convergence, fit errors).
inline std::filesystem::path MieReport(const std::string& type) {
  return std::filesystem::path("mie") / (type + ".report.json");
}

// outputs/clouds/noise/<volume><ext>: noise-gen's volume (the recipe file's stem), ext ".ktx2"
// (the product), ".exr" (float field) or ".png" (slice montage).
inline std::filesystem::path CloudNoise(const std::string& volume, const std::string& ext) {
  return std::filesystem::path("clouds") / "noise" / (volume + ext);
}
// outputs/clouds/cumulus_map_t<time>s<ext>: cumulus-map's map at `time` seconds (shortest
// round-trip decimal, e.g. "600"), ext ".ktx2", ".exr" or ".png".
inline std::filesystem::path CumulusMap(const std::string& time_s, const std::string& ext) {
  return std::filesystem::path("clouds") / ("cumulus_map_t" + time_s + "s" + ext);
}
// outputs/clouds/coverage<ext>: cumulus-map's coverage texture.
inline std::filesystem::path CoverageTexture(const std::string& ext) {
  return std::filesystem::path("clouds") / ("coverage" + ext);
}

}  // namespace skybake::paths
