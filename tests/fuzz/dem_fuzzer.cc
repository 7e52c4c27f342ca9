// libFuzzer target: what geodexd does with an uploaded GeoTIFF (MESH_FORMAT_GEOTIFF), on arbitrary
// bytes: GDAL's GTiff driver under a cell limit, then (for what reads) the stored-mesh round trip
// (Dem::FromMesh) and map points dropped at the grid's corners and centre. Byte 0 is the step, and
// from bit 2 up a z tolerance (0: the grid; else an adaptive TIN, holes and all).
// Nothing may crash, hang or allocate beyond the limit.

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>

#include "cpl_conv.h"
#include "geodex/terrain.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  // GDAL's block cache defaults to 5% of RAM: keep it small, and register the drivers (and GDAL's
  // per-thread state) before the first input so they are not counted as its leaks.
  CPLSetConfigOption("GDAL_CACHEMAX", "32");
  (void)geodex::terrain::Dem::ReadGeoTiffBytes(std::string("II*\0\0\0\0\0", 8), "warm-up");
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace geodex::terrain;
  if (size < 1) return 0;
  DemOptions options;
  options.step = 1 + data[0] % 4;
  options.z_tolerance = (data[0] >> 2) * 0.25;
  options.max_cells = 1 << 16;
  const std::string bytes(reinterpret_cast<const char*>(data) + 1, size - 1);
  absl::StatusOr<Dem> dem = Dem::ReadGeoTiffBytes(bytes, "fuzz.tif", options);
  if (!dem.ok()) return 0;
  absl::StatusOr<Dem> stored = Dem::FromMesh(dem->mesh(), dem->info());
  if (!stored.ok()) {
    // On stdout: scripts/fuzz.sh closes the target's stderr (-close_fd_mask=2), and the reason is
    // what a report needs.
    printf("STORED: %s (step %u, z tolerance %g)\n", std::string(stored.status().message()).c_str(),
           options.step, options.z_tolerance);
    fflush(stdout);
    __builtin_trap();
  }  // a mesh the reader made must come back
  const auto& gt = dem->info().geotransform;
  const double w = dem->info().grid_width, h = dem->info().grid_height;
  for (double u : {0.5, w / 2, w - 0.5}) {
    for (double v : {0.5, h / 2, h - 0.5}) {
      (void)stored->DropMapPoint(gt[0] + u * gt[1], gt[3] + v * gt[5]);
    }
  }
  return 0;
}
