// libFuzzer target: every mesh reader on arbitrary bytes, then (for what parses) the mesh build and
// a bounded exact solve. Byte 0 picks the format: 0 OFF, 1 OBJ, 2 PLY, 3 STL, 4+ auto-detect.
// Nothing may crash, hang or allocate beyond the read limits.

#include <cstddef>
#include <cstdint>
#include <string>

#include "absl/strings/string_view.h"
#include "geodex/geodesic_solver.h"
#include "geodex/mesh_io.h"
#include "geodex/triangle_mesh.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace geodex;
  if (size < 1) return 0;
  static constexpr MeshFormat kFormats[] = {MeshFormat::kOff, MeshFormat::kObj, MeshFormat::kPly,
                                            MeshFormat::kStl, MeshFormat::kAuto};
  const MeshFormat format = kFormats[data[0] < 4 ? data[0] : 4];
  ReadLimits limits;
  limits.max_vertices = 20000;
  limits.max_faces = 40000;
  absl::StatusOr<MeshData> mesh =
      ReadMeshFromBuffer(absl::string_view(reinterpret_cast<const char*>(data) + 1, size - 1),
                         format, "fuzz.mesh", limits);
  if (!mesh.ok() || mesh->vertex_count() == 0 || mesh->vertex_count() > 2000) return 0;
  absl::StatusOr<TriangleMesh> built = TriangleMesh::Build(*mesh);
  if (!built.ok()) return 0;
  GeodesicOptions options;
  options.max_windows = 200000;  // bounded: a budget error is an answer, not a failure
  (void)ComputeDistanceField(*built, {SurfacePoint::AtVertex(0)}, options);
  return 0;
}
