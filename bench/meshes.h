#pragma once

// The meshes of a run: each is loaded once by a baseline child (that only loads it), which gives
// its description, its sources and the resident size of the loaded mesh that every measurement on
// it is compared with.

#include <cstdint>
#include <string>
#include <vector>

#include "child_tasks.h"
#include "config.h"
#include "harness/table.h"

namespace geodex::bench {

struct MeshInfo {
  std::string path, name;
  ChildReport report;       // from the baseline child
  int64_t baseline_rss_kb;  // its ru_maxrss: the loaded mesh, resident
  std::vector<uint32_t> sources;
};

// The baseline child of every mesh file, in order of faces then name; a mesh that fails to load
// is skipped with a line on stdout.
std::vector<MeshInfo> LoadMeshes(const Config& config, const std::vector<std::string>& paths);

// The "Meshes" section, printed before every other.
Section MeshSection(const std::vector<MeshInfo>& meshes);

// --repeat, else 3 below 100k faces and 1 from 100k faces on.
int RepeatFor(const Config& config, const MeshInfo& mesh);

// The meshes a targeted-query mode runs on: all given --mesh files, else its defaults.
std::vector<const MeshInfo*> ModeMeshes(const Config& config, const std::vector<MeshInfo>& meshes,
                                        const std::vector<std::string>& defaults);

// The outcome's peak RSS over the mesh's baseline, in MiB.
std::string DeltaMiB(const Outcome& o, const MeshInfo& mesh);

}  // namespace geodex::bench
