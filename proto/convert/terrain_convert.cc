#include "terrain_convert.h"

namespace geodex::api {

void TerrainToProto(const terrain::DemInfo& info, v1::Terrain* out) {
  out->set_driver(info.driver);
  out->set_raster_width(info.raster_width);
  out->set_raster_height(info.raster_height);
  out->set_step(info.step);
  out->set_grid_width(info.grid_width);
  out->set_grid_height(info.grid_height);
  out->set_nodata_cells(info.nodata_cells);
  out->set_barrier_cells(info.barrier_cells);
  out->set_barrier_faces(info.barrier_faces);
  out->set_crs_name(info.file_crs_name);
  out->set_crs_wkt(info.file_crs_wkt);
  out->set_reprojected(info.reprojected);
  out->set_mesh_crs_name(info.mesh_crs_name);
  out->set_mesh_crs_wkt(info.mesh_crs_wkt);
  out->set_horizontal_scale(info.horizontal_scale);
  out->set_vertical_unit(info.vertical_unit);
  out->set_vertical_scale(info.vertical_scale);
  out->mutable_geotransform()->Assign(info.geotransform.begin(), info.geotransform.end());
  out->set_z_tolerance(info.z_tolerance);
  out->set_max_vertical_deviation(info.max_vertical_deviation);
  out->set_rms_vertical_deviation(info.rms_vertical_deviation);
}

terrain::DemInfo TerrainFromProto(const v1::Terrain& t) {
  terrain::DemInfo info;
  info.driver = t.driver();
  info.raster_width = t.raster_width();
  info.raster_height = t.raster_height();
  info.step = t.step();
  info.grid_width = t.grid_width();
  info.grid_height = t.grid_height();
  info.nodata_cells = t.nodata_cells();
  info.barrier_cells = t.barrier_cells();
  info.barrier_faces = t.barrier_faces();
  info.file_crs_name = t.crs_name();
  info.file_crs_wkt = t.crs_wkt();
  info.reprojected = t.reprojected();
  info.mesh_crs_name = t.mesh_crs_name();
  info.mesh_crs_wkt = t.mesh_crs_wkt();
  info.horizontal_scale = t.horizontal_scale();
  info.vertical_unit = t.vertical_unit();
  info.vertical_scale = t.vertical_scale();
  info.z_tolerance = t.z_tolerance();
  info.max_vertical_deviation = t.max_vertical_deviation();
  info.rms_vertical_deviation = t.rms_vertical_deviation();
  if (t.geotransform_size() == 6) {
    std::copy(t.geotransform().begin(), t.geotransform().end(), info.geotransform.begin());
  }
  return info;
}

absl::StatusOr<terrain::DemInfo> TerrainFromBytes(const std::string& bytes) {
  v1::Terrain terrain;
  if (!terrain.ParseFromString(bytes)) {
    return absl::InvalidArgumentError("the mesh's terrain does not parse as geodex.v1.Terrain");
  }
  return TerrainFromProto(terrain);
}

}  // namespace geodex::api
