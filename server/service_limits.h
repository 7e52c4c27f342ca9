#pragma once

// Request limits of geodexd. Every one is a flag (geodexd_main.cc, docs/service.md, its flag
// table); exceeding one answers RESOURCE_EXHAUSTED with a message naming the flag.

#include <cstddef>
#include <cstdint>

#include "geodex/limits.h"

namespace geodex::server {

struct ServiceLimits {
  uint64_t max_upload_bytes = uint64_t{1} << 30;  // --max_upload_bytes
  uint64_t max_vertices = 20'000'000;             // --max_vertices
  uint64_t max_faces = 40'000'000;                // --max_faces
  uint64_t max_dem_cells = 25'000'000;            // --max_dem_cells (a GeoTIFF upload's cells)
  uint32_t max_names_per_mesh = 16;               // --max_names_per_mesh (display name + aliases)
  uint32_t max_sources = 100'000;                 // --max_sources
  uint32_t max_targets = 50'000;                  // --max_targets (matrix columns, points)
  uint32_t max_levels = 1'000;                    // --max_levels (isolines)
  uint64_t max_output_values = 100'000'000;       // --max_output_values
  // The work budget per solve (windows, or a travel graph's links relaxed; geodex/limits.h);
  // 0 = unlimited. --max_windows
  uint64_t max_windows = kServerDefaultMaxWindows;
  // Steiner points of one travel-cost solve (the weighted engine, about 32 bytes each: 32M is
  // about 1 GiB); 0 = unlimited. --max_steiner_points
  uint64_t max_steiner_points = kDefaultMaxSteinerPoints;
  // Largest unary response (LocatePoints, EstimateDistances, FindShortestPath): clients keep
  // gRPC's default 4 MiB receive limit. --max_unary_response_bytes
  uint64_t max_unary_response_bytes = 4 << 20;
  // Size of one streamed message (fields, matrices, isolines, Voronoi, Delaunay).
  // --stream_chunk_bytes
  uint32_t stream_chunk_bytes = 1 << 20;
};

// The flag (without "--") that sets each limit core enforces for the server.
inline const char* FlagOfLimit(Limit limit) {
  switch (limit) {
    case Limit::kVertices:
      return "max_vertices";
    case Limit::kFaces:
      return "max_faces";
    case Limit::kInputBytes:
      return "max_upload_bytes";
    case Limit::kWindows:
      return "max_windows";
    case Limit::kDemCells:
      return "max_dem_cells";
    case Limit::kSteinerPoints:  // a travel cost's solve (SolverOptions.travel)
      return "max_steiner_points";
  }
  return "unknown";
}

}  // namespace geodex::server
