#pragma once

// The C++ client library of geodexd (what `geodex --server` uses).
//
// - Every call has a deadline (ClientOptions::deadline_seconds, or the call's own in its
//   CallOptions: a control loop gives each call its own budget; it bounds each attempt) and may
//   be cancelled from another thread (CallOptions::cancel), and is retried with exponential
//   backoff when the server answers
//   UNAVAILABLE (not yet listening, restarting, draining), or RESOURCE_EXHAUSTED with the
//   ErrorInfo reason QUEUE_FULL (every worker busy and the queue full: a moment later it may
//   fit). RESOURCE_EXHAUSTED for a limit (reason LIMIT) is never retried: it would fail again.
// - A mesh is named by a local file (or "sample:NAME"), a 64-hex mesh id or an alias. A file is
//   parsed locally and its id computed with the server's content hash (mesh_id.h); it is uploaded
//   only when the server does not have it, and uploaded again, transparently and once, when a
//   query answers NOT_FOUND for it (a replica that restarted or a rebalanced gateway).
// - Every mesh-scoped call carries the mesh id as `x-mesh-id` metadata, so a gateway can route by
//   mesh (uploads included). An alias is resolved to its id first (GetMesh).
// - Thread-safe: one GeodexClient may be shared by any number of threads calling at once (the
//   channel is shared; the counters are atomic). A MeshRef passed by reference may be updated by
//   the call (a transparent re-upload): give concurrent calls their own copies. The *Async
//   methods take theirs by value.
// Errors come back as absl::Status with the server's code and message.
//
// The API speaks core's types (geodex/*.h: SurfacePoint, FieldQuery, DistanceField, ...) and the
// few of its own below; no generated geodex.v1 type appears here, and linking this library pulls
// neither GDAL nor the terrain library (a DEM's map is read with proto/convert/terrain_convert.h).

#include <array>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <future>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <utility>
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

// A DEM's map as geodexd keeps it with the mesh (geodex.v1.Terrain, in the client's terms; plain
// values: reading the CRS is the caller's, e.g. with GDAL/PROJ from `crs_wkt`).
struct ServerTerrain {
  std::string driver;                            // GDAL's driver of the raster ("GTiff")
  uint32_t raster_width = 0, raster_height = 0;  // the raster's size in cells
  uint32_t step = 1;                             // every step-th cell was used
  uint32_t grid_width = 0, grid_height = 0;      // the used cells
  uint64_t nodata_cells = 0, barrier_cells = 0, barrier_faces = 0;
  std::string crs_name, crs_wkt;            // the raster's CRS (map points are in it)
  bool reprojected = false;                 // geographic raster: the mesh is in mesh_crs (UTM)
  std::string mesh_crs_name, mesh_crs_wkt;  // the CRS of the mesh's x and y (metres)
  double horizontal_scale = 1;              // the raster CRS's unit in metres
  std::string vertical_unit;                // the heights' unit ("" when none)
  double vertical_scale = 1;                // ... in metres
  // The used grid's geotransform in the raster's CRS (GDAL's order): cell (i, j) has its corner
  // at (g0 + i g1 + j g2, g3 + i g4 + j g5).
  std::array<double, 6> geotransform{};
  // An adaptive TIN (0 for the grid): the tolerance asked for, the largest and RMS vertical
  // distance (metres) between the TIN and the used cells.
  double z_tolerance = 0, max_vertical_deviation = 0, rms_vertical_deviation = 0;
};

// A mesh as geodexd stores it (the geodex.v1.Mesh resource, in the client's terms).
struct ServerMesh {
  std::string name;          // "meshes/{id}"
  std::string display_name;  // "" when none
  std::vector<std::string> aliases;
  MeshSummary summary;  // its counts and repairs, as Summarize() gives them locally
  uint64_t upload_bytes = 0, memory_bytes = 0;
  bool pinned = false;
  int64_t create_time_seconds = 0;  // Unix time
  // A DEM's mesh carries its map (`map`, plain values). `terrain` holds the same as the serialized
  // geodex.v1.Terrain, for the geodex CLI (which reads it with GDAL; this library links none).
  bool has_terrain = false;
  std::optional<ServerTerrain> map;
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
  // How far each 3D position (sources, then points) moved onto the surface; 0 for surface points.
  std::vector<double> snap_distances;
};

// Cancels calls from another thread: give it to calls in CallOptions::cancel, then Cancel(). A
// call in flight answers CANCELLED at once (its RPC is cancelled, retries stop); a call started
// afterwards with it answers CANCELLED without sending anything. Thread-safe.
class Cancellation {
 public:
  void Cancel();
  bool cancelled() const;

