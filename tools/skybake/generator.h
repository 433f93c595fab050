// pipeline.yaml -> outputs/build.ninja (docs/pipeline.md).
//
// The generated graph:
//  - a regeneration edge (generator = 1, restat = 1, pool = console) whose implicit inputs are
//    every file the generator read and the skybake binary, each also a phony leaf so that
//    deleting one regenerates instead of failing; its implicit outputs are the canonical
//    component files the generator writes (only when their content changes);
//  - one rule per tool with restat = 1 and a depfile, optional launcher prefix, pools;
//  - one edge per product, depending on components (not whole atmosphere files).
// build.ninja and the components are written with WriteFileIfChanged, so a regeneration that
// changes nothing touches nothing. Components that are no longer produced are deleted (the
// generator keeps a list in outputs/.skybake/components.txt).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "stage.h"

namespace skybake {

struct GenerateResult {
  std::filesystem::path build_ninja;  // absolute
  std::string ninja_text;
  std::vector<PlannedEdge> plan;
  bool changed = false;  // build.ninja was rewritten
};

// `tools_dir`: the folder holding the tool binaries (and skybake). With dry_run nothing is
// written (for `skybake graph`).
GenerateResult Generate(const std::filesystem::path& pipeline_yaml, const std::filesystem::path& tools_dir,
                        bool dry_run);

}  // namespace skybake
