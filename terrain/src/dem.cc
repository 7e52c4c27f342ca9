// Reading a DEM (geodex/terrain.h's Dem): a user's raster file or uploaded GeoTIFF bytes opened
// under geodex's rules, the dataset read into a grid mesh (heights in metres, reprojected to UTM
// when geographic, barriers cut out and friction outlines cut in), and a stored DEM's mesh mapped
// back to its cells (FromMesh). The adaptive TIN is dem_tin.cc; map points map_points.cc; rasters
// rasters.cc.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <memory>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_split.h"
#include "cpl_conv.h"
#include "cpl_string.h"
#include "dem_internal.h"
#include "gdal_priv.h"
#include "gdal_quiet.h"
#include "geodex/geodesic_solver.h"
#include "geodex/limits.h"
#include "geodex/terrain.h"
#include "mem_file.h"
#include "ogr_geometry.h"
#include "ogr_spatialref.h"

namespace geodex::terrain {

using dem_internal::BarrierPolygonsOf;
using dem_internal::CutBarrier;
using dem_internal::CutOutlines;
using dem_internal::DegreesPerUnit;
using dem_internal::FaceFrictionOf;
using dem_internal::FileMeshTransform;
using dem_internal::FrictionRegion;
using dem_internal::InconsistentCrsId;
using dem_internal::JoinCollections;
using dem_internal::LongitudesToGrid;
using dem_internal::MakeTransform;
using dem_internal::OpenBarrierFile;
using dem_internal::OpenUserRaster;
using dem_internal::OutlinesOf;
using dem_internal::ReadFrictionRegions;
using dem_internal::RegionsToMeshFrame;
using dem_internal::SnapOutlinesToVertices;
using dem_internal::TransformPtr;
using dem_internal::WktOf;

Dem::Dem(Dem&&) noexcept = default;
Dem& Dem::operator=(Dem&&) noexcept = default;
Dem::~Dem() = default;

bool IsDemPath(const std::string& path) {
  std::string ext = absl::AsciiStrToLower(std::filesystem::path(path).extension().string());
  for (const char* known :
       {".tif", ".tiff", ".vrt", ".asc", ".img", ".hgt", ".dem", ".bil", ".nc"}) {
    if (ext == known) return true;
  }
  return false;
}

namespace {

// Metres per unit of a band's height unit; 0 when the unit is not one geodex knows.
double MetresPerHeightUnit(std::string unit) {
  unit = absl::AsciiStrToLower(unit);
  if (unit.empty() || unit == "m" || unit == "metre" || unit == "meter" || unit == "metres" ||
      unit == "meters") {
    return 1;
  }
  if (unit == "ft" || unit == "foot" || unit == "feet" || unit == "international foot")
    return 0.3048;
  if (unit == "us survey foot" || unit == "us-ft" || unit == "ftus") return 1200.0 / 3937.0;
  return 0;
}

}  // namespace

namespace dem_internal {

// A user's own raster file (a DEM or a friction raster), through the drivers of the formats
// IsDemPath names, with its side-cars given by name. Not VRT: its sources name files and URLs of
// their own, opened by any driver. Null when none of the drivers reads it (QuietGdal's message).
GDALDatasetUniquePtr OpenUserRaster(const std::string& path) {
  const char* const drivers[] = {"GTiff",   "AAIGrid", "HFA",    "SRTMHGT",
                                 "USGSDEM", "EHdr",    "netCDF", nullptr};
  CPLStringList siblings = SideCarsOf(path);
  return GDALDatasetUniquePtr(GDALDataset::FromHandle(GDALOpenEx(
      path.c_str(), GDAL_OF_RASTER | GDAL_OF_READONLY, drivers, nullptr, siblings.List())));
}

}  // namespace dem_internal

bool IsGeoTiffPath(const std::string& path) {
  const std::string ext = absl::AsciiStrToLower(std::filesystem::path(path).extension().string());
  return ext == ".tif" || ext == ".tiff";
}

bool LooksLikeTiff(const std::string& bytes) {
  return bytes.size() >= 4 && ((bytes[0] == 'I' && bytes[1] == 'I' &&
                                (bytes[2] == 42 || bytes[2] == 43) && bytes[3] == 0) ||
                               (bytes[0] == 'M' && bytes[1] == 'M' && bytes[2] == 0 &&
                                (bytes[3] == 42 || bytes[3] == 43)));
}

absl::Status ValidateDemOptions(const DemOptions& options) {
  if (options.step < 1 || options.step > 1000000) {
    return OptionError("step", absl::StrCat("must be in [1, 1000000], got ", options.step));
  }
  if (std::isnan(options.barrier_below)) return OptionError("barrier_below", "must be a number");
  if (!(options.barrier_width >= 0) || !std::isfinite(options.barrier_width)) {
    return OptionError("barrier_width", "must be a finite number of metres, 0 or more");
  }
  if (!(options.z_tolerance >= 0) || !std::isfinite(options.z_tolerance)) {
    return OptionError("z_tolerance",
                       absl::StrCat("must be a finite height (the DEM's vertical unit), >= 0 (0: "
                                    "the full grid; > 0: a TIN), got ",
                                    options.z_tolerance));
  }
  if (!(options.friction_snap >= 0 && options.friction_snap <= 0.25)) {
    return OptionError("friction_snap",
                       absl::StrCat("must be in [0, 0.25] (a fraction of the shortest edge at a "
                                    "vertex; 0: exact), got ",
                                    options.friction_snap));
  }
  if (options.friction_snap > 0 && options.friction_file.empty()) {
    return OptionError("friction_snap",
                       "snaps friction outlines cut into the mesh (--friction-boundaries exact "
                       "with friction polygons); there are none");
  }
  return absl::OkStatus();
}

absl::StatusOr<Dem> Dem::Read(const std::string& path, const DemOptions& options) {
  if (absl::Status s = ValidateDemOptions(options); !s.ok()) return s;
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) {
    return absl::NotFoundError(absl::StrCat(path, ": cannot open: No such file or directory"));
  }
  QuietGdal quiet;
  // The user's own file (OpenUserRaster); a VRT is refused by name.
  if (absl::EndsWithIgnoreCase(path, ".vrt")) {
    return absl::InvalidArgumentError(absl::StrCat(
        path,
        ": a VRT is not read (its sources may name other files or URLs); make it a GeoTIFF "
        "(gdal_translate in.vrt out.tif)"));
  }
  GDALDatasetUniquePtr ds = OpenUserRaster(path);
  if (ds == nullptr) {
    return absl::InvalidArgumentError(
        absl::StrCat(path, ": not a raster GDAL reads (", QuietGdal::LastMessage(), ")"));
  }
  return ReadDataset(*ds, path, options);
}

