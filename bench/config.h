#pragma once

// geodex_bench's command line: every flag of every section (kUsage), parsed into one Config.

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/statusor.h"

namespace geodex::bench {

inline constexpr int kMaxSources = 16;

struct Config {
  std::string meshes_dir;
  bool meshes_dir_given = false;
  std::vector<std::string> mesh_files;
  int sources = 2;
  int repeat = 0;  // 0: 3 below 100k faces, 1 from 100k faces on
  uint64_t cgal_max_faces = 100'000;
  // run_ich: geodex's default exact engine (Method::kExact, "exact" in --methods); run_paper: the
  // paper's ICH with its window tree (Method::kIch, "ich").
  bool run_ich = true, run_dijkstra = true, run_cgal = true, run_paper = false;
  // --terrain: DEM-like grids made here (bumpy, and half exactly flat); --large: also 1M faces.
  bool terrain = false, large = false;
  std::string terrain_dir;  // --terrain-dir: write the grids there and keep them
  // --peer NAME=COMMAND: another exact code, run as `COMMAND MESH SOURCE OUT` (see kUsage).
  std::vector<std::pair<std::string, std::string>> peers;
  std::string markdown;
  double timeout_s = 300;
  double wait_idle_s = 0;
  bool ablation = false;
  bool lambda = false;
  // The targeted-query modes (sections 4 and 5 of the paper).
  bool astar = false, matrix = false, estimate = false;
  uint64_t seed = 2010;  // the random points of --astar, --matrix and --estimate
  int per_group = 12;    // --astar: target points per distance group
  int points = 1000;     // --estimate: face points per mesh
  int batch = 100;       // --estimate: points per ComputeExactDistancesAt call
};

// --astar, --matrix or --estimate.
bool PointQueryMode(const Config& config);

extern const char kUsage[];

// --help prints kUsage and exits 0.
absl::StatusOr<Config> ParseArgs(int argc, char** argv);

}  // namespace geodex::bench
