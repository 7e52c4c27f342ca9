// The approximate geometry of paper section 6 streamed: ComputeIsolines, ComputeVoronoi,
// ComputeDelaunay.

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "geodex/delaunay.h"
#include "geodex/isolines.h"
#include "geodex/voronoi.h"
#include "geometry_convert.h"
#include "proto_convert.h"
#include "queries.h"
#include "query_support.h"
#include "service_limits.h"
#include "status_convert.h"

namespace geodex::server {
namespace {

// The geometry's messages as a stream, the field's stats in the last one when asked for.
template <typename Response>
MessageProducer<Response> Streamed(std::vector<Response> messages, const SolvedField& solved,
                                   bool want_stats) {
  if (want_stats) FieldStatsToProto(*solved.field, solved.cached, messages.back().mutable_stats());
  return ProducerOf(std::move(messages));
}

}  // namespace

absl::StatusOr<MessageStream<v1::ComputeIsolinesResponse>> RunComputeIsolines(
    const QueryEnv& env, const v1::ComputeIsolinesRequest& request) {
  const uint32_t max_levels = env.limits->max_levels;
  if (static_cast<uint64_t>(request.levels_size()) > max_levels) {
    return ServerLimitError("max_levels", absl::StrCat("levels: ", request.levels_size(),
                                                       " levels, over --max_levels=", max_levels));
  }
  IsolineOptions options;
  for (int i = 0; i < request.levels_size(); ++i) {
    if (!std::isfinite(request.levels(i))) {
      return FieldError(absl::StrCat("levels[", i, "]"),
                        absl::StrCat("must be finite, got ", request.levels(i)));
    }
    options.levels.push_back(request.levels(i));
  }
  if (options.levels.empty()) {
    if (request.count() < 2) {
      return FieldError("count",
                        absl::StrCat("give levels, or a count >= 2 (got ", request.count(), ")"));
    }
    if (static_cast<uint64_t>(request.count()) > uint64_t{max_levels} + 1) {
      return ServerLimitError(
          "max_levels", absl::StrCat("count: ", request.count(), " gives ", request.count() - 1,
                                     " levels, over --max_levels=", max_levels));
    }
    options.count = request.count();
  }
  absl::StatusOr<SolvedField> solved =
      SolveField(env, request.mesh(), request.sources(), request.options());
  if (!solved.ok()) return solved.status();
  absl::StatusOr<Isolines> isolines = ExtractIsolines(*solved->mesh->mesh, *solved->field, options);
  if (!isolines.ok()) return isolines.status();

  std::vector<v1::ComputeIsolinesResponse> messages =
      api::IsolinesToProto(*isolines, env.limits->stream_chunk_bytes);
  return Streamed(std::move(messages), *solved, request.want_stats());
}

absl::StatusOr<MessageStream<v1::ComputeVoronoiResponse>> RunComputeVoronoi(
    const QueryEnv& env, const v1::ComputeVoronoiRequest& request) {
  absl::StatusOr<SolvedField> solved =
      SolveField(env, request.mesh(), request.sources(), request.options());
  if (!solved.ok()) return solved.status();
  absl::StatusOr<VoronoiDiagram> diagram = BuildVoronoi(*solved->mesh->mesh, *solved->field);
  if (!diagram.ok()) return diagram.status();

  std::vector<v1::ComputeVoronoiResponse> messages = api::VoronoiToProto(
      *diagram, solved->sources, request.omit_cell_faces(), env.limits->stream_chunk_bytes);
  return Streamed(std::move(messages), *solved, request.want_stats());
}

absl::StatusOr<MessageStream<v1::ComputeDelaunayResponse>> RunComputeDelaunay(
    const QueryEnv& env, const v1::ComputeDelaunayRequest& request) {
  absl::StatusOr<SolvedField> solved =
      SolveField(env, request.mesh(), request.sources(), request.options());
  if (!solved.ok()) return solved.status();
  absl::StatusOr<DelaunayTriangulation> delaunay =
      BuildDelaunay(*solved->mesh->mesh, *solved->field);
  if (!delaunay.ok()) return delaunay.status();

  std::vector<v1::ComputeDelaunayResponse> messages =
      api::DelaunayToProto(*delaunay, solved->sources, env.limits->stream_chunk_bytes);
  return Streamed(std::move(messages), *solved, request.want_stats());
}

}  // namespace geodex::server
