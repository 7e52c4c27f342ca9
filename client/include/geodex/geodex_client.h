#pragma once

// The C++ client library of geodexd (what `geodex --server` uses).
//
// - Every call has a deadline (ClientOptions::deadline_seconds, changed between calls with
//   set_deadline_seconds: a control loop gives each call its own budget; it bounds each attempt)
//   and is retried with exponential backoff when the server answers
//   UNAVAILABLE (not yet listening, restarting, draining), or RESOURCE_EXHAUSTED with the
//   ErrorInfo reason QUEUE_FULL (every worker busy and the queue full: a moment later it may
//   fit). RESOURCE_EXHAUSTED for a limit (reason LIMIT) is never retried: it would fail again.
// - A mesh is named by a local file (or "sample:NAME"), a 64-hex mesh id or an alias. A file is
//   parsed locally and its id computed with the server's content hash (mesh_id.h); it is uploaded
//   only when the server does not have it, and uploaded again, transparently and once, when a
//   query answers NOT_FOUND for it (a replica that restarted or a rebalanced gateway).
// - Every mesh-scoped call carries the mesh id as `x-mesh-id` metadata, so a gateway can route by
//   mesh (uploads included). An alias is resolved to its id first (GetMesh).
// Errors come back as absl::Status with the server's code and message.
//
// The API speaks core's types (geodex/*.h: SurfacePoint, FieldQuery, DistanceField, ...) and the
// few of its own below; no generated geodex.v1 type appears here, and linking this library pulls
// neither GDAL nor the terrain library (a DEM's map is read with proto/convert/terrain_convert.h).

#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "geodex/delaunay.h"
#include "geodex/distance_field.h"
#include "geodex/distance_matrix.h"
#include "geodex/geometry_queries.h"
#include "geodex/isolines.h"
#include "geodex/locate.h"
#include "geodex/mesh_data.h"
#include "geodex/point_distance.h"
#include "geodex/shortest_path.h"
#include "geodex/surface_point.h"
#include "geodex/triangle_mesh.h"
#include "geodex/voronoi.h"

namespace grpc {
class Channel;
class ClientContext;
class Status;
}  // namespace grpc

