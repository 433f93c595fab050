// A stage of the generated pipeline: one tool's rule and its build edges.
//
// Adding a tool to the pipeline = one new file tools/skybake/stage_<tool>.cpp implementing Stage
// plus one line in stages.cpp (docs/pipeline.md, "Adding a stage"). A stage
//   - may own a section of pipeline.yaml (ParseConfig reads it; unknown keys are errors),
//   - declares one Ninja rule per tool with restat = 1 and a depfile (EmitRules),
//   - emits its edges, writing any canonical component files it needs through the context
//     (EmitEdges), so that tools depend on components, not on whole atmosphere files.
// Stages run in the order of stages.cpp; a later stage finds an earlier stage's products through
// the path conventions of paths.h.
#pragma once

#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "io/yaml.h"
#include "ninja_writer.h"
#include "pipeline.h"

namespace skybake {

// One planned edge, for `skybake graph`.
struct PlannedEdge {
  std::string tool;
  std::vector<std::string> outputs;
  std::vector<std::string> inputs;
};

class GenContext {
 public:
  GenContext(const Pipeline& pipeline, std::filesystem::path tools_dir, bool dry_run);

  const Pipeline& pipeline() const { return pipeline_; }
  NinjaWriter& ninja() { return ninja_; }

  // A path as written in build.ninja: relative to the outputs folder (Ninja runs there).
  std::string Rel(const std::filesystem::path& absolute) const;
  // The tool binary, relative to the outputs folder.
  std::string ToolPath(const std::string& tool) const;
  // The command prefix for a tool from pipeline.yaml `launchers` ("" if none), with a space.
  std::string LauncherPrefix(const std::string& tool) const;

  // Writes a generator-owned file under the outputs folder (only if its content changed) and
  // records it as an implicit output of the regeneration edge. `rel` is relative to outputs/.
  // Returns the absolute path.
  std::filesystem::path WriteComponent(const std::filesystem::path& rel, const std::string& content);
  // A file the generator read (an implicit input of the regeneration edge).
  void AddRegenInput(const std::filesystem::path& absolute);

  // Emits a build statement and records it for `skybake graph`.
  void Build(const std::string& tool, const NinjaBuild& build);
  // While set, the edges built are the pipeline's path-traced references: their outputs make up
  // the `validate` phony target (`skybake validate`), and they are default targets only when
  // `in_default` (pipeline.yaml `sky.target`, docs/pipeline.md).
  void SetReferenceEdges(bool references, bool in_default = true) {
    references_ = references;
    references_in_default_ = in_default;
  }
  // Every default target (for `default`) and every reference target (for `validate`).
  const std::vector<std::string>& products() const { return products_; }
  const std::vector<std::string>& references() const { return reference_products_; }
  const std::vector<PlannedEdge>& plan() const { return plan_; }
  const std::vector<std::filesystem::path>& components() const { return components_; }
  const std::vector<std::filesystem::path>& regen_inputs() const { return regen_inputs_; }

 private:
  const Pipeline& pipeline_;
  std::filesystem::path tools_dir_;
  bool dry_run_;
  NinjaWriter ninja_;
  std::vector<std::string> products_, reference_products_;
  bool references_ = false, references_in_default_ = true;
  std::vector<PlannedEdge> plan_;
  std::vector<std::filesystem::path> components_;
  std::vector<std::filesystem::path> regen_inputs_;
};

class Stage {
 public:
  virtual ~Stage() = default;
  // The tool this stage runs, e.g. "profile-import".
  virtual std::string tool() const = 0;
  // Reads this stage's section of pipeline.yaml, if it has one (the map is pipeline.yaml's root;
  // read only your own keys). Problems go to the document's diagnostics.
  virtual void ParseConfig(YamlMap& root) {}
  virtual void EmitRules(GenContext& ctx) const = 0;
  virtual void EmitEdges(GenContext& ctx) const = 0;
};

// The standard rule for a tool: `<launcher><tool> $args --depfile $out.d -o $out $in`, with
// restat, a depfile and `description = <tool> $out`. `pool` may be "".
NinjaRule ToolRule(GenContext& ctx, const std::string& rule_name, const std::string& tool,
                   const std::string& pool);

// All stages, in order (stages.cpp).
std::vector<std::unique_ptr<Stage>> MakeStages();

}  // namespace skybake
