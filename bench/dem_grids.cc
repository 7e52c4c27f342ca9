#include "dem_grids.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <system_error>

#include "absl/status/status.h"
#include "geodex/mesh_io.h"

namespace geodex::bench {

// A height field on n x n grid points over the unit square, like a DEM: vertex (row, col) has id
// row * n + col, every cell split into two triangles along the same diagonal. The relief is 60
// Gaussian bumps and pits (seeded, so every run makes the same grid). With `flat_share` > 0 every
// height below the flat_share quantile becomes exactly that quantile: a lake or sea stored at one
// level, the flat areas real DEMs have.
MeshData MakeDemGrid(int n, double flat_share, uint64_t seed) {
  struct Bump {
    double x, y, amplitude, width;
  };
  std::vector<Bump> bumps;
  uint64_t state = seed;
  auto uniform = [&]() {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return static_cast<double>(state >> 11) * 0x1.0p-53;
  };
  for (int k = 0; k < 60; ++k) {
    Bump b;
    b.x = uniform();
    b.y = uniform();
    b.amplitude = (uniform() < 0.5 ? -1 : 1) * (0.02 + 0.06 * uniform());
    b.width = 0.03 + 0.07 * uniform();
    bumps.push_back(b);
  }
  MeshData m;
  m.positions.reserve(3 * size_t(n) * n);
  std::vector<double> heights;
  for (int row = 0; row < n; ++row) {
    for (int col = 0; col < n; ++col) {
      const double x = col / double(n - 1), y = row / double(n - 1);
      double z = 0;
      for (const Bump& b : bumps) {
        const double r2 = (x - b.x) * (x - b.x) + (y - b.y) * (y - b.y);
        z += b.amplitude * std::exp(-r2 / (2 * b.width * b.width));
      }
      m.positions.insert(m.positions.end(), {x, y, z});
      heights.push_back(z);
    }
  }
  if (flat_share > 0) {
    std::vector<double> sorted = heights;
    const size_t k = static_cast<size_t>(flat_share * (sorted.size() - 1));
    std::nth_element(sorted.begin(), sorted.begin() + k, sorted.end());
    const double level = sorted[k];
    for (size_t v = 0; v < heights.size(); ++v) {
      m.positions[3 * v + 2] = std::max(heights[v], level);
    }
  }
  m.faces.reserve(6 * size_t(n - 1) * (n - 1));
  for (int row = 0; row + 1 < n; ++row) {
    for (int col = 0; col + 1 < n; ++col) {
      const uint32_t a = row * n + col, b = a + 1, c = a + n, d = c + 1;
      m.faces.insert(m.faces.end(), {a, b, d});
      m.faces.insert(m.faces.end(), {a, d, c});
    }
  }
  return m;
}

// Writes the --terrain grids as OFF files (full double precision, readable by peers) into a fresh
// directory under /tmp; returns their paths.
std::vector<std::string> WriteDemGrids(const Config& config, std::string* dir) {
  std::string out_dir = config.terrain_dir;
  if (out_dir.empty()) {
    char templ[] = "/tmp/geodex_bench_dem_XXXXXX";
    if (mkdtemp(templ) == nullptr) return {};
    out_dir = *dir = templ;  // removed at the end
  } else {
    std::error_code error;
    std::filesystem::create_directories(out_dir, error);
  }
  struct Grid {
    std::string name;
    int n;
    double flat;
  };
  std::vector<Grid> grids = {{"dem-bumpy-88k", 211, 0}, {"dem-half-flat-88k", 211, 0.5}};
  if (config.large) {
    grids.push_back({"dem-bumpy-997k", 707, 0});
    grids.push_back({"dem-half-flat-997k", 707, 0.5});
  }
  std::vector<std::string> paths;
  for (const Grid& g : grids) {
    const std::string path = out_dir + "/" + g.name + ".off";
    if (absl::Status st = WriteMeshOff(path, MakeDemGrid(g.n, g.flat, 2010)); !st.ok()) {
      std::fprintf(stderr, "geodex_bench: %s\n", std::string(st.message()).c_str());
      continue;
    }
    paths.push_back(path);
  }
  return paths;
}

}  // namespace geodex::bench