 private:
  friend class GeodexClient;
  // The attempt in flight registers its context, so that Cancel() can cancel it; false when
  // already cancelled (the attempt is then not sent).
  bool Register(grpc::ClientContext* context);
  void Unregister(grpc::ClientContext* context);
  mutable std::mutex mu_;
  bool cancelled_ = false;
  std::vector<grpc::ClientContext*> in_flight_;
};

// One call's own settings, the last argument of every query method (unset: the client's).
struct CallOptions {
  std::optional<double> deadline_seconds;  // each attempt's deadline (ClientOptions')
  std::optional<double> max_snap;          // farthest a 3D position may be snapped (ClientOptions')
  std::shared_ptr<Cancellation> cancel;    // cancel from another thread (none: not cancellable)
};

// A call running on a thread of its own (GeodexClient::*Async). Get() waits for its answer;
// Cancel() makes it answer CANCELLED soon. Destroying an AsyncCall whose answer was not taken
// cancels the call and waits for it. The GeodexClient must outlive its AsyncCalls.
template <typename T>
class AsyncCall {
 public:
  AsyncCall(std::future<absl::StatusOr<T>> future, std::shared_ptr<Cancellation> cancel)
      : future_(std::move(future)), cancel_(std::move(cancel)) {}
  AsyncCall(AsyncCall&&) noexcept = default;
  AsyncCall& operator=(AsyncCall&&) noexcept = default;
  ~AsyncCall() {
    if (future_.valid()) {
      cancel_->Cancel();
      future_.wait();
    }
  }
  // The answer (once: valid() is false afterwards).
  absl::StatusOr<T> Get() { return future_.get(); }
  // Whether the answer is there, waiting up to `seconds` for it.
  bool Ready(double seconds = 0) const {
    return future_.wait_for(std::chrono::duration<double>(seconds)) == std::future_status::ready;
  }
  bool valid() const { return future_.valid(); }
  void Cancel() { cancel_->Cancel(); }

