#include "planner.h"

#include <unistd.h>

#include <cstdio>
#include <string>
#include <vector>

#include "geodex/distance_matrix.h"
#include "geodex/geodex_client.h"
#include "geodex/shortest_path.h"
#include "geodex/surface_point.h"

namespace {

int Fail(const char* what, const absl::Status& status) {
  std::fprintf(stderr, "planner: %s: %s\n", what, status.ToString().c_str());
  return 1;
}

}  // namespace

int RunPlanner(const std::string& target, const std::string& mesh_file, uint32_t from,
               uint32_t to) {
  geodex::client::ClientOptions options;
  options.target = target;
  options.deadline_seconds = 60;
  options.wait_for_ready = true;  // a planner started before the server waits for it
  geodex::client::GeodexClient client(options);

  // The mesh: uploaded once, by content hash; re-uploaded if the server loses it.
  absl::StatusOr<geodex::client::MeshRef> mesh = client.ResolveMesh(mesh_file);
  if (!mesh.ok()) return Fail("mesh", mesh.status());

  // 1. The exact path.
  geodex::PathQuery path_query;
  path_query.from = geodex::SurfacePoint::AtVertex(from);
  path_query.to = geodex::SurfacePoint::AtVertex(to);
  absl::StatusOr<geodex::PathQueryResult> path = client.ShortestPath(*mesh, path_query);
  if (!path.ok()) return Fail("path", path.status());
  std::printf("%.17g\n", path->distance);
  std::printf("path: %zu points\n", path->path.points.size());
  for (const geodex::PathPoint& p : path->path.points) {
    std::printf("  %s\n", geodex::SurfacePointToString(p.where).c_str());
  }

  // 2. A matrix between waypoints: the two ends and the path's middle point.
  const std::vector<geodex::SurfacePoint> waypoints = {
      path_query.from, path->path.points[path->path.points.size() / 2].where, path_query.to};
  geodex::MatrixQuery matrix_query;
  matrix_query.sources = waypoints;
  matrix_query.targets = waypoints;
  absl::StatusOr<geodex::DistanceMatrix> matrix = client.Matrix(*mesh, matrix_query);
  if (!matrix.ok()) return Fail("matrix", matrix.status());
  std::printf("matrix %zu x %zu:\n", matrix->rows, matrix->cols);
  for (size_t r = 0; r < matrix->rows; ++r) {
    for (size_t c = 0; c < matrix->cols; ++c) {
      std::printf("%s%.17g", c ? " " : "  ", matrix->values[r * matrix->cols + c]);
    }
    std::printf("\n");
  }

  // 3. k nearest: each start's 2 nearest waypoints (the others come back as inf).
  matrix_query.options.k_nearest = 2;
  absl::StatusOr<geodex::DistanceMatrix> nearest = client.Matrix(*mesh, matrix_query);
  if (!nearest.ok()) return Fail("k nearest", nearest.status());
  std::printf("2 nearest:\n");
  for (size_t r = 0; r < nearest->rows; ++r) {
    for (size_t c = 0; c < nearest->cols; ++c) {
      std::printf("%s%.17g", c ? " " : "  ", nearest->values[r * nearest->cols + c]);
    }
    std::printf("\n");
  }

  // 4. A call's own deadline (CallOptions): too short, DEADLINE_EXCEEDED; the client's own 60 s
  // still apply to the next call. (A max_distance of its own: the server caches fields, and a
  // cached one could be back within any deadline; this one is solved.)
  geodex::FieldQuery field_query;
  field_query.sources = {path_query.from};
  field_query.options.max_distance = 1e9 + static_cast<double>(getpid());
  geodex::client::CallOptions hurried;
  hurried.deadline_seconds = 1e-6;
  absl::StatusOr<geodex::DistanceField> field = client.Field(*mesh, field_query, nullptr, hurried);
  std::printf("deadline 1 us: %s\n", field.ok() ? "answered" : field.status().ToString().c_str());
  if (field.ok() || !absl::IsDeadlineExceeded(field.status())) return 1;
  field = client.Field(*mesh, field_query);
  if (!field.ok()) return Fail("field after the short deadline", field.status());
  std::printf("deadline 60 s: %zu distances\n", field->distance.size());

  // 5. Asynchronous: the path computed while this thread does other work, then taken; and a
  // call cancelled while it runs (or before it is sent): CANCELLED.
  geodex::client::AsyncCall<geodex::PathQueryResult> pending =
      client.ShortestPathAsync(*mesh, path_query);
  absl::StatusOr<geodex::PathQueryResult> later = pending.Get();
  if (!later.ok()) return Fail("async path", later.status());
  std::printf("async path: %s\n",
              later->distance == path->distance ? "the same length" : "differs");
  field_query.options.max_distance = 2e9 + static_cast<double>(getpid());  // solved, not cached
  geodex::client::AsyncCall<geodex::DistanceField> cancelled =
      client.FieldAsync(*mesh, field_query);
  cancelled.Cancel();
  absl::StatusOr<geodex::DistanceField> gone = cancelled.Get();
  // (A field this small may finish before the cancel reaches it: then it answers.)
  std::printf("cancelled: %s\n", gone.ok() ? "answered first" : gone.status().ToString().c_str());
  if (!gone.ok() && !absl::IsCancelled(gone.status())) return Fail("cancel", gone.status());
  return 0;
}