absl::StatusOr<Dem> Dem::ReadGeoTiffBytes(const std::string& bytes, const std::string& name,
                                          const DemOptions& options) {
  if (absl::Status s = ValidateDemOptions(options); !s.ok()) return s;
  if (!options.barrier_files.empty()) {
    return absl::InvalidArgumentError("a barrier file is read with the DEM's path, not its bytes");
  }
  if (!LooksLikeTiff(bytes)) {
    return absl::InvalidArgumentError(absl::StrCat(name, ": not a GeoTIFF (no TIFF header)"));
  }
  QuietGdal quiet;
  MemFile tiff(".tif", bytes);
  if (!tiff.ok()) return absl::InternalError("GDAL cannot make an in-memory file");
  // Only the GTiff driver parses untrusted bytes; its georeferencing comes from the file alone
  // (no world file or .aux.xml), and no side-car is listed (PrepareGdal, and an empty sibling
  // list).
  const char* const drivers[] = {"GTiff", nullptr};
  const char* const open_options[] = {"GEOREF_SOURCES=INTERNAL", nullptr};
  const char* const no_siblings[] = {nullptr};
  GDALDatasetUniquePtr ds(GDALDataset::FromHandle(GDALOpenEx(
      tiff.path().c_str(), GDAL_OF_RASTER | GDAL_OF_READONLY, drivers, open_options, no_siblings)));
  if (ds == nullptr) {
    return absl::InvalidArgumentError(
        absl::StrCat(name, ": not a GeoTIFF GDAL reads (", QuietGdal::LastMessage(), ")"));
  }
  // Its CRS may carry PROJ text (a PROJ4 extension, a user-defined citation) naming grid files or
  // +init files, which PROJ would open on the server: refused.
  if (const OGRSpatialReference* srs = ds->GetSpatialRef(); srs != nullptr) {
    if (std::string why = InconsistentCrsId(*srs); !why.empty()) {
      return absl::InvalidArgumentError(absl::StrCat(name, ": ", why));
    }
    char* proj4 = nullptr;
    srs->exportToProj4(&proj4);
    const std::string text = proj4 != nullptr ? proj4 : "";
    CPLFree(proj4);
    for (absl::string_view token : absl::StrSplit(text, ' ', absl::SkipEmpty())) {
      bool names_file = absl::StartsWith(token, "+init=");
      for (const char* key : {"+nadgrids=", "+geoidgrids="}) {
        if (!absl::StartsWith(token, key)) continue;
        for (absl::string_view grid : absl::StrSplit(token.substr(std::strlen(key)), ',')) {
          names_file |= grid != "@null";  // "@null" is no file: the identity
        }
      }
      if (names_file) {
        return absl::InvalidArgumentError(
            absl::StrCat(name, ": its CRS names files (", std::string(token.substr(0, 60)),
                         "); geodex reads no file or URL an upload names"));
      }
    }
  }
  // A GeoTIFF's own metadata can name an overview file (OVERVIEW_FILE in the OVERVIEWS domain),
  // which GDAL opens, path or URL, when overviews are asked for. geodex never asks, and refuses
  // the indirection outright.
  if (CSLCount(ds->GetMetadata("OVERVIEWS")) > 0) {
    return absl::InvalidArgumentError(
        absl::StrCat(name,
                     ": its metadata names an external overview file; geodex reads no file or URL "
                     "an upload names"));
  }
  return ReadDataset(*ds, name, options);
}

