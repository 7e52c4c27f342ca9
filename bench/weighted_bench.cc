// weighted_bench: the weighted (travel cost) engine against the exact geodesic engine on one mesh
// from one source vertex. Per epsilon: the solve time, Steiner points, nodes settled, graph edges
// evaluated, peak bytes, and (all weights 1) the largest relative error of the weighted costs
// against the exact distances; then the same solve with a slope friction map (weight 1 + 9 (1 -
// |n_z|) per face: steeper faces cost up to 10x), its time and its ratio to the exact field's.
//
//   weighted_bench MESH [--eps 0.1,0.03,0.01] [--source V] [--no-friction] [--no-unit]
//
// Run it alone (one core per solve; times are wall-clock of one run each).

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "geodex/geodesic_solver.h"
#include "geodex/mesh_io.h"
#include "geodex/triangle_mesh.h"
#include "geodex/weighted_field.h"

namespace {

double Ms(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

std::vector<double> ParseList(const std::string& s) {
  std::vector<double> out;
  size_t at = 0;
  while (at < s.size()) {
    size_t comma = s.find(',', at);
    if (comma == std::string::npos) comma = s.size();
    out.push_back(std::stod(s.substr(at, comma - at)));
    at = comma + 1;
  }
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr,
                 "usage: weighted_bench MESH [--eps 0.1,0.03,0.01] [--source V] [--no-friction] "
                 "[--no-unit]\n");
    return 2;
  }
  const std::string path = argv[1];
  std::vector<double> eps = {0.1, 0.03, 0.01};
  uint32_t source = 0;
  bool friction = true, unit = true;
  for (int i = 2; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--eps" && i + 1 < argc) {
      eps = ParseList(argv[++i]);
    } else if (a == "--source" && i + 1 < argc) {
      source = static_cast<uint32_t>(std::atoi(argv[++i]));
    } else if (a == "--no-friction") {
      friction = false;
    } else if (a == "--no-unit") {
      unit = false;
    } else {
      std::fprintf(stderr, "unknown argument %s\n", a.c_str());
      return 2;
    }
  }
  absl::StatusOr<geodex::MeshData> data = geodex::ReadMeshFile(path);
  if (!data.ok()) {
    std::fprintf(stderr, "%s\n", data.status().ToString().c_str());
    return 1;
  }
  absl::StatusOr<geodex::TriangleMesh> mesh = geodex::TriangleMesh::Build(*data);
  if (!mesh.ok()) {
    std::fprintf(stderr, "%s\n", mesh.status().ToString().c_str());
    return 1;
  }
  const uint32_t nf = static_cast<uint32_t>(data->faces.size() / 3);
  std::printf("mesh %s: %u vertices, %u faces, source vertex %u\n", path.c_str(),
              mesh->file_vertex_count(), nf, source);
  const std::vector<geodex::SurfacePoint> sources = {geodex::SurfacePoint::AtVertex(source)};

  const auto t0 = std::chrono::steady_clock::now();
  absl::StatusOr<geodex::DistanceField> exact = geodex::ComputeDistanceField(*mesh, sources);
  const double exact_ms = Ms(t0);
  if (!exact.ok()) {
    std::fprintf(stderr, "%s\n", exact.status().ToString().c_str());
    return 1;
  }
  std::printf("exact field: %.1f ms\n", exact_ms);

  // Slope friction: 1 + 9 (1 - |n_z|) per file face.
  std::vector<double> slope(nf, 1);
  for (uint32_t f = 0; f < nf; ++f) {
    double p[3][3];
    for (int k = 0; k < 3; ++k) {
      for (int j = 0; j < 3; ++j) p[k][j] = data->positions[3 * data->faces[3 * f + k] + j];
    }
    const double ux = p[1][0] - p[0][0], uy = p[1][1] - p[0][1], uz = p[1][2] - p[0][2];
    const double vx = p[2][0] - p[0][0], vy = p[2][1] - p[0][1], vz = p[2][2] - p[0][2];
    const double nx = uy * vz - uz * vy, ny = uz * vx - ux * vz, nz = ux * vy - uy * vx;
    const double len = std::sqrt(nx * nx + ny * ny + nz * nz);
    slope[f] = len > 0 ? 1 + 9 * (1 - std::fabs(nz) / len) : 1;
  }

  std::printf("%-8s %-9s %10s %8s %12s %12s %14s %10s %12s\n", "eps", "weights", "ms", "x exact",
              "steiner", "settled", "relaxations", "peak MiB", "max rel err");
  for (const double e : eps) {
    for (int pass = 0; pass < 2; ++pass) {
      if (pass == 0 && !unit) continue;
      if (pass == 1 && !friction) continue;
      geodex::WeightedOptions options;
      options.epsilon = e;
      if (pass == 1) options.face_weight = slope;
      const auto t1 = std::chrono::steady_clock::now();
      absl::StatusOr<geodex::WeightedField> w =
          geodex::ComputeWeightedField(*mesh, sources, options);
      const double ms = Ms(t1);
      if (!w.ok()) {
        std::printf("eps %g: %s\n", e, w.status().ToString().c_str());
        continue;
      }
      double worst = 0;
      if (pass == 0) {
        for (size_t v = 0; v < w->cost.size(); ++v) {
          const double d = exact->distance[v];
          if (!(d > 0) || !std::isfinite(d)) continue;
          worst = std::max(worst, std::fabs(w->cost[v] - d) / d);
        }
      }
      std::printf("%-8g %-9s %10.1f %8.1f %12llu %12llu %14llu %10.1f %12s\n", e,
                  pass == 0 ? "1" : "slope", ms, ms / exact_ms,
                  static_cast<unsigned long long>(w->steiner_points),
                  static_cast<unsigned long long>(w->stats.nodes_settled),
                  static_cast<unsigned long long>(w->stats.edge_relaxations),
                  w->stats.peak_bytes / 1048576.0, pass == 0 ? std::to_string(worst).c_str() : "-");
      std::fflush(stdout);
    }
  }
  return 0;
}
