#pragma once

// The header of a mesh file in the data directory (mesh_disk.h): a MeshRecord in geodexd's own
// versioned binary layout, private to storage, so the public API can change without touching
// stored meshes.
//
// Version 2, integers and doubles little-endian, strings as uint32 length + bytes:
//   string id, string display_name, uint32 alias count, that many strings,
//   uint64 vertex_count, face_count, upload_bytes, memory_bytes, uint8 pinned,
//   int64 create time (Unix nanoseconds),
//   the summary: uint64 x 14 (MeshReport's counts in declaration order), uint64 internal_vertices,
//   float64 mean_edge_length, max_edge_length, bbox_min[3], bbox_max[3], uint64 bytes.
// Version 3 appends the terrain: uint8 1 when the mesh is a DEM's, then DemInfo's
//   fields in declaration order (strings as above, uint32 sizes, uint64 counts, uint8 reprojected,
//   float64 scales and the 6 geotransform values); uint8 0 otherwise. Version 2 is read as
//   version 3 without a terrain.
// Version 4 (current) appends to a terrain the adaptive TIN's float64 z_tolerance,
//   max_vertical_deviation and rms_vertical_deviation (0 for a grid); version 3 reads as 0.
// Version 1 files (written before this layout) hold a serialized geodex.v1.Mesh; they are still
// read, and rewritten in the current version when their header next changes.

#include <cstdint>
#include <string>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "mesh_record.h"

namespace geodex::server {

inline constexpr uint32_t kMeshFileVersion = 4;

std::string EncodeMeshFileHeader(const MeshRecord& record);
// DataLoss("corrupt header", ...) when the bytes do not hold a whole header of that version, or
// the version is unknown.
absl::StatusOr<MeshRecord> DecodeMeshFileHeader(uint32_t version, absl::string_view bytes);

}  // namespace geodex::server
