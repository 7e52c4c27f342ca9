#pragma once

// What geodexd knows about a stored mesh besides the mesh itself: its names, sizes, pin and build
// summary. The mesh store keeps one per mesh (resident or not), the data directory stores it as
// each file's header (mesh_file_header.h), and the Mesh resource shows it (proto_convert.h).

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "absl/time/time.h"
#include "geodex/terrain.h"
#include "geodex/triangle_mesh.h"

namespace geodex::server {

struct MeshRecord {
  std::string id;                    // SHA-256 hex of the canonical encoding (geodex/mesh_id.h)
  std::string display_name;          // optional alias
  std::vector<std::string> aliases;  // further aliases (re-uploads under other names)
  uint64_t vertex_count = 0;         // file vertices
  uint64_t face_count = 0;
  uint64_t upload_bytes = 0;
  uint64_t memory_bytes = 0;  // mesh + locator, counted against the budget
  bool pinned = false;
  absl::Time create_time;
  // The build report and geometry (kept so that records answer GetMesh without loading).
  MeshSummary summary;
  // A mesh made from a DEM (a GeoTIFF upload): its map, for map points and GIS outputs.
  std::optional<terrain::DemInfo> terrain;
};

}  // namespace geodex::server
