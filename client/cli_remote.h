#pragma once

// Remote mode of the geodex command line: `geodex --server HOST:PORT COMMAND ...` (or the
// GEODEX_SERVER environment variable) runs the command on a geodexd through the client library and
// prints exactly what local mode prints (timings and --stats aside).

#include <memory>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "cli_commands.h"
#include "geodex/delaunay.h"
#include "geodex/distance_field.h"
#include "geodex/isolines.h"
#include "geodex/shortest_path.h"
#include "geodex/surface_point.h"
#include "geodex/voronoi.h"

namespace geodex::cli {

// Connection settings of remote mode: global options before the command.
struct RemoteOptions {
  std::string target;      // --server HOST:PORT, or GEODEX_SERVER
  bool tls = false;        // --tls
  std::string ca_file;     // --ca FILE (PEM roots; implies --tls)
  std::string token_file;  // --token-file FILE, or the token itself in GEODEX_TOKEN
};
// Set once by main before any command runs.
void SetRemoteOptions(const RemoteOptions& options);

// True when this binary was built with the gRPC API (remote mode available).
bool RemoteAvailable();

// Runs `command` against `target`; kExitUsage for a command remote mode does not offer.
int RunRemote(const std::string& target, const std::string& command, const Args& args);

// The section-6 geometry computed by a geodexd, for cli_geometry.cc (which formats it exactly as
// in local mode). No gRPC types here, so cli_geometry.cc builds without gRPC.
class RemoteGeometry {
 public:
  virtual ~RemoteGeometry() = default;
  // Resolves MESH on the server (uploading a file if needed) and snaps p:X:Y:Z points there.
  virtual absl::Status Prepare(const std::string& mesh, std::vector<SurfacePoint>* points) = 0;
  virtual absl::StatusOr<DistanceField> ComputeField(const std::vector<SurfacePoint>& sources) = 0;
  virtual absl::StatusOr<PathQueryResult> ComputePath(const SurfacePoint& from,
                                                      const SurfacePoint& to) = 0;
  virtual absl::StatusOr<Isolines> ComputeIsolines(const std::vector<SurfacePoint>& sources,
                                                   const IsolineOptions& levels) = 0;
  virtual absl::StatusOr<VoronoiDiagram> ComputeVoronoi(const std::vector<SurfacePoint>& sites) = 0;
  virtual absl::StatusOr<DelaunayTriangulation> ComputeDelaunay(
      const std::vector<SurfacePoint>& sites) = 0;
};

// nullptr when this binary has no gRPC.
std::unique_ptr<RemoteGeometry> ConnectRemoteGeometry(const std::string& target);

// Prints a server error as one line and returns its exit code (2 bad argument, 3 unknown or
// unreadable mesh, 1 otherwise).
int FailRemote(const absl::Status& status);

}  // namespace geodex::cli