namespace geodex::client {

// A mesh as geodexd stores it (the geodex.v1.Mesh resource, in the client's terms).
struct ServerMesh {
  std::string name;          // "meshes/{id}"
  std::string display_name;  // "" when none
  std::vector<std::string> aliases;
  MeshSummary summary;  // its counts and repairs, as Summarize() gives them locally
  uint64_t upload_bytes = 0, memory_bytes = 0;
  bool pinned = false;
  int64_t create_time_seconds = 0;  // Unix time
  // A DEM's mesh carries its map: `terrain` is the serialized geodex.v1.Terrain, read with
  // api::TerrainFromBytes (proto/convert/terrain_convert.h, which links GDAL; this library does
  // not).
  bool has_terrain = false;
  std::string terrain;
  std::string id() const { return name.rfind("meshes/", 0) == 0 ? name.substr(7) : name; }
};

// How geodexd makes a mesh of an uploaded GeoTIFF DEM (geodex.v1.DemOptions).
struct DemUploadOptions {
  uint32_t step = 0;                    // every step-th cell (0 or 1: every cell)
  std::optional<double> barrier_below;  // cells below this height are removed
  double z_tolerance = 0;               // > 0: an adaptive TIN within this height (docs/terrain.md)
};

// What DeriveMesh removes from a stored mesh (geodex.v1.Barrier), and what it cuts in.
struct BarrierOptions {
  std::optional<double> below;   // faces with a corner below this height
  std::string polygons_geojson;  // polygons cut out, lines slit (docs/barriers.md)
  double width = 0;              // lines and points widened to this width (map units)
  // Friction polygons whose outlines are cut in, nothing removed (DeriveMeshRequest's
  // friction_geojson): travel on the derived mesh with the same text has exact regions.
  std::string friction_geojson;
};

// Which distances EstimateDistances answers with.
enum class PointDistanceMode { kEstimate, kExact, kBoth };
struct PointDistances {
  std::vector<PointEstimate> estimates;  // the paper's unfolding estimate (kEstimate, kBoth)
  PointValues exact;                     // exact values (kExact, kBoth)
};

// The request field a failed call named, read from the google.rpc.BadRequest geodexd attaches
// (see server/status_convert.h): "sources[1].vertex" and what is wrong with it.
struct FieldViolation {
  std::string field;
  std::string description;
};
std::optional<FieldViolation> FieldViolationOf(const absl::Status& status);

struct ClientOptions {
  std::string target = "127.0.0.1:50051";  // HOST:PORT
  double deadline_seconds = 600;           // per call
  int max_attempts = 4;                    // tries on a full queue (RESOURCE_EXHAUSTED QUEUE_FULL)
  double initial_backoff_seconds = 0.2;    // doubled after each retry (at most 1 s between)
  // UNAVAILABLE (the server restarting on the same address, draining, not yet listening) is
  // retried for up to this long from the first one, each retry waiting for the channel to
  // connect again (geodexd's shutdown grace, 10 s by default, plus its start); the channel tries
  // to reconnect every 0.1 to 1 s. Then the call answers UNAVAILABLE.
  double reconnect_wait_seconds = 30;
  // Wait for the server to come up (until the deadline) instead of failing an attempt at once
  // with UNAVAILABLE while the channel is not connected (gRPC's wait-for-ready).
  bool wait_for_ready = false;
  bool retry_queue_full = true;  // retry RESOURCE_EXHAUSTED reason QUEUE_FULL
  size_t upload_chunk_bytes = 1 << 20;
  // TLS: `tls` on, with `ca_pem` the PEM roots to trust ("" = the system's roots).
  bool tls = false;
  std::string ca_pem;
  // Bearer token sent as "authorization: Bearer TOKEN" on every call ("" = none).
  std::string token;
  // On every query that takes points: the server refuses a 3D position farther than this from
  // the surface (INVALID_ARGUMENT; FieldViolationOf names it, e.g. "to.position"); +inf snaps any.
  double max_snap = std::numeric_limits<double>::infinity();
  // Called with (bytes sent, total) during uploads (the CLI's progress bar); may be empty.
  std::function<void(uint64_t, uint64_t)> upload_progress;
};

// A mesh as the client knows it.
struct MeshRef {
  std::string name;  // "meshes/{id}" once known, else "meshes/{alias}"
  std::string id;    // empty only for an alias that could not be resolved
  // For a local file: its bytes (uploaded on demand) and name.
  std::string file_bytes;
  std::string file_name;
  bool uploaded = false;  // this client uploaded it
  // Set when file_bytes are a GeoTIFF DEM: uploaded as MESH_FORMAT_GEOTIFF with these options.
  std::optional<DemUploadOptions> dem;
};

class GeodexClient {
 public:
  explicit GeodexClient(ClientOptions options);
  ~GeodexClient();
  GeodexClient(GeodexClient&&) noexcept;
  GeodexClient& operator=(GeodexClient&&) noexcept;

  // grpc.health.v1 Check for `service` ("" = the server as a whole): true when SERVING.
  absl::StatusOr<bool> Health(const std::string& service = "");

  // MESH argument -> reference: a readable file or "sample:NAME" (uploaded if the server lacks
  // it), a 64-hex id, or an alias.
  absl::StatusOr<MeshRef> ResolveMesh(const std::string& mesh);
  // A mesh read here (a sample, a DEM triangulated by the CLI): uploaded as OFF text named
  // `file_name` unless the server has its id already.
  absl::StatusOr<MeshRef> ResolveMeshData(const std::string& file_name, const MeshData& data);
  // A GeoTIFF DEM at `path`, read here into `mesh` (whose id names it): the raster's bytes are
  // uploaded (MESH_FORMAT_GEOTIFF with `options`) unless the server has that mesh with its map.
  absl::StatusOr<MeshRef> ResolveDem(const std::string& path, const MeshData& mesh,
                                     const DemUploadOptions& options);
  // Uploads file bytes (idempotent). `expected_id` is checked by the server when set. With
  // `dem`, the bytes are a GeoTIFF DEM made a mesh with those options.
  absl::StatusOr<ServerMesh> Upload(const std::string& file_name, const std::string& bytes,
                                    const std::string& alias, const std::string& expected_id,
                                    const std::optional<DemUploadOptions>& dem = std::nullopt);
  absl::StatusOr<ServerMesh> GetMesh(const std::string& name);
  // The mesh's positions and faces, as geodexd holds them (for drawing without the file).
  absl::StatusOr<MeshData> GetMeshGeometry(MeshRef& mesh);
  absl::StatusOr<std::vector<ServerMesh>> ListMeshes();  // every page
  absl::Status DeleteMesh(const std::string& name);
  // The mesh `name` without what `barrier` covers, stored by the server (DeriveMesh).
  absl::StatusOr<ServerMesh> DeriveMesh(const std::string& name, const BarrierOptions& barrier,
                                        const std::string& alias = "");