absl::StatusOr<Dem> Dem::ReadDataset(GDALDataset& dataset, const std::string& path,
                                     const DemOptions& options) {
  GDALDataset* ds = &dataset;
  auto bad = [&](const std::string& why) {
    return absl::InvalidArgumentError(absl::StrCat(path, ": ", why));
  };
  if (ds->GetRasterCount() != 1) {
    return bad(absl::StrCat("a DEM has one band; this raster has ", ds->GetRasterCount()));
  }
  Dem dem;
  DemInfo& info = dem.info_;
  info.driver = ds->GetDriver() != nullptr ? ds->GetDriver()->GetDescription() : "";
  info.raster_width = static_cast<uint32_t>(ds->GetRasterXSize());
  info.raster_height = static_cast<uint32_t>(ds->GetRasterYSize());
  if (options.max_cells != 0 &&
      uint64_t{info.raster_width} * info.raster_height > options.max_cells) {
    return LimitExceededError(
        Limit::kDemCells,
        absl::StrFormat("%s: %ux%u cells, more than the %u a DEM may have here", path,
                        info.raster_width, info.raster_height, options.max_cells));
  }
  info.step = options.step;
  info.grid_width = (info.raster_width + options.step - 1) / options.step;
  info.grid_height = (info.raster_height + options.step - 1) / options.step;
  if (info.grid_width < 2 || info.grid_height < 2) {
    return bad(absl::StrFormat("%ux%u cells at --dem-step %u; a DEM needs at least 2x2",
                               info.grid_width, info.grid_height, options.step));
  }
  const uint64_t most_vertices = uint64_t{info.grid_width} * info.grid_height;
  const uint64_t most_faces = 2 * uint64_t{info.grid_width - 1} * (info.grid_height - 1);
  if (options.z_tolerance == 0 && options.max_vertices != 0 &&
      most_vertices > options.max_vertices) {
    return LimitExceededError(
        Limit::kVertices,
        absl::StrFormat(
            "%s: %ux%u used cells can make %d vertices, more than the %d a mesh may have here",
            path, info.grid_width, info.grid_height, most_vertices, options.max_vertices));
  }
  if (options.z_tolerance == 0 && options.max_faces != 0 && most_faces > options.max_faces) {
    return LimitExceededError(
        Limit::kFaces,
        absl::StrFormat(
            "%s: %ux%u used cells can make %d faces, more than the %d a mesh may have here", path,
            info.grid_width, info.grid_height, most_faces, options.max_faces));
  }
  double gt[6];
  if (ds->GetGeoTransform(gt) != CE_None) return bad("no geotransform (not georeferenced)");
  if (gt[2] != 0 || gt[4] != 0) return bad("a rotated grid (geotransform terms 2 and 4 not 0)");
  if (!std::all_of(gt, gt + 6, [](double v) { return std::isfinite(v); }) || gt[1] == 0 ||
      gt[5] == 0) {
    return bad("its geotransform is not a grid (a cell size of 0, or not finite)");
  }
  // Cells that doubles cannot tell apart at these coordinates (or, geographic, finer than a
  // centimetre, below what a projection's round trip resolves) make no surface.
  const double reach = std::max({std::abs(gt[0]), std::abs(gt[3]), 1.0});
  if (std::min(std::abs(gt[1]), std::abs(gt[5])) < 1e-9 * reach) {
    return bad(absl::StrFormat("cells of %.3g by %.3g are too small at coordinates near %.6g",
                               std::abs(gt[1]), std::abs(gt[5]), reach));
  }
  const OGRSpatialReference* file_srs = ds->GetSpatialRef();
  if (file_srs == nullptr || file_srs->IsEmpty()) return bad("no coordinate reference system");
  if (std::string why = InconsistentCrsId(*file_srs); !why.empty()) return bad(why);
  OGRSpatialReference file_crs(*file_srs);
  file_crs.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  info.file_crs_name = file_crs.GetName() != nullptr ? file_crs.GetName() : "";
  info.file_crs_wkt = WktOf(file_crs);

  // The used grid: cell centre (i, j) is the file's pixel centre (i step + 0.5, j step + 0.5).
  const double s = options.step;
  const double corner = 0.5 - s / 2;
  info.geotransform = {gt[0] + corner * gt[1], s * gt[1], 0, gt[3] + corner * gt[5], 0, s * gt[5]};

  // Mesh coordinates: metres, in the file's CRS or (geographic) the UTM zone of the centre.
  TransformPtr to_mesh(nullptr, &OGRCoordinateTransformation::DestroyCT);
  if (file_crs.IsGeographic()) {
    if (std::min(std::abs(gt[1]), std::abs(gt[5])) < 1e-7) {
      return bad("cells finer than 1e-7 degrees (about a centimetre)");
    }
    // A prime meridian far from Greenwich (found by dem_fuzzer: 1.1e119 degrees) swallows every
    // longitude's digits: the cells collapse onto one meridian and the mesh cannot be mapped back.
    if (const double meridian = file_crs.GetPrimeMeridian(); !(std::abs(meridian) <= 180)) {
      return bad(absl::StrFormat(
          "a prime meridian %.9g degrees from Greenwich: at most 180 either way", meridian));
    }
    // The grid must be longitudes and latitudes: at most a turn wide, its rows within the poles
    // (its centre alone, wrapped by PROJ, could pass with cells a million degrees wide).
    const double degrees = DegreesPerUnit(info.file_crs_wkt);
    const double width = std::abs(gt[1]) * info.raster_width * degrees;
    const double top = gt[3] * degrees, bottom = (gt[3] + gt[5] * info.raster_height) * degrees;
    if (!(degrees > 0 && width <= 360 && std::abs(top) <= 90 + 1e-9 &&
          std::abs(bottom) <= 90 + 1e-9)) {
      return bad(absl::StrFormat(
          "a longitude/latitude grid %.9g degrees wide, rows from latitude %.9g to %.9g: at most "
          "360 wide, within [-90, 90]",
          width, std::min(top, bottom), std::max(top, bottom)));
    }
    double lon = gt[0] + gt[1] * info.raster_width / 2.0,
           lat = gt[3] + gt[5] * info.raster_height / 2.0;
    OGRSpatialReference wgs84;
    wgs84.SetWellKnownGeogCS("WGS84");
    wgs84.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
    TransformPtr to_wgs84 = MakeTransform(file_crs, wgs84);
    if (to_wgs84 == nullptr || !to_wgs84->Transform(1, &lon, &lat)) {
      return bad(
          absl::StrCat("cannot find the DEM's centre in WGS 84 (", QuietGdal::LastMessage(), ")"));
    }
    // A file may count longitudes 0 to 360 (or -360 to 0): its zone is found a turn away.
    if (!(std::abs(lon) <= 360 && std::abs(lat) <= 90)) {
      return bad(absl::StrFormat(
          "its centre (%.9g, %.9g) is not a longitude (within [-360, 360]) and latitude", lon,
          lat));
    }
    lon = std::remainder(lon, 360.0);
    const int zone = std::clamp(static_cast<int>(std::floor((lon + 180) / 6)) + 1, 1, 60);
    OGRSpatialReference utm;
    utm.importFromEPSG((lat >= 0 ? 32600 : 32700) + zone);
    utm.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
    info.reprojected = true;
    info.mesh_crs_name = utm.GetName() != nullptr ? utm.GetName() : "";
    info.mesh_crs_wkt = WktOf(utm);
    // From the stored texts, as a stored DEM rebuilds it (Dem::FromMesh): the same operation.
    to_mesh = FileMeshTransform(info, /*to_mesh=*/true);
    if (to_mesh == nullptr) {
      return bad(absl::StrCat("cannot project to UTM (", QuietGdal::LastMessage(), ")"));
    }
  } else if (file_crs.IsProjected() || file_crs.IsLocal()) {
    info.horizontal_scale = file_crs.GetLinearUnits();
    if (!(info.horizontal_scale > 0)) return bad("the CRS has no linear unit");
    // A foot-based CRS: the mesh is in metres, in that CRS's frame.
    info.mesh_crs_name = info.horizontal_scale == 1
                             ? info.file_crs_name
                             : absl::StrCat(info.file_crs_name, " (x and y in metres)");
    info.mesh_crs_wkt = info.file_crs_wkt;
  } else {
    return bad("the CRS is neither projected nor geographic");
  }

  GDALRasterBand* band = ds->GetRasterBand(1);
  info.vertical_unit = band->GetUnitType() != nullptr ? band->GetUnitType() : "";
  const double unit = MetresPerHeightUnit(info.vertical_unit);
  if (unit == 0) {
    return bad(
        absl::StrCat("height unit '", info.vertical_unit, "' is not m, ft or US survey foot"));
  }
  int has_scale = 0, has_offset = 0;
  double scale = band->GetScale(&has_scale), offset = band->GetOffset(&has_offset);
  if (!has_scale) scale = 1;
  if (!has_offset) offset = 0;
  info.vertical_scale = unit * scale;
  // Which cells have data: GDAL's mask (the nodata value compared in the band's own type, or a
  // per-dataset mask or alpha band), plus NaN.
  GDALRasterBand* mask = band->GetMaskBand();
  std::vector<uint8_t> valid(info.raster_width);
  if (uint64_t{info.grid_width} * info.grid_height >= kNoVertex) {
    return bad(absl::StrFormat("%ux%u cells: more than a mesh can index; use --dem-step",
                               info.grid_width, info.grid_height));
  }

  // Vertices: the used cells with data, row by row (one file row read at a time).
  const uint32_t W = info.grid_width, H = info.grid_height;
  dem.vertex_of_cell_.assign(size_t{W} * H, kNoVertex);
  std::vector<double> row(info.raster_width);
  std::vector<double> xs, ys;
  uint32_t next = 0;
  for (uint32_t j = 0; j < H; ++j) {
    if (band->RasterIO(GF_Read, 0, static_cast<int>(j * options.step), info.raster_width, 1,
                       row.data(), info.raster_width, 1, GDT_Float64, 0, 0) != CE_None) {
      return bad(absl::StrCat("read error (", QuietGdal::LastMessage(), ")"));
    }
    if (mask->RasterIO(GF_Read, 0, static_cast<int>(j * options.step), info.raster_width, 1,
                       valid.data(), info.raster_width, 1, GDT_Byte, 0, 0) != CE_None) {
      return bad(absl::StrCat("read error in the nodata mask (", QuietGdal::LastMessage(), ")"));
    }
    for (uint32_t i = 0; i < W; ++i) {
      const double raw = row[size_t{i} * options.step];
      if (!std::isfinite(raw) || valid[size_t{i} * options.step] == 0) {
        ++info.nodata_cells;
        continue;
      }
      if ((raw * scale + offset) * unit < options.barrier_below) {
        ++info.barrier_cells;
        continue;
      }
      dem.vertex_of_cell_[size_t{j} * W + i] = next++;
      const double px = (i + 0.5) * info.geotransform[1] + info.geotransform[0];
      const double py = (j + 0.5) * info.geotransform[5] + info.geotransform[3];
      xs.push_back(px);
      ys.push_back(py);
      dem.mesh_.positions.insert(
          dem.mesh_.positions.end(),
          {px * info.horizontal_scale, py * info.horizontal_scale, (raw * scale + offset) * unit});
    }
  }
  if (to_mesh != nullptr && next > 0) {
    std::vector<int> ok(next);
    if (!to_mesh->Transform(static_cast<int>(next), xs.data(), ys.data(), nullptr, ok.data()) ||
        std::find(ok.begin(), ok.end(), 0) != ok.end()) {
      return bad(absl::StrCat("cannot project the cells to ", info.mesh_crs_name));
    }
    for (uint32_t v = 0; v < next; ++v) {
      dem.mesh_.positions[3 * size_t{v}] = xs[v];
      dem.mesh_.positions[3 * size_t{v} + 1] = ys[v];
    }
  }

  // A barrier drawn as polygons: one union in the file's CRS, cut out of the mesh once it is made.
  // Several files add up: their features go into the one collection, as one file holding them all.
  std::unique_ptr<OGRGeometry> barrier;
  const std::string barrier_name = BarrierFilesName(options.barrier_files);
  for (const std::string& path : options.barrier_files) {
    const std::string name = absl::StrCat("--barrier ", path);
    absl::StatusOr<GDALDatasetUniquePtr> file = OpenBarrierFile(path, name);
    if (!file.ok()) return file.status();
    absl::StatusOr<std::unique_ptr<OGRGeometry>> polygons =
        BarrierPolygonsOf(file->get(), name, &file_crs);
    if (!polygons.ok()) return polygons.status();
    barrier = barrier == nullptr ? *std::move(polygons)
                                 : JoinCollections(std::move(barrier), *std::move(polygons));
  }
  // Friction regions: their outlines cut in once the barrier is out (geodex/friction.h).
  std::vector<FrictionRegion> friction_regions;
  const std::string friction_name = absl::StrCat("--friction ", options.friction_file);
  if (!options.friction_file.empty()) {
    absl::StatusOr<GDALDatasetUniquePtr> file =
        OpenBarrierFile(options.friction_file, friction_name);
    if (!file.ok()) return file.status();
    absl::StatusOr<std::vector<FrictionRegion>> regions =
        ReadFrictionRegions(**file, &file_crs, friction_name);
    if (!regions.ok()) return regions.status();
    friction_regions = *std::move(regions);
  }
  std::vector<double> face_friction;  // the cut mesh's (Dem::face_friction)
  // What is drawn on the mesh once it is made: the barrier cut out, then the outlines cut in.
  auto cut_drawn = [&](MeshData mesh) -> absl::StatusOr<MeshData> {
    if (barrier != nullptr) {
      CutStats stats;
      absl::StatusOr<MeshData> cut =
          CutBarrier(mesh, *barrier, &info, &file_crs, options.barrier_width, options.max_vertices,
                     barrier_name, &stats);
      if (!cut.ok()) return cut.status();
      if (cut->faces.empty()) return bad("the barrier covers every face: nothing is left");
      info.barrier_faces = stats.faces_removed + stats.faces_cut;
      mesh = *std::move(cut);
    }
    if (!friction_regions.empty()) {
      // In the mesh's x y, snapped there (friction_snap), cut in, and every face valued from
      // those same shapes: a snapped outline is where the values change.
      if (absl::Status s = RegionsToMeshFrame(friction_regions, info, file_crs, friction_name);
          !s.ok()) {
        return s;
      }
      if (options.friction_snap > 0) {
        SnapOutlinesToVertices(friction_regions, mesh, options.friction_snap);
      }
      CutStats stats;
      absl::StatusOr<MeshData> cut =
          CutOutlines(mesh, *OutlinesOf(friction_regions), /*dem=*/nullptr, /*file_crs=*/nullptr,
                      options.max_vertices, friction_name, &stats);
      if (!cut.ok()) return cut.status();
      absl::StatusOr<std::vector<double>> values =
          FaceFrictionOf(std::move(friction_regions), *cut, /*dem=*/nullptr, friction_name);
      if (!values.ok()) return values.status();
      face_friction = *std::move(values);
      mesh = *std::move(cut);
    }
    return mesh;
  };
  auto made = [&](MeshData drawn) {
    absl::StatusOr<Dem> out = FromMesh(std::move(drawn), info);
    if (out.ok()) out->face_friction_ = std::move(face_friction);
    return out;
  };

  // Faces: per block, corners a (i, j), b (i+1, j), c (i, j+1), d (i+1, j+1), split along a-d:
  // (a, c, d) and (a, d, b), counter-clockwise seen from above when rows run south (gt[5] < 0).
  const bool flip = gt[1] * gt[5] > 0;  // rows run north: mirror the winding
  if (options.z_tolerance > 0) {
    absl::StatusOr<MeshData> tin = BuildTin(dem, options, flip, file_crs, path, &info);
    if (!tin.ok()) return tin.status();
    info.z_tolerance = options.z_tolerance;
    absl::StatusOr<MeshData> drawn = cut_drawn(*std::move(tin));
    if (!drawn.ok()) return drawn.status();
    return made(*std::move(drawn));
  }
  dem.face_of_block_.assign(2 * size_t{W - 1} * (H - 1), kNoVertex);
  for (uint32_t j = 0; j + 1 < H; ++j) {
    for (uint32_t i = 0; i + 1 < W; ++i) {
      const uint32_t a = dem.VertexAt(i, j), b = dem.VertexAt(i + 1, j);
      const uint32_t c = dem.VertexAt(i, j + 1), d = dem.VertexAt(i + 1, j + 1);
      const std::array<std::array<uint32_t, 3>, 2> tris = {{{a, c, d}, {a, d, b}}};
      for (int k = 0; k < 2; ++k) {
        std::array<uint32_t, 3> t = tris[k];
        if (t[0] == kNoVertex || t[1] == kNoVertex || t[2] == kNoVertex) continue;
        if (flip) std::swap(t[1], t[2]);
        dem.face_of_block_[2 * (size_t{j} * (W - 1) + i) + k] =
            static_cast<uint32_t>(dem.mesh_.face_count());
        dem.mesh_.faces.insert(dem.mesh_.faces.end(), t.begin(), t.end());
      }
    }
  }
  if (dem.mesh_.faces.empty()) {
    return bad(info.barrier_cells > 0
                   ? "no 2x2 block of cells above the barrier: nothing to triangulate"
                   : "no 2x2 block of cells with data: nothing to triangulate");
  }
  if (barrier == nullptr && friction_regions.empty()) return dem;
  absl::StatusOr<MeshData> drawn = cut_drawn(dem.mesh_);
  if (!drawn.ok()) return drawn.status();
  return made(*std::move(drawn));
}

