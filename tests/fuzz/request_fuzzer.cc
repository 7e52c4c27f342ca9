// libFuzzer target: the query handlers of geodexd (server/queries.h) on arbitrary requests, against
// an in-process mesh store with two small meshes ("meshes/hills" and its id) and a DEM's mesh
// ("meshes/dem", with its map: map points, DeriveMesh's GeoJSON polygons, ExportGis). Byte 0 picks
// the method from the service's own table (GeodexService::Methods, so a new method is fuzzed
// without a change here); the rest is parsed as that method's request message. Every outcome must
// be an answer or a status, never a crash; streamed results are drained. Solves are bounded by a
// window budget.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

#include "absl/strings/str_cat.h"
#include "field_cache.h"
#include "geodex/cancel.h"
#include "geodex/mesh_id.h"
#include "geodex/mesh_io.h"
#include "geodex/terrain.h"
#include "geodex_service.h"
#include "mesh_store.h"
#include "ogr_spatialref.h"
#include "queries.h"
#include "service_limits.h"

namespace {

using namespace geodex;
using namespace geodex::server;

std::string Grid(int n) {
  std::string off = absl::StrCat("OFF\n", (n + 1) * (n + 1), " ", 2 * n * n, " 0\n");
  for (int j = 0; j <= n; ++j) {
    for (int i = 0; i <= n; ++i) absl::StrAppend(&off, i, " ", j, " ", (i * j) % 3 * 0.25, "\n");
  }
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const int a = j * (n + 1) + i;
      absl::StrAppend(&off, "3 ", a, " ", a + 1, " ", a + n + 2, "\n3 ", a, " ", a + n + 2, " ",
                      a + n + 1, "\n");
    }
  }
  return off;
}

struct World {
  MeshStore store{uint64_t{1} << 30};
  FieldCache cache{uint64_t{16} << 20};
  ServiceLimits limits;
  ServiceCounters counters;
  World() {
    limits.max_windows = 100000;
    // Travel-cost solves grow as k^2 links per face: a fuzzed tiny epsilon on the grid must stay
    // well inside the per-input timeout under the sanitizers, as max_windows bounds the exact one.
    limits.max_steiner_points = 20000;
    limits.max_sources = 64;
    limits.max_targets = 64;
    limits.max_levels = 16;
    limits.max_output_values = 10000;
    limits.stream_chunk_bytes = 4096;
    for (int n : {6, 9}) {
      MeshData data = *ReadMeshFromBuffer(Grid(n), MeshFormat::kOff, "grid.off");
      auto mesh = MakeStoredMesh(ComputeMeshId(data), *TriangleMesh::Build(data));
      if (n == 6) mesh->display_name = "hills";
      (void)store.Insert(std::move(mesh));
    }
    // A 6 x 6 DEM of 10 m cells in UTM 33N: its cell centres, two triangles per block.
    MeshData grid;
    for (int j = 0; j < 6; ++j) {
      for (int i = 0; i < 6; ++i) {
        grid.positions.insert(grid.positions.end(),
                              {500005.0 + 10 * i, 4999995.0 - 10 * j, 0.5 * i * j});
      }
    }
    for (uint32_t j = 0; j < 5; ++j) {
      for (uint32_t i = 0; i < 5; ++i) {
        const uint32_t a = j * 6 + i, b = a + 1, c = a + 6, d = a + 7;
        grid.faces.insert(grid.faces.end(), {a, c, d, a, d, b});
      }
    }
    terrain::DemInfo info;
    info.raster_width = info.raster_height = info.grid_width = info.grid_height = 6;
    info.geotransform = {500000, 10, 0, 5000000, 0, -10};
    OGRSpatialReference utm;
    utm.importFromEPSG(32633);
    char* wkt = nullptr;
    utm.exportToWkt(&wkt);
    info.file_crs_wkt = info.mesh_crs_wkt = wkt;
    CPLFree(wkt);
    auto dem = std::make_shared<const terrain::Dem>(*terrain::Dem::FromMesh(grid, info));
    auto mesh = MakeStoredMesh(ComputeMeshId(grid), *TriangleMesh::Build(grid), dem);
    mesh->display_name = "dem";
    (void)store.Insert(std::move(mesh));
  }
};

// The methods driven: every one of the service's table (GeodexService::Methods) that runs on a
// serialized request, but DeleteMesh, which would empty the world.
const std::vector<const GeodexService::MethodInfo*>& Fuzzed() {
  static const auto* methods = [] {
    auto* out = new std::vector<const GeodexService::MethodInfo*>;
    for (const GeodexService::MethodInfo& m : GeodexService::Methods()) {
      if (m.run_serialized != nullptr && m.name != "DeleteMesh") out->push_back(&m);
    }
    return out;
  }();
  return *methods;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static World* world = new World();
  if (size < 1) return 0;
  CancelToken cancel;
  const QueryEnv env{&world->store, &world->limits, &cancel, &world->cache, &world->counters};
  const std::vector<const GeodexService::MethodInfo*>& methods = Fuzzed();
  (void)methods[data[0] % methods.size()]->run_serialized(
      env, absl::string_view(reinterpret_cast<const char*>(data + 1), size - 1));
  return 0;
}
