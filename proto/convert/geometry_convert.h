#pragma once

// The streamed section-6 geometry, both directions, in one place (geodex.proto, "Streaming of
// long results"): isolines, Voronoi diagrams and Delaunay triangulations become stream messages
// of about `budget_bytes` each (geodexd), and are reassembled message by message (the C++
// client). A polyline, cell or edge too long for one message is split into pieces that repeat
// its header and set `continued` on all but the last.

#include <cstddef>
#include <vector>

#include "geodex/delaunay.h"
#include "geodex/geometry_queries.h"
#include "geodex/isolines.h"
#include "geodex/mesh_data.h"
#include "geodex/surface_point.h"
#include "geodex/v1/geodex.pb.h"
#include "geodex/voronoi.h"

namespace geodex::api {

// The queries asked whole (geometry_queries.h): sources, solver options and the product's own
// options into the request (the mesh and want_stats are the caller's). geodexd reads the sources
// and solver options with its limits (server/query_support.h) and the levels with
// IsolineLevelsFromProto, then checks them with core's ValidateIsolineQuery.
void IsolineQueryToProto(const IsolineQuery& query, v1::ComputeIsolinesRequest* out);
void VoronoiQueryToProto(const VoronoiQuery& query, v1::ComputeVoronoiRequest* out);
void DelaunayQueryToProto(const DelaunayQuery& query, v1::ComputeDelaunayRequest* out);
// The isoline options of ComputeIsolines (an option added to IsolineOptions is read here), and
// the levels of ExportGis' isochrones: `levels`, or without them `count`.
IsolineOptions IsolineLevelsFromProto(const v1::ComputeIsolinesRequest& request);
IsolineOptions IsolineLevelsFromProto(const google::protobuf::RepeatedField<double>& levels,
                                      int32_t count);

// At least one message each; stats (when wanted) go into the last one.
std::vector<v1::ComputeIsolinesResponse> IsolinesToProto(const Isolines& isolines,
                                                         size_t budget_bytes);
std::vector<v1::ComputeVoronoiResponse> VoronoiToProto(
    const VoronoiDiagram& diagram, const std::vector<SurfacePoint>& resolved_sources,
    bool omit_cell_faces, size_t budget_bytes);
std::vector<v1::ComputeDelaunayResponse> DelaunayToProto(
    const DelaunayTriangulation& delaunay, const std::vector<SurfacePoint>& resolved_sources,
    size_t budget_bytes);

// A mesh's geometry (GetMeshGeometry): positions first, then faces.
std::vector<v1::MeshGeometry> MeshGeometryToProto(const MeshData& mesh, size_t budget_bytes);

// Reassembly as the messages arrive: Add each in order, then take result().
class MeshGeometryAssembler {
 public:
  using Message = v1::MeshGeometry;  // what it is fed, one stream message at a time
  void Add(const v1::MeshGeometry& message);
  MeshData& result() { return out_; }

 private:
  MeshData out_;
};

class IsolinesAssembler {
 public:
  using Message = v1::ComputeIsolinesResponse;  // what it is fed, one stream message at a time
  void Add(const v1::ComputeIsolinesResponse& message);
  Isolines& result() { return out_; }

 private:
  Isolines out_;
  bool open_ = false;
};

class VoronoiAssembler {
 public:
  using Message = v1::ComputeVoronoiResponse;  // what it is fed, one stream message at a time
  void Add(const v1::ComputeVoronoiResponse& message);
  VoronoiDiagram& result() { return out_; }
  const std::vector<SurfacePoint>& resolved_sources() const { return sources_; }

 private:
  VoronoiDiagram out_;
  std::vector<SurfacePoint> sources_;
  bool first_ = true, cell_open_ = false, boundary_open_ = false;
};

class DelaunayAssembler {
 public:
  using Message = v1::ComputeDelaunayResponse;  // what it is fed, one stream message at a time
  void Add(const v1::ComputeDelaunayResponse& message);
  DelaunayTriangulation& result() { return out_; }
  const std::vector<SurfacePoint>& resolved_sources() const { return sources_; }

 private:
  DelaunayTriangulation out_;
  std::vector<SurfacePoint> sources_;
  bool kept_open_ = false, removed_open_ = false;
};

}  // namespace geodex::api
