#pragma once

// Where a geodex command runs: in this process (core) or on a geodexd (--server HOST:PORT). Each
// command is written once against this interface (cli_commands.cc, cli_geometry.cc,
// cli_render.cc), so it takes the same options and prints the same output in both modes.
// LocalBackend is in cli_local_backend.cc, RemoteBackend in cli_remote.cc; the shared point
// resolution, exit codes and mesh-reading options in cli_args.cc.

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "cli_common.h"
#include "geodex/delaunay.h"
#include "geodex/distance_field.h"
#include "geodex/distance_matrix.h"
#include "geodex/geodesic_solver.h"
#include "geodex/geojson.h"
#include "geodex/geometry_queries.h"
#include "geodex/isolines.h"
#include "geodex/locate.h"
#include "geodex/mesh_data.h"
#include "geodex/shortest_path.h"
#include "geodex/surface_point.h"
#include "geodex/terrain.h"
#include "geodex/voronoi.h"

namespace geodex::cli {

// `distances --at`: the unfolding estimate at each point (paper section 4, from the sources'
// field) beside core's exact answer, whatever members PointValues has.
struct AtValues {
  std::vector<double> estimate;
  PointValues exact;
};

class Backend {
 public:
  virtual ~Backend() = default;

  // Opens MESH: a file, a DEM (terrain::IsDemPath, read with `dem`) or sample:NAME; remotely also
  // a mesh id or a name the server knows (a file is uploaded only if the server lacks it; a DEM is
  // triangulated here and uploaded as that mesh). Its errors are the mesh's (exit 3).
  virtual absl::Status Open(const std::string& mesh, const MeshBuildOptions& build,
                            const terrain::DemOptions& dem) = 0;
  // The DEM MESH was read from, or null (a mesh file, a sample, a mesh named on a server).
  virtual const terrain::Dem* Terrain() const = 0;
  // False, with *error naming the flag, for an option this backend cannot honour (a remote call
  // leaves engine ablations, threads and the window budget to geodexd).
  virtual bool Supports(const Args& args, std::string* error) const = 0;
  // The nearest surface points to 3D positions (file coordinates), with how far each moved.
  virtual absl::StatusOr<std::vector<LocatedPoint>> Locate(
      const std::vector<std::array<double, 3>>& xyz) = 0;
  // Checks vertex, edge and face points against the mesh (remotely the server checks them with
  // the query); errors name `option` (exit 2).
  virtual absl::Status Check(const std::string& option,
                             const std::vector<SurfacePoint>& points) = 0;
  // The mesh as read, file coordinates: what draws a picture or places a site.
  virtual absl::StatusOr<const MeshData*> Geometry() = 0;

  virtual absl::StatusOr<InfoValues> Info() = 0;
  // The field with every product the query asks for. The query is forwarded whole: to core
  // locally, through proto/convert remotely. The field is the backend's, valid until it solves
  // for other sources or options: a local backend keeps its last solve, so render's layers on the
  // same sources share one, uncopied.
  virtual absl::StatusOr<const DistanceField*> Field(const FieldQuery& query) = 0;
  // The query is forwarded whole: to core locally, through proto/convert remotely.
  virtual absl::StatusOr<AtValues> DistancesAt(const PointQuery& query) = 0;
  // Path and matrix are forwarded whole too.
  virtual absl::StatusOr<PathQueryResult> Path(const PathQuery& query) = 0;
  // query.options.on_row sees rows as they are solved (locally) or arrive (remotely).
  virtual absl::StatusOr<DistanceMatrix> Matrix(const MatrixQuery& query) = 0;
  // Section 6 geometry, asked whole (geometry_queries.h) and forwarded unchanged: a local backend
  // solves the query's field once for all of them, a remote one sends the query.
  virtual absl::StatusOr<Isolines> ComputeIsolines(const IsolineQuery& query) = 0;
  virtual absl::StatusOr<VoronoiDiagram> ComputeVoronoi(const VoronoiQuery& query) = 0;
  virtual absl::StatusOr<DelaunayTriangulation> ComputeDelaunay(const DelaunayQuery& query) = 0;

