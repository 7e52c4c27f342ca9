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

// The geometry's messages as a stream: the sources' snap distances in the first one, the field's
// stats in the last one when asked for.
template <typename Response>
MessageProducer<Response> Streamed(std::vector<Response> messages, const SolvedField& solved,
                                   bool want_stats) {
  SnapsToProto(solved.snaps, &messages.front());
  if (want_stats) FieldStatsToProto(*solved.field, solved.cached, messages.back().mutable_stats());
  return ProducerOf(std::move(messages));
}

}  // namespace

absl::StatusOr<MessageStream<v1::ComputeIsolinesResponse>> RunComputeIsolines(
    const QueryEnv& env, const v1::ComputeIsolinesRequest& request) {
  absl::StatusOr<IsolineOptions> options = IsolineLevels(env, api::IsolineLevelsFromProto(request));
  if (!options.ok()) return options.status();
  absl::StatusOr<SolvedField> solved = SolveField(env, request.mesh(), request.sources(),
                                                  request.options(), SnapsOf(request), &*options);
  if (!solved.ok()) return solved.status();
  absl::StatusOr<Isolines> isolines =
      ExtractIsolines(*solved->mesh->mesh, *solved->field, *options);
  if (!isolines.ok()) return isolines.status();

  std::vector<v1::ComputeIsolinesResponse> messages =
      api::IsolinesToProto(*isolines, env.limits->stream_chunk_bytes);
  messages.front().set_travel_epsilon(solved->field->travel_epsilon);
  messages.front().set_travel_exact(solved->field->travel_exact);
  return Streamed(std::move(messages), *solved, request.want_stats());
}

absl::StatusOr<MessageStream<v1::ComputeVoronoiResponse>> RunComputeVoronoi(
    const QueryEnv& env, const v1::ComputeVoronoiRequest& request) {
  absl::StatusOr<SolvedField> solved =
      SolveField(env, request.mesh(), request.sources(), request.options(), SnapsOf(request));
  if (!solved.ok()) return solved.status();
  absl::StatusOr<VoronoiDiagram> diagram =
      BuildVoronoi(*solved->mesh->mesh, *solved->field,
                   solved->options.travel.has_value() ? &*solved->options.travel : nullptr);
  if (!diagram.ok()) return diagram.status();

  std::vector<v1::ComputeVoronoiResponse> messages = api::VoronoiToProto(
      *diagram, solved->sources, request.omit_cell_faces(), env.limits->stream_chunk_bytes);
  messages.front().set_travel_epsilon(solved->field->travel_epsilon);
  messages.front().set_travel_exact(solved->field->travel_exact);
  return Streamed(std::move(messages), *solved, request.want_stats());
}

absl::StatusOr<MessageStream<v1::ComputeDelaunayResponse>> RunComputeDelaunay(
    const QueryEnv& env, const v1::ComputeDelaunayRequest& request) {
  if (absl::Status s = RefuseTravel(request.options(), kDelaunayNeedsOrigins); !s.ok()) return s;
  absl::StatusOr<SolvedField> solved =
      SolveField(env, request.mesh(), request.sources(), request.options(), SnapsOf(request));
  if (!solved.ok()) return solved.status();
  absl::StatusOr<DelaunayTriangulation> delaunay =
      BuildDelaunay(*solved->mesh->mesh, *solved->field);
  if (!delaunay.ok()) return delaunay.status();

  std::vector<v1::ComputeDelaunayResponse> messages =
      api::DelaunayToProto(*delaunay, solved->sources, env.limits->stream_chunk_bytes);
  return Streamed(std::move(messages), *solved, request.want_stats());
}

}  // namespace geodex::server
