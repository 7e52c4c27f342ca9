#pragma once

// The programs of geodex_bench, one file each. Main (geodex_bench.cc) runs the ones the flags ask
// for, in this order, after the "Meshes" section (meshes.h), and prints what they return:
//
//   engine_table.cc  (no mode flag)  ICH vs Dijkstra vs CGAL, and --peer codes
//   ablation.cc      --ablation      Lemma 1 (one angle one split) and Lemma 2 (filter) on and off
//   lambda.cc        --lambda        the precision knob lambda (section 7)
//   astar.cc         --astar         exact paths: A* vs the full field (section 5, Table 2)
//   matrix.cc        --matrix        a distance matrix vs full fields vs A* queries
//   estimate.cc      --estimate      the unfolding estimate at surface points (section 4, Table 1)
//
// The tasks their children run are declared in child_tasks.h and defined next to the section.

#include <string>
#include <vector>

#include "config.h"
#include "harness/table.h"
#include "meshes.h"

namespace geodex::bench {

std::vector<Section> RunEngineTable(const Config& config, const std::vector<MeshInfo>& meshes);
std::vector<Section> RunAblation(const Config& config, const std::vector<MeshInfo>& meshes);
std::vector<Section> RunLambda(const Config& config, const std::vector<MeshInfo>& meshes);
std::vector<Section> RunAstar(const Config& config, const std::vector<MeshInfo>& meshes);
std::vector<Section> RunMatrix(const Config& config, const std::vector<MeshInfo>& meshes);
std::vector<Section> RunEstimate(const Config& config, const std::vector<MeshInfo>& meshes);

// Without --mesh, each targeted-query mode takes these meshes from the mesh directory.
const std::vector<std::string>& AstarMeshes();
const std::vector<std::string>& MatrixMeshes();
const std::vector<std::string>& EstimateMeshes();

}  // namespace geodex::bench
