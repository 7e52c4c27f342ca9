#pragma once

// DEM-like grids made at run time (--terrain): a bumpy terrain and the same with half of it
// exactly flat.

#include <cstdint>
#include <string>
#include <vector>

#include "config.h"
#include "geodex/mesh_data.h"

namespace geodex::bench {

// A height field on n x n grid points over the unit square, like a DEM (see dem_grids.cc).
MeshData MakeDemGrid(int n, double flat_share, uint64_t seed);

// Writes the --terrain grids (and with --large their 1M-face versions) as OFF files into
// config.terrain_dir, or else into a fresh directory under /tmp whose path goes to *dir (for the
// caller to remove); returns their paths.
std::vector<std::string> WriteDemGrids(const Config& config, std::string* dir);

}  // namespace geodex::bench
