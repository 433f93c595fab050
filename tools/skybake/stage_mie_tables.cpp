// mie-tables edges: one per distinct particle type referenced by the pipeline's atmospheres
// (`aerosols[].particle`), so a type shared by several atmospheres is computed once (docs/mie.md,
// "Pipeline").
//
//   outputs/components/particles/<type>.yaml   canonical particle type (written here, only when
//                                              its content changes)
//   outputs/mie/<type>.exr, <type>.report.json  mie-tables build, on the pipeline's wavelengths
//
// A type's name is its file's stem; two different files with the same stem are an error. The
// edge depends on the canonical component (not on the atmosphere files), the tool and the
// refractive-index tables, so an edit elsewhere in an atmosphere - or a comment in the particle
// file - does not re-run it. The particle files and their tables are regeneration inputs: the
// generator reads them to validate (file:line) and to write the component.
#include <fmt/format.h>

#include <map>

#include "optics/particle_type.h"
#include "paths.h"
#include "stage.h"

namespace skybake {

namespace {

class MieTablesStage : public Stage {
 public:
  std::string tool() const override { return "mie-tables"; }

  void EmitRules(GenContext& ctx) const override {
    // Each build uses every core: share the heavy-render pool when pipeline.yaml declares it.
    const std::string pool = ctx.pipeline().pools.count("render") ? "render" : "";
    ctx.ninja().Rule(ToolRule(ctx, "mie_tables", tool(), pool));
  }

  void EmitEdges(GenContext& ctx) const override {
    // Distinct particle files by name (sorted: the edges do not depend on atmosphere order).
    std::map<std::string, std::filesystem::path> types;
    Diagnostics diags;
    for (const PipelineAtmosphere& a : ctx.pipeline().atmospheres) {
      for (const AerosolLayerSpec& layer : a.spec.aerosols) {
        if (!layer.particle) continue;
        const std::filesystem::path file = std::filesystem::absolute(*layer.particle).lexically_normal();
        const std::string name = file.stem().string();
        auto [it, inserted] = types.emplace(name, file);
        if (!inserted && it->second != file) {
          diags.Add(FileLoc{a.file.string(), 0},
                    fmt::format("aerosol layer '{}': particle types are named by their file, and {} and {} are both "
                                "named '{}' (rename one)",
                                layer.name, it->second.string(), file.string(), name));
        }
      }
    }
    diags.ThrowIfAny();

    const PipelineWavelengths& wl = ctx.pipeline().wavelengths;
    for (const auto& [name, file] : types) {
      ctx.AddRegenInput(file);
      const mie::ParticleType type = mie::LoadParticleType(file);
      for (const std::filesystem::path& input : type.inputs) ctx.AddRegenInput(input);
      mie::CheckWavelengthCoverage(type, wl.min_nm, wl.max_nm);

      const std::filesystem::path comp_rel = paths::ParticleComponent(name);
      const std::filesystem::path comp_abs = ctx.pipeline().out_dir / comp_rel;
      ctx.WriteComponent(comp_rel, mie::CanonicalParticleYaml(type, comp_abs.parent_path()));

      NinjaBuild b;
      b.outputs = {paths::MieTable(name).generic_string()};
      const std::string report = paths::MieReport(name).generic_string();
      b.implicit_outputs = {report};
      b.rule = "mie_tables";
      b.inputs = {comp_rel.generic_string()};
      b.implicit_inputs = {ctx.ToolPath(tool())};
      for (size_t i = 1; i < type.inputs.size(); ++i) b.implicit_inputs.push_back(ctx.Rel(type.inputs[i]));
      b.variables = {{"args", fmt::format("build --wavelength-min-nm {} --wavelength-max-nm {} --wavelength-step-nm {} "
                                          "--report {}",
                                          FormatExact(wl.min_nm), FormatExact(wl.max_nm), FormatExact(wl.step_nm),
                                          report)}};
      ctx.Build(tool(), b);
    }
  }
};

}  // namespace

std::unique_ptr<Stage> MakeMieTablesStage() { return std::make_unique<MieTablesStage>(); }

}  // namespace skybake