absl::StatusOr<std::array<double, 2>> Dem::CellCentreInMesh(uint32_t col, uint32_t row) const {
  const std::array<double, 6>& gt = info_.geotransform;
  double x = gt[0] + (col + 0.5) * gt[1], y = gt[3] + (row + 0.5) * gt[5];
  if (!info_.reprojected)
    return std::array<double, 2>{x * info_.horizontal_scale, y * info_.horizontal_scale};
  QuietGdal quiet;
  TransformPtr t = FileMeshTransform(info_, /*to_mesh=*/true);
  if (t == nullptr || !t->Transform(1, &x, &y)) {
    return absl::InvalidArgumentError("a cell centre does not project to the mesh's CRS");
  }
  return std::array<double, 2>{x, y};
}

absl::StatusOr<Dem> Dem::FromMesh(MeshData mesh, DemInfo info) {
  auto bad = [](const std::string& why) {
    return absl::InvalidArgumentError(absl::StrCat("not the mesh of this DEM: ", why));
  };
  const uint32_t W = info.grid_width, H = info.grid_height;
  const std::array<double, 6>& gt = info.geotransform;
  if (W < 2 || H < 2 || uint64_t{W} * H >= kNoVertex || gt[1] == 0 || gt[5] == 0 ||
      !(info.horizontal_scale > 0)) {
    return bad("its grid is not a DEM's");
  }
  const size_t n = mesh.vertex_count();
  // The grid maps are W x H: bounded by the mesh (a DEM up to 255 of 256 cells without data),
  // whatever a header says.
  // (A TIN's grid may be far larger than its mesh: up to 2^28 cells, 1 GiB of maps.)
  if (info.z_tolerance > 0 ? uint64_t{W} * H > (uint64_t{1} << 28)
                           : uint64_t{W} * H > 256 * (uint64_t{n} + 1) + (uint64_t{1} << 24)) {
    return bad("its grid is far larger than its mesh");
  }
  // Each vertex's map position in the file's CRS.
  std::vector<double> xs(n), ys(n);
  for (size_t v = 0; v < n; ++v) {
    xs[v] = mesh.positions[3 * v];
    ys[v] = mesh.positions[3 * v + 1];
  }
  if (info.reprojected) {
    QuietGdal quiet;
    TransformPtr back = FileMeshTransform(info, /*to_mesh=*/false);
    if (back == nullptr) return bad("its CRS does not parse, or does not project");
    std::vector<int> ok(n);
    if (back == nullptr ||
        (n > 0 &&
         !back->Transform(static_cast<int>(n), xs.data(), ys.data(), nullptr, ok.data())) ||
        std::find(ok.begin(), ok.end(), 0) != ok.end()) {
      return bad("its vertices do not project back to the file's CRS");
    }
    LongitudesToGrid(info, xs.data(), n);
  } else {
    for (size_t v = 0; v < n; ++v) {
      xs[v] /= info.horizontal_scale;
      ys[v] /= info.horizontal_scale;
    }
  }
  // Reprojected, which cell centre a vertex is at is decided in the mesh's metres: its nearest
  // centre, projected forward as the reader projected it, must be where the vertex is (0.1 mm).
  // The way back only finds the candidate: between datums (WGS 72 to WGS 84's UTM) PROJ's 2D
  // round trip is off by up to 1e-10 degrees, a thousandth of the finest cell the reader takes.
  std::vector<char> at_centre(n, 0);
  if (info.reprojected) {
    std::vector<double> cx(n), cy(n);
    for (size_t v = 0; v < n; ++v) {
      const double u = (xs[v] - gt[0]) / gt[1] - 0.5, w = (ys[v] - gt[3]) / gt[5] - 0.5;
      cx[v] = gt[0] + (std::round(u) + 0.5) * gt[1];
      cy[v] = gt[3] + (std::round(w) + 0.5) * gt[5];
    }
    QuietGdal quiet;
    TransformPtr forward = FileMeshTransform(info, /*to_mesh=*/true);
    std::vector<int> ok(n);
    if (forward == nullptr || (n > 0 && !forward->Transform(static_cast<int>(n), cx.data(),
                                                            cy.data(), nullptr, ok.data()))) {
      return bad("its cell centres do not project to the mesh's CRS");
    }
    for (size_t v = 0; v < n; ++v) {
      at_centre[v] = ok[v] && std::abs(cx[v] - mesh.positions[3 * v]) < 1e-4 &&
                     std::abs(cy[v] - mesh.positions[3 * v + 1]) < 1e-4;
    }
  }
  Dem dem;
  dem.vertex_of_cell_.assign(size_t{W} * H, kNoVertex);
  // The cells' vertices come first, in row order; after them, a barrier cut's (at no cell centre).
  std::vector<uint32_t> cell_of_vertex(n, kNoVertex);
  size_t previous = 0, cells = 0;
  for (size_t v = 0; v < n; ++v) {
    const double u = (xs[v] - gt[0]) / gt[1] - 0.5, w = (ys[v] - gt[3]) / gt[5] - 0.5;
    const double i = std::round(u), j = std::round(w);
    // A cell centre to far better than a cell (in the file's own units, exact to ~1e-12 of one).
    const bool near =
        info.reprojected ? at_centre[v] != 0 : std::abs(u - i) < 1e-6 && std::abs(w - j) < 1e-6;
    const bool centre = near && i >= 0 && j >= 0 && i < W && j < H;
    const size_t cell = centre ? static_cast<size_t>(j) * W + static_cast<size_t>(i) : 0;
    if (!centre || (v > 0 && cell <= previous)) {
      if (v == 0) return bad("vertex 0 is not at a cell centre");
      break;
    }
    previous = cell;
    dem.vertex_of_cell_[cell] = static_cast<uint32_t>(v);
    cell_of_vertex[v] = static_cast<uint32_t>(cell);
    ++cells;
  }
  for (size_t v = cells; v < n; ++v) {  // a cut's vertices lie within the grid, at no cell centre
    const double u = (xs[v] - gt[0]) / gt[1] - 0.5, w = (ys[v] - gt[3]) / gt[5] - 0.5;
    const double slack = info.reprojected ? 1e-2 : 1e-6;  // the way back's error, as above
    if (!(u >= -slack && w >= -slack && u <= W - 1 + slack && w <= H - 1 + slack)) {
      return bad(absl::StrCat("vertex ", v, " is outside the grid"));
    }
    // On the grid a cut's vertex is at a cell centre only as a copy of that cell's vertex (a line
    // barrier's two sides); on a TIN also where a hole's outline turns (most cells are no vertex).
    const bool near =
        info.reprojected ? at_centre[v] != 0
                         : std::abs(u - std::round(u)) < 1e-6 && std::abs(w - std::round(w)) < 1e-6;
    if (info.z_tolerance == 0 && near) {
      const size_t cell =
          static_cast<size_t>(std::round(w)) * W + static_cast<size_t>(std::round(u));
      const uint32_t original =
          std::round(u) < W && std::round(w) < H ? dem.vertex_of_cell_[cell] : kNoVertex;
      if (original == kNoVertex || !std::equal(&mesh.positions[3 * v], &mesh.positions[3 * v] + 3,
                                               &mesh.positions[3 * size_t{original}])) {
        return bad(absl::StrCat("vertex ", v, " is out of row order"));
      }
    }
  }
  if (info.z_tolerance > 0) {  // an adaptive TIN: its faces are not blocks
    dem.cell_uv_.resize(n);
    for (size_t v = 0; v < n; ++v) {
      dem.cell_uv_[v] = {(xs[v] - gt[0]) / gt[1] - 0.5, (ys[v] - gt[3]) / gt[5] - 0.5};
    }
    dem.mesh_ = std::move(mesh);
    dem.info_ = std::move(info);
    if (absl::Status mapped = dem.MapTin(); !mapped.ok()) return bad(std::string(mapped.message()));
    return dem;
  }
  dem.face_of_block_.assign(2 * size_t{W - 1} * (H - 1), kNoVertex);
  std::vector<std::pair<uint64_t, uint32_t>> pieces;  // (block triangle, face) of a cut's faces
  for (size_t f = 0; f < mesh.face_count(); ++f) {
    uint32_t ci[3], cj[3];
    bool on_cells = true;
    for (int c = 0; c < 3; ++c) {
      const uint32_t v = mesh.faces[3 * f + c];
      if (v >= n) return bad(absl::StrCat("face ", f, " has no vertex ", v));
      on_cells &= cell_of_vertex[v] != kNoVertex;
      ci[c] = on_cells ? cell_of_vertex[v] % W : 0;
      cj[c] = on_cells ? cell_of_vertex[v] / W : 0;
    }
    if (!on_cells) {
      // A piece of a cut face: filed under the block triangle that holds its centre, found again
      // by DropMeshPoint among that triangle's neighbours too.
      double u = 0, w = 0;
      for (int c = 0; c < 3; ++c) {
        const uint32_t v = mesh.faces[3 * f + c];
        u += ((xs[v] - gt[0]) / gt[1] - 0.5) / 3;
        w += ((ys[v] - gt[3]) / gt[5] - 0.5) / 3;
      }
      const uint32_t i = static_cast<uint32_t>(std::clamp(std::floor(u), 0.0, W - 2.0));
      const uint32_t j = static_cast<uint32_t>(std::clamp(std::floor(w), 0.0, H - 2.0));
      const int k = (w - j) >= (u - i) ? 0 : 1;  // (a, c, d) below the a-d diagonal, else (a, d, b)
      pieces.push_back({2 * (uint64_t{j} * (W - 1) + i) + k, static_cast<uint32_t>(f)});
      continue;
    }
    const uint32_t i = std::min({ci[0], ci[1], ci[2]}), j = std::min({cj[0], cj[1], cj[2]});
    // (a, c, d) has the block's lower-left corner c (i, j + 1); (a, d, b) its b (i + 1, j).
    int k = -1, corners = 0;
    for (int c = 0; c < 3; ++c) {
      const uint32_t di = ci[c] - i, dj = cj[c] - j;
      if (di > 1 || dj > 1) break;
      corners |= 1 << (di + 2 * dj);  // a 1, b 2, c 4, d 8
    }
    if (corners == (1 | 4 | 8)) k = 0;
    if (corners == (1 | 8 | 2)) k = 1;
    if (k < 0 || i + 1 >= W || j + 1 >= H) {
      return bad(absl::StrCat("face ", f, " is not one of a block's two triangles"));
    }
    uint32_t& slot = dem.face_of_block_[2 * (size_t{j} * (W - 1) + i) + k];
    if (slot != kNoVertex) return bad(absl::StrCat("face ", f, " repeats face ", slot));
    slot = static_cast<uint32_t>(f);
  }
  std::sort(pieces.begin(), pieces.end());
  dem.pieces_ = std::move(pieces);
  dem.mesh_ = std::move(mesh);
  dem.info_ = std::move(info);
  return dem;
}

}  // namespace geodex::terrain