  // --stats members that say where the work ran, as `"key": value, ` pairs: the load and build
  // times locally; the server, replica, mesh and cache remotely.
  virtual std::string StatsContext() const = 0;
};

// Snapping is never silent: the farthest a command's p:X:Y:Z points moved onto the surface.
struct SnapReport {
  double max_distance = 0;
  std::string point;  // that point's SPEC, "" when no position was given
};
// A snap farther than this fraction of the mesh's bounding-box diagonal is warned about on stderr.
inline constexpr double kSnapWarnRel = 0.01;
// Snaps `points`' p:X:Y:Z entries on the backend, refusing any farther than --max-snap (when
// given) and warning above kSnapWarnRel, then checks every point. Errors name --`option`.
absl::Status ResolvePoints(Backend& backend, const Args& args, const std::string& option,
                           std::vector<SurfacePoint>* points, SnapReport* report);
// Parses a SPEC list given as --`option`; `g:X:Y` and `ll:LON:LAT` items are dropped onto the
// backend's DEM (without a backend, before MESH is open, only their syntax is checked).
// InvalidArgument naming the option.
absl::StatusOr<std::vector<SurfacePoint>> ParseSpec(const Backend* backend,
                                                    const std::string& option,
                                                    const std::string& spec);
// Parses --`option` (which must be present), then ResolvePoints.
absl::Status ResolveOption(Backend& backend, const Args& args, const std::string& option,
                           std::vector<SurfacePoint>* points, SnapReport* report);

std::unique_ptr<Backend> MakeLocalBackend();
// nullptr when this geodex was built without gRPC.
std::unique_ptr<Backend> MakeRemoteBackend(const std::string& target);

// --face-weights FILE (one weight per face, a number a line, "inf" impassable) or --friction FILE
// (on a DEM: polygons with a "friction" property, or a raster in the DEM's CRS; geodex/friction.h)
// into options->travel, once MESH is open; nothing without a travel cost. Returns 0 or the exit
// code after printing the one-line error (2 naming the flag; 3 when FILE cannot be read).
int ResolveTravelWeights(Backend& backend, const Args& args, GeodesicOptions* options);

// The exit code of a failed query, the same in both modes: a bad argument 2 (INVALID_ARGUMENT,
// OUT_OF_RANGE), an unknown or unreadable mesh 3 (NOT_FOUND, DATA_LOSS), anything else 1
// (cancelled, budget, unreachable target).
int QueryExitCode(const absl::Status& status);
// Prints the status as one line and returns QueryExitCode.
int FailQuery(const absl::Status& status);
// --output FILE with a vector file's extension (.geojson, .gpkg, .shp, .fgb: gis_formats.h): writes
// `features` (mesh coordinates of the backend's DEM), GeoJSON as RFC 7946 unless --crs native, the
// others in the DEM's CRS. Exit 2 without a DEM, or when FILE cannot be written (the reason given).
bool IsVectorPath(const Args& args);
// The file records what made it (terrain::Provenance: the command line, and what `options`, when
// given, make of the values).
int WriteVectorOutput(const Backend& backend, const Args& args,
                      const std::vector<terrain::GeoFeature>& features,
                      const GeodesicOptions* options = nullptr);
// How MESH is read (--dem-step, --barrier-below, --barrier) and GeoJSON written (--crs), checked:
// InvalidArgument naming the flag.
absl::StatusOr<terrain::DemOptions> MeshReadOptions(const Args& args, const std::string& mesh);
// Backend::Open, or the one-line failure's exit code: 3 for the mesh (unreadable, invalid,
// unknown), 1 when the service failed (unauthenticated, unavailable, over its limits).
int OpenMesh(Backend& backend, const Args& args, const std::string& mesh,
             const MeshBuildOptions& build);

}  // namespace geodex::cli
