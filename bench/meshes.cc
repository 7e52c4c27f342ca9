#include "meshes.h"

#include <algorithm>
#include <cstdio>
#include <utility>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "harness/cli.h"

namespace geodex::bench {

std::vector<MeshInfo> LoadMeshes(const Config& config, const std::vector<std::string>& paths) {
  std::vector<MeshInfo> meshes;
  for (const std::string& path : paths) {
    Job job;
    job.task = Task::kInfo;
    job.path = path;
    job.sources_wanted = config.sources;
    const Outcome o = RunChild(job, config.timeout_s, 0);
    if (!o.ok()) {
      std::printf("skipping %s: %s\n", path.c_str(),
                  o.message.empty() ? o.StatusText().c_str() : o.message.c_str());
      continue;
    }
    MeshInfo info;
    info.path = path;
    info.name = MeshName(path);
    info.report = o.report;
    info.baseline_rss_kb = o.maxrss_kb;
    info.sources.assign(o.report.sources, o.report.sources + o.report.source_count);
    meshes.push_back(std::move(info));
  }
  std::sort(meshes.begin(), meshes.end(), [](const MeshInfo& a, const MeshInfo& b) {
    return a.report.faces != b.report.faces ? a.report.faces < b.report.faces : a.name < b.name;
  });
  return meshes;
}

Section MeshSection(const std::vector<MeshInfo>& meshes) {
  Section s{"Meshes",
            "Baseline child per mesh: read + TriangleMesh::Build, nothing else. \"resident\" is "
            "the RSS once loaded (the baseline subtracted from every measurement), \"load peak\" "
            "the high-water mark while loading.",
            Table({"mesh", "vertices", "faces", "components", "largest comp. faces", "saddles",
                   "boundary vertices", "sources", "load ms", "resident MiB", "load peak MiB"},
                  "lrrrrrrlrrr"),
            {}};
  for (const MeshInfo& m : meshes) {
    s.table.AddRow({m.name, Count(m.report.file_vertices), Count(m.report.faces),
                    Count(m.report.components), Count(m.report.largest_component_faces),
                    Count(m.report.saddles), Count(m.report.boundary_vertices),
                    absl::StrJoin(m.sources, ", "), Ms(m.report.load_ms),
                    MiBOfKb(m.baseline_rss_kb), MiBOfKb(m.report.load_peak_kb)});
    if (!m.report.hiwater_reset) {
      s.notes.push_back(absl::StrCat(m.name,
                                     ": /proc/self/clear_refs could not reset the RSS "
                                     "high-water mark; RSS peaks include the load peak"));
    }
  }
  return s;
}

int RepeatFor(const Config& config, const MeshInfo& mesh) {
  if (config.repeat > 0) return config.repeat;
  return mesh.report.faces < 100'000 ? 3 : 1;
}

std::vector<const MeshInfo*> ModeMeshes(const Config& config, const std::vector<MeshInfo>& meshes,
                                        const std::vector<std::string>& defaults) {
  std::vector<const MeshInfo*> out;
  for (const MeshInfo& m : meshes) {
    if (!config.mesh_files.empty() ||
        std::find(defaults.begin(), defaults.end(), m.name) != defaults.end()) {
      out.push_back(&m);
    }
  }
  return out;
}

std::string DeltaMiB(const Outcome& o, const MeshInfo& mesh) {
  return MiBOfKb(o.maxrss_kb - mesh.baseline_rss_kb);
}

}  // namespace geodex::bench
