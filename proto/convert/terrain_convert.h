#pragma once

// A DEM mesh's map (geodex.v1.Terrain <-> terrain::DemInfo), both directions, in a library of its
// own (geodex_api_convert_terrain): the terrain library links GDAL, and the client library
// (geodex_client), which only carries the map as bytes (ServerMesh::terrain), must not.

#include <string>

#include "absl/status/statusor.h"
#include "geodex/terrain.h"
#include "geodex/v1/geodex.pb.h"

namespace geodex::api {

// A Terrain without 6 geotransform values gives zeros (Dem::FromMesh then refuses it).
void TerrainToProto(const terrain::DemInfo& info, v1::Terrain* out);
terrain::DemInfo TerrainFromProto(const v1::Terrain& terrain);
// From the serialized Terrain a client's ServerMesh carries; InvalidArgument if it does not parse.
absl::StatusOr<terrain::DemInfo> TerrainFromBytes(const std::string& bytes);

}  // namespace geodex::api
