// A planner's smallest use of the C++ client library (geodex_client): ask a running geodexd for
// the exact shortest path between two vertices of a mesh file (uploaded once, by content hash)
// and print its length and points. It speaks only core's types and the client's own; it links
// geodex_client alone (no GDAL, no terrain library: tests/CMakeLists.txt checks that).
//
//   path_client HOST:PORT MESH_FILE FROM_VERTEX TO_VERTEX

#include <cstdio>
#include <cstdlib>
#include <string>

#include "geodex/geodex_client.h"
#include "geodex/shortest_path.h"
#include "geodex/surface_point.h"

int main(int argc, char** argv) {
  if (argc != 5) {
    std::fprintf(stderr, "usage: %s HOST:PORT MESH_FILE FROM_VERTEX TO_VERTEX\n", argv[0]);
    return 2;
  }
  geodex::client::ClientOptions options;
  options.target = argv[1];
  options.deadline_seconds = 60;
  geodex::client::GeodexClient client(options);
  absl::StatusOr<geodex::client::MeshRef> mesh = client.ResolveMesh(argv[2]);
  if (!mesh.ok()) {
    std::fprintf(stderr, "%s\n", std::string(mesh.status().message()).c_str());
    return 1;
  }
  geodex::PathQuery query;
  query.from = geodex::SurfacePoint::AtVertex(static_cast<uint32_t>(std::atoi(argv[3])));
  query.to = geodex::SurfacePoint::AtVertex(static_cast<uint32_t>(std::atoi(argv[4])));
  absl::StatusOr<geodex::PathQueryResult> path = client.ShortestPath(*mesh, query);
  if (!path.ok()) {
    std::fprintf(stderr, "%s\n", std::string(path.status().message()).c_str());
    return 1;
  }
  std::printf("length %.17g, %zu points\n", path->distance, path->path.points.size());
  for (const geodex::PathPoint& p : path->path.points) {
    std::printf("%.17g %.17g %.17g %s\n", p.position[0], p.position[1], p.position[2],
                geodex::SurfacePointToString(p.where).c_str());
  }
  return 0;
}
