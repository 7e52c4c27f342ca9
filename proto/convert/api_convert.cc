#include "api_convert.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"

namespace geodex::api {

void SurfacePointToProto(const SurfacePoint& point, v1::SurfacePoint* out) {
  switch (point.kind) {
    case SurfacePoint::Kind::kVertex:
      out->set_vertex(point.vertex);
      break;
    case SurfacePoint::Kind::kEdge: {
      v1::EdgePoint* e = out->mutable_edge();
      e->set_from(point.edge_from);
      e->set_to(point.edge_to);
      e->set_t(point.t);
      break;
    }
    case SurfacePoint::Kind::kFace: {
      v1::FacePoint* f = out->mutable_face();
      f->set_face(point.face);
      f->set_b0(point.bary[0]);
      f->set_b1(point.bary[1]);
      f->set_b2(point.bary[2]);
      break;
    }
    case SurfacePoint::Kind::kPosition:
      PositionToProto(point.position, out->mutable_position());
      break;
  }
}

SurfacePoint SurfacePointFromProto(const v1::SurfacePoint& point) {
  switch (point.point_case()) {
    case v1::SurfacePoint::kEdge:
      return SurfacePoint::OnEdge(point.edge().from(), point.edge().to(), point.edge().t());
    case v1::SurfacePoint::kFace:
      return SurfacePoint::InFace(point.face().face(), point.face().b0(), point.face().b1(),
                                  point.face().b2());
    case v1::SurfacePoint::kPosition: {
      SurfacePoint p;
      p.kind = SurfacePoint::Kind::kPosition;
      p.position = PositionFromProto(point.position());
      return p;
    }
    case v1::SurfacePoint::kVertex:
    case v1::SurfacePoint::kMapPoint:  // map points need the DEM: the server drops them
    case v1::SurfacePoint::kLonLat:
    case v1::SurfacePoint::POINT_NOT_SET:
      break;
  }
  return SurfacePoint::AtVertex(point.vertex());
}

void PositionToProto(const std::array<double, 3>& position, v1::Position* out) {
  out->set_x(position[0]);
  out->set_y(position[1]);
  out->set_z(position[2]);
}

std::array<double, 3> PositionFromProto(const v1::Position& position) {
  return {position.x(), position.y(), position.z()};
}

void PathPointToProto(const PathPoint& point, v1::PathPoint* out) {
  PositionToProto(point.position, out->mutable_position());
  SurfacePointToProto(point.where, out->mutable_where());
}

PathPoint PathPointFromProto(const v1::PathPoint& point) {
  PathPoint p;
  p.position = PositionFromProto(point.position());
  p.where = SurfacePointFromProto(point.where());
  return p;
}

void StatsToProto(const SolveStats& stats, v1::SolveStats* out) {
  out->set_windows_created(stats.windows_created);
  out->set_windows_processed(stats.windows_processed);
  out->set_windows_filtered(stats.windows_filtered_at_creation + stats.windows_filtered_at_pop);
  out->set_pseudo_sources(stats.pseudo_sources);
  out->set_edge_relaxations(stats.edge_relaxations);
  out->set_max_level(stats.max_level);
  out->set_peak_live_windows(stats.peak_live_windows);
  out->set_peak_bytes(stats.peak_bytes);
  out->set_solve_ms(stats.solve_ms);
}

SolveStats StatsFromProto(const v1::SolveStats& stats) {
  SolveStats s;
  s.windows_created = stats.windows_created();
  s.windows_processed = stats.windows_processed();
  s.windows_filtered_at_pop = stats.windows_filtered();
  s.pseudo_sources = stats.pseudo_sources();
  s.edge_relaxations = stats.edge_relaxations();
  s.max_level = stats.max_level();
  s.peak_live_windows = stats.peak_live_windows();
  s.peak_bytes = stats.peak_bytes();
  s.solve_ms = stats.solve_ms();
  return s;
}

void MeshSummaryToProto(const MeshSummary& s, v1::Mesh* out) {
  const MeshReport& r = s.report;
  out->set_vertex_count(r.file_vertices);
  out->set_face_count(r.file_faces);
  out->set_boundary_edges(r.boundary_edges);
  out->set_components(r.components);
  out->set_non_manifold_edges(r.non_manifold_edges);
  out->set_degenerate_faces(r.degenerate_faces);
  v1::MeshInfo* info = out->mutable_info();
  info->set_boundary_loops(r.boundary_loops);
  info->set_vertex_connected_components(r.vertex_connected_components);
  info->set_isolated_vertices(r.isolated_vertices);
  info->set_non_manifold_vertices(r.non_manifold_vertices);
  info->set_flipped_faces(r.flipped_faces);
  info->set_orientation_cuts(r.orientation_cuts);
  info->set_saddle_vertices(r.saddle_vertices);
  info->set_boundary_vertices(r.boundary_vertices);
  info->set_internal_vertices(s.internal_vertices);
  info->set_mean_edge_length(s.mean_edge_length);
  info->set_max_edge_length(s.max_edge_length);
  PositionToProto(s.bbox_min, info->mutable_bbox_min());
  PositionToProto(s.bbox_max, info->mutable_bbox_max());
  info->set_mesh_bytes(s.bytes);
}

MeshSummary MeshSummaryFromProto(const v1::Mesh& m) {
  MeshSummary s;
  MeshReport& r = s.report;
  const v1::MeshInfo& i = m.info();
  r.file_vertices = m.vertex_count();
  r.file_faces = m.face_count();
  r.boundary_edges = m.boundary_edges();
  r.components = m.components();
  r.non_manifold_edges = m.non_manifold_edges();
  r.degenerate_faces = m.degenerate_faces();
  r.boundary_loops = i.boundary_loops();
  r.vertex_connected_components = i.vertex_connected_components();
  r.isolated_vertices = i.isolated_vertices();
  r.non_manifold_vertices = i.non_manifold_vertices();
  r.flipped_faces = i.flipped_faces();
  r.orientation_cuts = i.orientation_cuts();
  r.saddle_vertices = i.saddle_vertices();
  r.boundary_vertices = i.boundary_vertices();
  s.internal_vertices = i.internal_vertices();
  s.mean_edge_length = i.mean_edge_length();
  s.max_edge_length = i.max_edge_length();
  s.bbox_min = PositionFromProto(i.bbox_min());
  s.bbox_max = PositionFromProto(i.bbox_max());
  s.bytes = i.mesh_bytes();
  return s;
}

void SolverOptionsToProto(const GeodesicOptions& options, v1::SolverOptions* out) {
  out->set_lambda(options.lambda);
  out->set_lambda_scale(options.lambda_scale == LambdaScale::kMeanEdge ? v1::LAMBDA_SCALE_MEAN_EDGE
                                                                       : v1::LAMBDA_SCALE_MAX_EDGE);
  if (std::isfinite(options.max_distance)) out->set_max_distance(options.max_distance);
  if (options.travel) {
    const TravelCost& travel = *options.travel;
    v1::TravelCost* t = out->mutable_travel();
    t->set_speed_kmh(travel.speed_kmh);
    if (travel.epsilon.has_value()) t->set_epsilon(*travel.epsilon);  // unset: the model's default
    t->set_max_slope_deg(travel.max_slope_deg);
    if (travel.face_weight != nullptr) {
      t->mutable_face_weights()->Add(travel.face_weight->begin(), travel.face_weight->end());
    }
    switch (travel.speed_model) {
      case SpeedModel::kConstant:
        t->set_speed_model(v1::SPEED_MODEL_CONSTANT);
        break;
      case SpeedModel::kTobler:
        t->set_speed_model(v1::SPEED_MODEL_TOBLER);
        break;
      case SpeedModel::kTable:
        t->set_speed_model(v1::SPEED_MODEL_TABLE);
        break;
    }
    if (travel.speed_table != nullptr) {
      for (const std::array<double, 2>& row : *travel.speed_table) {
        v1::SpeedTableRow* r = t->add_speed_table();
        r->set_slope_deg(row[0]);
        r->set_speed_kmh(row[1]);
      }
    }
    t->set_inbound(travel.inbound);
    // max_steiner_points is the server's (--max_steiner_points), not the request's.
  }
}

absl::StatusOr<GeodesicOptions> SolverOptionsFromProto(const v1::SolverOptions& options) {
  GeodesicOptions out;
  out.lambda = options.lambda();
  switch (options.lambda_scale()) {
    case v1::LAMBDA_SCALE_UNSPECIFIED:
    case v1::LAMBDA_SCALE_MAX_EDGE:
      out.lambda_scale = LambdaScale::kMaxEdge;
      break;
    case v1::LAMBDA_SCALE_MEAN_EDGE:
      out.lambda_scale = LambdaScale::kMeanEdge;
      break;
    default:
      return OptionError("lambda_scale", absl::StrCat("unknown value ", options.lambda_scale()));
  }
  if (options.has_max_distance()) out.max_distance = options.max_distance();
  if (options.has_travel()) {
    const v1::TravelCost& t = options.travel();
    TravelCost travel;
    travel.speed_kmh = t.speed_kmh();
    if (t.has_epsilon()) travel.epsilon = t.epsilon();
    travel.max_slope_deg = t.max_slope_deg();
    switch (t.speed_model()) {
      case v1::SPEED_MODEL_UNSPECIFIED:
      case v1::SPEED_MODEL_CONSTANT:
        travel.speed_model = SpeedModel::kConstant;
        break;
      case v1::SPEED_MODEL_TOBLER:
        travel.speed_model = SpeedModel::kTobler;
        break;
      case v1::SPEED_MODEL_TABLE:
        travel.speed_model = SpeedModel::kTable;
        break;
      default:
        return OptionError("travel.speed_model", absl::StrCat("unknown value ", t.speed_model()));
    }
    if (!t.speed_table().empty()) {  // core checks the rows (and that the model reads them)
      auto table = std::make_shared<std::vector<std::array<double, 2>>>();
      table->reserve(t.speed_table_size());
      for (const v1::SpeedTableRow& row : t.speed_table()) {
        table->push_back({row.slope_deg(), row.speed_kmh()});
      }
      travel.speed_table = std::move(table);
    }
    travel.inbound = t.inbound();
    if (!t.face_weights().empty() && !t.friction_geojson().empty()) {
      return OptionError("travel.friction_geojson",
                         "give at most one of face_weights and friction_geojson");
    }
    // (their count and values are the engine's to check against the mesh: "face_weight[i]")
    if (!t.face_weights().empty()) {
      travel.face_weight = std::make_shared<const std::vector<double>>(t.face_weights().begin(),
                                                                       t.face_weights().end());
    }
    out.travel = std::move(travel);
  }
  if (absl::Status s = ValidateGeodesicOptions(out); !s.ok()) return s;  // core's one check
  return out;
}

void PointQueryToProto(const PointQuery& query, v1::EstimateDistancesRequest* out) {
  for (const SurfacePoint& p : query.sources) SurfacePointToProto(p, out->add_sources());
  for (const SurfacePoint& p : query.points) SurfacePointToProto(p, out->add_points());
  SolverOptionsToProto(query.options, out->mutable_options());
  out->set_want_directions(query.directions);
}

void PointValuesToProto(const PointValues& values, v1::EstimateDistancesResponse* out) {
  for (size_t i = 0; i < values.distance.size(); ++i) {
    out->add_exact(values.distance[i]);
    out->add_exact_labels(values.source[i]);
  }
  for (const std::array<double, 3>& d : values.direction) {
    for (double x : d) out->add_exact_directions(x);
  }
}

PointValues PointValuesFromProto(const v1::EstimateDistancesResponse& response) {
  PointValues out;
  out.distance.assign(response.exact().begin(), response.exact().end());
  out.source.assign(response.exact_labels().begin(), response.exact_labels().end());
  for (int i = 0; i + 2 < response.exact_directions_size(); i += 3) {
    out.direction.push_back({response.exact_directions(i), response.exact_directions(i + 1),
                             response.exact_directions(i + 2)});
  }
  if (response.has_exact_stats()) out.stats = StatsFromProto(response.exact_stats());
  return out;
}

void PointEstimateToProto(const PointEstimate& estimate, v1::EstimateDistancesResponse* out) {
  out->add_estimates(estimate.distance);
  out->add_estimate_labels(estimate.source);
}

std::vector<PointEstimate> PointEstimatesFromProto(const v1::EstimateDistancesResponse& response) {
  std::vector<PointEstimate> out;
  for (int i = 0; i < response.estimates_size() && i < response.estimate_labels_size(); ++i) {
    out.push_back({response.estimates(i), response.estimate_labels(i)});
  }
  return out;
}

void FieldQueryToProto(const FieldQuery& query, v1::ComputeDistanceFieldRequest* out) {
  for (const SurfacePoint& p : query.sources) SurfacePointToProto(p, out->add_sources());
  SolverOptionsToProto(query.options, out->mutable_options());
  out->set_want_directions(query.directions);
}

size_t FieldBytesPerVertex(const FieldEncoding& encoding, const DistanceField& products) {
  return (encoding.f32 ? 4 : 8) + (encoding.labels ? 4 : 0) + (products.direction.empty() ? 0 : 24);
}

void FieldChunkToProto(const DistanceField& field, const DistanceField& products, size_t begin,
                       size_t end, const FieldEncoding& encoding,
                       v1::ComputeDistanceFieldResponse* out) {
  out->set_vertex_count(field.distance.size());
  out->set_offset(begin);
  if (begin == 0) {
    for (const SurfacePoint& p : field.sources) SurfacePointToProto(p, out->add_resolved_sources());
    out->set_travel_epsilon(field.travel_epsilon);
    out->set_travel_exact(field.travel_exact);
  }
  if (encoding.f32) {
    auto* values = out->mutable_distances_f32();
    values->Reserve(static_cast<int>(end - begin));
    for (size_t i = begin; i < end; ++i) {
      values->AddAlreadyReserved(static_cast<float>(field.distance[i]));
    }
  } else {
    out->mutable_distances_f64()->Add(field.distance.begin() + begin, field.distance.begin() + end);
  }
  if (encoding.labels) {
    out->mutable_labels()->Add(field.source.begin() + begin, field.source.begin() + end);
  }
  if (!products.direction.empty()) {
    out->mutable_directions()->Reserve(static_cast<int>(3 * (end - begin)));
    for (size_t i = begin; i < end; ++i) {
      for (double c : products.direction[i]) out->mutable_directions()->AddAlreadyReserved(c);
    }
  }
}

void FieldAssembler::Add(const v1::ComputeDistanceFieldResponse& message) {
  if (message.offset() == 0) {
    field_.travel_epsilon = message.travel_epsilon();
    field_.travel_exact = message.travel_exact();
    field_.snap_distances.assign(message.snap_distances().begin(), message.snap_distances().end());
    field_.distance.reserve(message.vertex_count());
    field_.source.reserve(message.vertex_count());
    for (const auto& p : message.resolved_sources()) {
      field_.sources.push_back(SurfacePointFromProto(p));
    }
  }
  field_.distance.insert(field_.distance.end(), message.distances_f64().begin(),
                         message.distances_f64().end());
  field_.distance.insert(field_.distance.end(), message.distances_f32().begin(),
                         message.distances_f32().end());
  field_.source.insert(field_.source.end(), message.labels().begin(), message.labels().end());
  for (int i = 0; i + 2 < message.directions_size(); i += 3) {
    field_.direction.push_back(
        {message.directions(i), message.directions(i + 1), message.directions(i + 2)});
  }
  if (message.has_stats()) {
    field_.stats = StatsFromProto(message.stats());
    cached_ = message.stats().cached();
  }
}

void PathQueryToProto(const PathQuery& query, v1::FindShortestPathRequest* out) {
  SurfacePointToProto(query.from, out->mutable_from());
  SurfacePointToProto(query.to, out->mutable_to());
  SolverOptionsToProto(query.options.solver, out->mutable_options());
}

void MatrixQueryToProto(const MatrixQuery& query, v1::ComputeDistanceMatrixRequest* out) {
  for (const SurfacePoint& p : query.sources) SurfacePointToProto(p, out->add_sources());
  for (const SurfacePoint& p : query.targets) SurfacePointToProto(p, out->add_targets());
  SolverOptionsToProto(query.options.solver, out->mutable_options());
  out->set_k_nearest(query.options.k_nearest);
}

void PathResultToProto(double distance, double length_m, const std::vector<PathPoint>& points,
                       v1::FindShortestPathResponse* out) {
  out->set_distance(distance);
  out->set_length_m(length_m);
  for (const PathPoint& p : points) PathPointToProto(p, out->add_points());
}

PathQueryResult PathResultFromProto(const v1::FindShortestPathResponse& response) {
  PathQueryResult result;
  result.distance = response.distance();
  // Metres along the surface (a server before length_m sent only `distance`: metres when exact).
  result.path.length = response.length_m() > 0 || response.travel_epsilon() > 0
                           ? response.length_m()
                           : response.distance();
  for (const auto& p : response.points()) result.path.points.push_back(PathPointFromProto(p));
  if (response.has_stats()) result.stats = StatsFromProto(response.stats());
  result.snap_distances.assign(response.snap_distances().begin(), response.snap_distances().end());
  return result;
}

void LocatedPointToProto(const LocatedPoint& point, v1::LocatedPoint* out) {
  SurfacePointToProto(point.point, out->mutable_point());
  PositionToProto(point.position, out->mutable_position());
  out->set_distance(point.distance);
}

LocatedPoint LocatedPointFromProto(const v1::LocatedPoint& point) {
  return {SurfacePointFromProto(point.point()), PositionFromProto(point.position()),
          point.distance()};
}

void MatrixChunkToProto(size_t rows, size_t cols, const std::vector<double>& values, size_t begin,
                        size_t end, bool f32, v1::ComputeDistanceMatrixResponse* out) {
  out->set_rows(rows);
  out->set_cols(cols);
  out->set_offset(begin);
  if (f32) {
    for (size_t i = begin; i < end; ++i) out->add_values_f32(static_cast<float>(values[i]));
  } else {
    out->mutable_values_f64()->Add(values.begin() + begin, values.begin() + end);
  }
}

void MatrixAssembler::Add(const v1::ComputeDistanceMatrixResponse& message) {
  matrix_.rows = message.rows();
  matrix_.cols = message.cols();
  if (message.snap_distances_size() > 0) {  // the first message's
    matrix_.snap_distances.assign(message.snap_distances().begin(), message.snap_distances().end());
  }
  matrix_.values.insert(matrix_.values.end(), message.values_f64().begin(),
                        message.values_f64().end());
  matrix_.values.insert(matrix_.values.end(), message.values_f32().begin(),
                        message.values_f32().end());
  if (message.has_stats()) matrix_.stats = StatsFromProto(message.stats());
  progress_ = message.progress();
}

size_t MatrixAssembler::rows_done() const {
  if (matrix_.cols == 0) return 0;
  const size_t solved = static_cast<size_t>(progress_ * matrix_.rows);
  return std::max(matrix_.values.size() / matrix_.cols, solved);
}

}  // namespace geodex::api