 private:
  std::future<absl::StatusOr<T>> future_;
  std::shared_ptr<Cancellation> cancel_;
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
  // A mesh in memory (a sample, a DEM triangulated by the CLI, a planner's own map): uploaded as
  // OFF text named `file_name` unless the server has its id already.
  absl::StatusOr<MeshRef> UploadMeshData(const std::string& file_name, const MeshData& data);
  [[deprecated("UploadMeshData")]] absl::StatusOr<MeshRef> ResolveMeshData(
      const std::string& file_name, const MeshData& data) {
    return UploadMeshData(file_name, data);
  }
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
                                      bool* cached = nullptr, const CallOptions& call = {});
  // The path asked whole (api::PathQueryToProto; the server answers with A*).
  absl::StatusOr<PathQueryResult> ShortestPath(MeshRef& mesh, const PathQuery& query,
                                               const CallOptions& call = {});
  // The matrix asked whole (api::MatrixQueryToProto). The server streams rows as they finish;
  // query.options.on_row(rows received, rows), when set, is called as they arrive.
  absl::StatusOr<DistanceMatrix> Matrix(MeshRef& mesh, const MatrixQuery& query,
                                        const CallOptions& call = {});
  // EstimateDistances: the query sent whole (api::PointQueryToProto), the estimates and/or the
  // exact values back.
  absl::StatusOr<PointDistances> DistancesAtPoints(MeshRef& mesh, const PointQuery& query,
                                                   PointDistanceMode mode,
                                                   const CallOptions& call = {});
  // The approximate geometry of section 6, asked whole (api::IsolineQueryToProto, ...) and
  // reassembled from the streamed pieces.
  absl::StatusOr<Isolines> ComputeIsolines(MeshRef& mesh, const IsolineQuery& query,
                                           const CallOptions& call = {});
  absl::StatusOr<VoronoiDiagram> ComputeVoronoi(MeshRef& mesh, const VoronoiQuery& query,
                                                const CallOptions& call = {});
  absl::StatusOr<DelaunayTriangulation> ComputeDelaunay(MeshRef& mesh, const DelaunayQuery& query,
                                                        const CallOptions& call = {});
  // Positions -> surface points (vertex, edge or face point) on the server's copy of the mesh,
  // with where they landed and how far they moved. A finite `max_snap` makes the server refuse a
  // position farther than that from the surface (INVALID_ARGUMENT naming it).
  absl::StatusOr<std::vector<LocatedPoint>> Locate(
      MeshRef& mesh, const std::vector<std::array<double, 3>>& xyz,
      double max_snap = std::numeric_limits<double>::infinity(), const CallOptions& call = {});

  // The same queries on a thread of their own: the answer is the AsyncCall's (Get), and the call
  // can be cancelled (AsyncCall::Cancel, or call.cancel). The mesh and query are copied.
  AsyncCall<PathQueryResult> ShortestPathAsync(MeshRef mesh, PathQuery query,
                                               CallOptions call = {});
  AsyncCall<DistanceField> FieldAsync(MeshRef mesh, FieldQuery query, CallOptions call = {});
  AsyncCall<PointDistances> DistancesAtPointsAsync(MeshRef mesh, PointQuery query,
                                                   PointDistanceMode mode, CallOptions call = {});
  AsyncCall<DistanceMatrix> MatrixAsync(MeshRef mesh, MatrixQuery query, CallOptions call = {});

  // The default deadline of each attempt of the calls made from now on (seconds; ClientOptions'
  // at first); a call's CallOptions::deadline_seconds overrides it.
  void set_deadline_seconds(double seconds) { state_->deadline_seconds = seconds; }
  double deadline_seconds() const { return state_->deadline_seconds; }

  // Calls made, retries (UNAVAILABLE, full queue) and transparent re-uploads (for tests and
  // --stats).
  int calls() const { return state_->calls; }
  int retries() const { return state_->retries; }
  int reuploads() const { return state_->reuploads; }
  // The replica that answered the last call (its x-geodex-replica metadata; "" if none).
  std::string last_replica() const {
    std::lock_guard<std::mutex> lock(state_->mu);
    return state_->last_replica;
  }

 private:
  // Uploads ref's file bytes unless the server has ref.id.
  absl::StatusOr<MeshRef> UploadIfAbsent(MeshRef ref);
  // Runs `call(context)` with a fresh context (deadline, x-mesh-id) per attempt, retrying on
  // UNAVAILABLE and on a full queue.
  grpc::Status Call(const std::string& mesh_id,
                    const std::function<grpc::Status(grpc::ClientContext*)>& call,
                    const CallOptions& options = {});
  // Runs a mesh-scoped query; on NOT_FOUND for a mesh this client has the file of, uploads it
  // again and retries once.
  grpc::Status MeshCall(MeshRef& mesh,
                        const std::function<grpc::Status(grpc::ClientContext*)>& call,
                        const CallOptions& options);
  // The one server-streaming call: `start(context)` opens the stream (a reader), every message
  // goes to `on_message`, and a retried attempt starts over with a fresh `Assembler` in *out.
  template <typename Assembler, typename Start, typename OnMessage>
  absl::Status ReadStream(MeshRef& mesh, Start start, Assembler* out, OnMessage on_message,
                          const CallOptions& options);
  // ClientOptions' max_snap unless the call sets its own.
  double MaxSnap(const CallOptions& call) const {
    return call.max_snap.value_or(options_.max_snap);
  }
  // Runs `run(mesh, query, call)` on a thread of its own, with a Cancellation (the call's own,
  // or a new one).
  template <typename T, typename Query, typename Run>
  AsyncCall<T> Async(MeshRef mesh, Query query, CallOptions call, Run run);

  struct Stub;  // the generated geodex.v1 stub (geodex_client.cc)

  // What calls change, shared by threads (behind a pointer: the client stays movable).
  struct State {
    std::atomic<double> deadline_seconds{600};
    std::atomic<int> calls{0}, retries{0}, reuploads{0};
    mutable std::mutex mu;
    std::string last_replica;  // guarded by mu
  };

  ClientOptions options_;  // read-only after construction
  std::shared_ptr<grpc::Channel> channel_;
  std::unique_ptr<Stub> stub_;
  std::unique_ptr<State> state_;
};

// OFF text of a mesh with exactly round-tripping coordinates (%.17g): how samples are uploaded.
std::string MeshToOffText(const MeshData& mesh);

template <typename T, typename Query, typename Run>
AsyncCall<T> GeodexClient::Async(MeshRef mesh, Query query, CallOptions call, Run run) {
  if (call.cancel == nullptr) call.cancel = std::make_shared<Cancellation>();
  std::shared_ptr<Cancellation> cancel = call.cancel;
  return AsyncCall<T>(
      std::async(std::launch::async,
                 [this, mesh = std::move(mesh), query = std::move(query), call = std::move(call),
                  run]() mutable -> absl::StatusOr<T> { return run(*this, mesh, query, call); }),
      std::move(cancel));
}

}  // namespace geodex::client