  // Queries, asked whole in core's types; results in core's types.
  // A field asked whole (api::FieldQueryToProto) and put back together (api::FieldAssembler),
  // with every product the query asks for; `cached`: the server's cache answered.
  absl::StatusOr<DistanceField> Field(MeshRef& mesh, const FieldQuery& query,
                                      bool* cached = nullptr);
  // The path asked whole (api::PathQueryToProto; the server answers with A*).
  absl::StatusOr<PathQueryResult> ShortestPath(MeshRef& mesh, const PathQuery& query);
  // The matrix asked whole (api::MatrixQueryToProto). The server streams rows as they finish;
  // query.options.on_row(rows received, rows), when set, is called as they arrive.
  absl::StatusOr<DistanceMatrix> Matrix(MeshRef& mesh, const MatrixQuery& query);
  // EstimateDistances: the query sent whole (api::PointQueryToProto), the estimates and/or the
  // exact values back.
  absl::StatusOr<PointDistances> DistancesAtPoints(MeshRef& mesh, const PointQuery& query,
                                                   PointDistanceMode mode);
  // The approximate geometry of section 6, asked whole (api::IsolineQueryToProto, ...) and
  // reassembled from the streamed pieces.
  absl::StatusOr<Isolines> ComputeIsolines(MeshRef& mesh, const IsolineQuery& query);
  absl::StatusOr<VoronoiDiagram> ComputeVoronoi(MeshRef& mesh, const VoronoiQuery& query);
  absl::StatusOr<DelaunayTriangulation> ComputeDelaunay(MeshRef& mesh, const DelaunayQuery& query);
  // Positions -> surface points (vertex, edge or face point) on the server's copy of the mesh,
  // with where they landed and how far they moved. A finite `max_snap` makes the server refuse a
  // position farther than that from the surface (INVALID_ARGUMENT naming it).
  absl::StatusOr<std::vector<LocatedPoint>> Locate(
      MeshRef& mesh, const std::vector<std::array<double, 3>>& xyz,
      double max_snap = std::numeric_limits<double>::infinity());

  // The deadline of each attempt of the calls made from now on (seconds; ClientOptions' at first).
  // A GeodexClient is not thread-safe: one per thread, or one call at a time.
  void set_deadline_seconds(double seconds) { options_.deadline_seconds = seconds; }
  double deadline_seconds() const { return options_.deadline_seconds; }

  // Calls made, retries (UNAVAILABLE, full queue) and transparent re-uploads (for tests and
  // --stats).
  int calls() const { return calls_; }
  int retries() const { return retries_; }
  int reuploads() const { return reuploads_; }
  // The replica that answered the last call (its x-geodex-replica metadata; "" if none).
  const std::string& last_replica() const { return last_replica_; }

 private:
  // Uploads ref's file bytes unless the server has ref.id.
  absl::StatusOr<MeshRef> UploadIfAbsent(MeshRef ref);
  // Runs `call(context)` with a fresh context (deadline, x-mesh-id) per attempt, retrying on
  // UNAVAILABLE and on a full queue.
  grpc::Status Call(const std::string& mesh_id,
                    const std::function<grpc::Status(grpc::ClientContext*)>& call);
  // Runs a mesh-scoped query; on NOT_FOUND for a mesh this client has the file of, uploads it
  // again and retries once.
  grpc::Status MeshCall(MeshRef& mesh,
                        const std::function<grpc::Status(grpc::ClientContext*)>& call);
  // The one server-streaming call: `start(context)` opens the stream (a reader), every message
  // goes to `on_message`, and a retried attempt starts over with a fresh `Assembler` in *out.
  template <typename Assembler, typename Start, typename OnMessage>
  absl::Status ReadStream(MeshRef& mesh, Start start, Assembler* out, OnMessage on_message);

  struct Stub;  // the generated geodex.v1 stub (geodex_client.cc)

  ClientOptions options_;
  std::shared_ptr<grpc::Channel> channel_;
  std::unique_ptr<Stub> stub_;
  int calls_ = 0, retries_ = 0, reuploads_ = 0;
  std::string last_replica_;
};

// OFF text of a mesh with exactly round-tripping coordinates (%.17g): how samples are uploaded.
std::string MeshToOffText(const MeshData& mesh);

}  // namespace geodex::client
