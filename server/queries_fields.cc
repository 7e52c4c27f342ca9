// Streamed distances: ComputeDistanceField and ComputeDistanceMatrix (rows streamed as they
// finish).

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "field_cache.h"
#include "geodex/distance_matrix.h"
#include "geodex/geodesic_solver.h"
#include "proto_convert.h"
#include "queries.h"
#include "query_support.h"
#include "service_limits.h"
#include "status_convert.h"

namespace geodex::server {

// ------------------------------------------------------------------------------------------
// Streamed queries

absl::StatusOr<MessageStream<v1::ComputeDistanceFieldResponse>> RunComputeDistanceField(
    const QueryEnv& env, const v1::ComputeDistanceFieldRequest& request) {
  if (!v1::ValueType_IsValid(request.value_type())) {
    return FieldError("value_type", absl::StrCat("unknown value ", request.value_type()));
  }
  absl::StatusOr<SolvedField> solved =
      SolveField(env, request.mesh(), request.sources(), request.options(), SnapsOf(request));
  if (!solved.ok()) return solved.status();

  // Produced lazily from the field: no second copy of a large result. The products the request
  // asks for go beside the cached field, which stays as it is.
  // (The field's own sources, sent in the first message, are solved.sources: the cache keys
  // fields by them.)
  FieldQuery query;
  query.sources = solved->sources;
  query.directions = request.want_directions();
  struct State {
    SolvedField solved;      // the shared field: chunks are read from it, never copied whole
    DistanceField products;  // ComputeFieldProducts' members only
    size_t next = 0;
    bool started = false;
  };
  auto state = std::make_shared<State>();
  state->solved = *std::move(solved);
  if (absl::Status s = ComputeFieldProducts(*state->solved.mesh->mesh, *state->solved.field, query,
                                            &state->products);
      !s.ok()) {
    return FieldError("options.travel", s.message());  // directions with a travel cost
  }
  api::FieldEncoding encoding;
  encoding.f32 = request.value_type() == v1::VALUE_TYPE_FLOAT32;
  encoding.labels = !request.omit_labels();
  const bool want_stats = request.want_stats();
  const size_t chunk = std::max<size_t>(
      1, env.limits->stream_chunk_bytes / api::FieldBytesPerVertex(encoding, state->products));
  return MessageProducer<v1::ComputeDistanceFieldResponse>(
      [state, encoding, want_stats, chunk](v1::ComputeDistanceFieldResponse* out) {
        const DistanceField& field = *state->solved.field;
        const size_t n = field.distance.size();
        if (state->started && state->next >= n) return false;
        const size_t begin = state->next, end = std::min(n, begin + chunk);
        api::FieldChunkToProto(field, state->products, begin, end, encoding, out);
        if (!state->started) SnapsToProto(state->solved.snaps, out);
        if (end == n && want_stats) {
          FieldStatsToProto(field, state->solved.cached, out->mutable_stats());
        }
        state->started = true;
        state->next = end;
        return true;
      });
}

namespace {

using FinalRowFn = std::function<void(size_t row, const double* values)>;

// The rows of a matrix: from cached full fields where possible (see RunComputeDistanceMatrix),
// the rest solved in one engine call. `*cached` is true when nothing was solved. Each row goes to
// `on_final_row` as soon as it and every row before it are final, in order.
absl::StatusOr<DistanceMatrix> SolveMatrixRows(const QueryEnv& env, const StoredMesh& mesh,
                                               const std::vector<SurfacePoint>& sources,
                                               const std::vector<SurfacePoint>& targets,
                                               const GeodesicOptions& solver, uint32_t k_nearest,
                                               bool symmetric, const FinalRowFn& on_final_row,
                                               const std::function<void(double)>& on_progress,
                                               bool* cached) {
  DistanceMatrix out;
  out.rows = sources.size();
  out.cols = targets.size();
  out.values.assign(out.rows * out.cols, std::numeric_limits<double>::infinity());
  std::vector<size_t> missing;
  std::vector<char> row_final(out.rows, 0);
  size_t next_final = 0;
  auto hand_out = [&] {  // the final prefix, in order
    for (; next_final < out.rows && row_final[next_final]; ++next_final) {
      on_final_row(next_final, &out.values[next_final * out.cols]);
    }
  };
  const bool vertex_targets =
      std::all_of(targets.begin(), targets.end(),
                  [](const SurfacePoint& p) { return p.kind == SurfacePoint::Kind::kVertex; });
  for (size_t r = 0; r < sources.size(); ++r) {
    std::shared_ptr<const DistanceField> field;
    if (vertex_targets && !symmetric && env.cache->enabled()) {
      field = env.cache->Find(FieldCacheKey(mesh.id, {sources[r]}, solver));
    }
    if (field == nullptr) {
      missing.push_back(r);
      continue;
    }
    double* row = &out.values[r * out.cols];
    for (size_t c = 0; c < targets.size(); ++c) row[c] = field->distance[targets[c].vertex];
    KeepKNearest(k_nearest, row, targets.size());  // as the engine's rows do
    row_final[r] = 1;
  }
  hand_out();
  *cached = missing.empty();
  if (missing.empty()) return out;

  std::vector<SurfacePoint> rest;
  rest.reserve(missing.size());
  for (size_t r : missing) rest.push_back(sources[r]);
  MatrixOptions matrix_options;
  matrix_options.solver = solver;
  ShareTravelSurface(env, mesh, &matrix_options.solver);
  matrix_options.k_nearest = k_nearest;
  if (env.pool != nullptr) {
    // Rows beyond the calling worker's go to the shared pool, behind work already queued; a
    // refused helper (queue full) only means fewer rows at once.
    ComputePool* pool = env.pool;
    matrix_options.threads = static_cast<unsigned>(pool->threads());
    matrix_options.spawn = [pool](std::function<void()> helper) {
      pool->TrySubmit(std::move(helper));
    };
  } else {
    matrix_options.threads = 1;
  }
  const double cached_rows = static_cast<double>(out.rows - missing.size());
  matrix_options.on_row = [&](size_t done, size_t total) {
    on_progress((cached_rows + static_cast<double>(done) / total * missing.size()) / out.rows);
  };
  // The engine hands out its rows one at a time, in order: place each, then pass on the prefix.
  matrix_options.on_final_row = [&](size_t i, const double* values) {
    std::copy_n(values, out.cols, out.values.begin() + missing[i] * out.cols);
    row_final[missing[i]] = 1;
    hand_out();
  };
  absl::StatusOr<DistanceMatrix> matrix =
      ComputeDistanceMatrix(*mesh.mesh, rest, targets, matrix_options);
  if (!matrix.ok()) return NameSolveError(matrix.status(), "sources/targets");
  env.counters->solves.fetch_add(1, std::memory_order_relaxed);
  env.counters->windows_processed.fetch_add(matrix->stats.windows_processed,
                                            std::memory_order_relaxed);
  out.stats = matrix->stats;
  return out;
}

// A matrix on its way to the client: rows are added as they become final (the first
// `final_values` values), `done` once the solve has returned and `stats` are set.
struct MatrixStreamState {
  std::mutex mu;
  size_t rows = 0, cols = 0;
  std::vector<double> values;
  size_t final_values = 0;
  bool done = false;
  SolveStats stats;
  bool cached = false;
  std::vector<double> snap_distances;      // sent in the first message
  double travel_epsilon = 0;               // sent in the first message
  bool travel_exact = false;               // sent in the first message
  size_t next = 0;                         // the next value to send
  bool sent = false;                       // a message went out (an empty matrix still gets one)
  double progress = 0, progress_sent = 0;  // fraction of the solves done; the last one sent
};

// The next message of a matrix stream: the final values not sent yet (at most `chunk`), the last
// value held back until the solve returned so that the stats ride with it.
Produced NextMatrixMessage(MatrixStreamState& state, bool f32, bool want_stats, size_t chunk,
                           v1::ComputeDistanceMatrixResponse* out) {
  std::lock_guard<std::mutex> lock(state.mu);
  const size_t n = state.values.size();
  if (state.done && state.next >= n && (n > 0 || state.sent)) return Produced::kEnd;
  const size_t ready = state.done ? n : std::min(state.final_values, n > 0 ? n - 1 : 0);
  const double progress = state.done ? 1.0 : state.progress;
  // Progress alone is worth a message in steps of 1% (rows that wait on others).
  const bool progressed = progress >= state.progress_sent + 0.01;
  if (state.next >= ready && !(state.done && !state.sent) && !progressed) return Produced::kLater;
  const size_t begin = state.next, end = std::min(ready, begin + chunk);
  api::MatrixChunkToProto(state.rows, state.cols, state.values, begin, end, f32, out);
  out->set_progress(progress);
  if (!state.sent) {
    out->mutable_snap_distances()->Add(state.snap_distances.begin(), state.snap_distances.end());
    out->set_travel_epsilon(state.travel_epsilon);
    out->set_travel_exact(state.travel_exact);
  }
  state.progress_sent = progress;
  if (end == n && want_stats) {
    StatsToProto(state.stats, out->mutable_stats());
    out->mutable_stats()->set_cached(state.cached);
  }
  state.next = end > begin ? end : (n == 0 ? 1 : begin);
  state.sent = true;
  return Produced::kMessage;
}

}  // namespace

absl::StatusOr<MessageStream<v1::ComputeDistanceMatrixResponse>> RunComputeDistanceMatrix(
    const QueryEnv& env, const v1::ComputeDistanceMatrixRequest& request) {
  if (!v1::ValueType_IsValid(request.value_type())) {
    return FieldError("value_type", absl::StrCat("unknown value ", request.value_type()));
  }
  absl::StatusOr<std::shared_ptr<const StoredMesh>> mesh = LookupMesh(env, request.mesh(), "mesh");
  if (!mesh.ok()) return mesh.status();
  absl::StatusOr<PointSnaps> snaps = SnapsOf(request);
  if (!snaps.ok()) return snaps.status();
  absl::StatusOr<std::vector<SurfacePoint>> sources =
      ResolveSources(env, **mesh, request.sources(), &*snaps);
  if (!sources.ok()) return sources.status();
  absl::StatusOr<std::vector<SurfacePoint>> targets = ResolvePoints(
      **mesh, request.targets(), "targets", env.limits->max_targets, "max_targets", &*snaps);
  if (!targets.ok()) return targets.status();
  const uint64_t values = uint64_t{sources->size()} * targets->size();
  if (values > env.limits->max_output_values) {
    return ServerLimitError(
        "max_output_values",
        absl::StrCat("the matrix has ", sources->size(), " x ", targets->size(), " = ", values,
                     " values, over --max_output_values=", env.limits->max_output_values));
  }
  absl::StatusOr<GeodesicOptions> solver = Options(env, **mesh, request.options());
  if (!solver.ok()) return solver.status();

  // Reuse (issue 19): a repeated matrix is one cache entry (values as a DistanceField); otherwise
  // rows whose source has a full field in the cache are read from it when every target is a
  // vertex (not for symmetric requests, whose pairs the engine solves once and mirrors), and only
  // the other rows are solved.
  const std::string sources_key = FieldCacheKey((*mesh)->id, *sources, *solver);
  const std::string targets_key = FieldCacheKey("", *targets, *solver);
  std::string matrix_key =
      absl::StrCat(sources_key, "|matrix|", targets_key, "|k", request.k_nearest());
  std::shared_ptr<const DistanceField> cached_matrix = env.cache->Find(matrix_key, !env.quick);
  if (cached_matrix == nullptr && env.quick) return SolveLaneNeeded();

  auto state = std::make_shared<MatrixStreamState>();
  state->rows = sources->size();
  state->cols = targets->size();
  state->snap_distances = std::move(snaps->distances);
  state->travel_epsilon = TravelEpsilon(*solver);
  state->travel_exact = TravelExact(*solver);
  const bool f32 = request.value_type() == v1::VALUE_TYPE_FLOAT32;
  const bool want_stats = request.want_stats();
  const size_t chunk = std::max<size_t>(1, env.limits->stream_chunk_bytes / (f32 ? 4 : 8));
  auto next = [state, f32, want_stats, chunk](v1::ComputeDistanceMatrixResponse* out) {
    return NextMatrixMessage(*state, f32, want_stats, chunk, out);
  };
  if (cached_matrix != nullptr) {
    state->values = cached_matrix->distance;
    state->final_values = state->values.size();
    state->stats = cached_matrix->stats;
    state->cached = state->done = true;
    return MessageStream<v1::ComputeDistanceMatrixResponse>(std::move(next), nullptr);
  }
  // Solved while streaming (issue 19): each row is sent as soon as it and the rows before it are
  // final, so a client sees progress; the whole matrix then enters the cache.
  state->values.assign(values, std::numeric_limits<double>::infinity());
  const bool symmetric = sources_key == FieldCacheKey((*mesh)->id, *targets, *solver);
  auto work = [env, mesh = *std::move(mesh), sources = *std::move(sources),
               targets = *std::move(targets), solver = *solver, k = request.k_nearest(), symmetric,
               matrix_key = std::move(matrix_key),
               state](const std::function<void()>& ready) -> absl::Status {
    auto on_final_row = [&](size_t row, const double* row_values) {
      {
        std::lock_guard<std::mutex> lock(state->mu);
        std::copy_n(row_values, state->cols, state->values.begin() + row * state->cols);
        state->final_values = (row + 1) * state->cols;
      }
      ready();
    };
    auto on_progress = [&](double progress) {
      {
        std::lock_guard<std::mutex> lock(state->mu);
        state->progress = progress;
      }
      ready();
    };
    bool cached = false;
    absl::StatusOr<DistanceMatrix> solved = SolveMatrixRows(
        env, *mesh, sources, targets, solver, k, symmetric, on_final_row, on_progress, &cached);
    if (!solved.ok()) return solved.status();
    auto entry = std::make_shared<DistanceField>();
    entry->distance = std::move(solved->values);  // the stream already holds every row
    entry->stats = solved->stats;
    env.cache->Insert(matrix_key, std::move(entry));
    std::lock_guard<std::mutex> lock(state->mu);
    state->stats = solved->stats;
    state->cached = cached;
    state->done = true;
    return absl::OkStatus();
  };
  return MessageStream<v1::ComputeDistanceMatrixResponse>(std::move(next), std::move(work));
}

}  // namespace geodex::server
