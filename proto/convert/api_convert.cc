#include "api_convert.h"

#include <cmath>

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

void SolverOptionsToProto(const GeodesicOptions& options, v1::SolverOptions* out) {
  out->set_lambda(options.lambda);
  out->set_lambda_scale(options.lambda_scale == LambdaScale::kMeanEdge
                            ? v1::LAMBDA_SCALE_MEAN_EDGE
                            : v1::LAMBDA_SCALE_MAX_EDGE);
  if (std::isfinite(options.max_distance)) out->set_max_distance(options.max_distance);
}

}  // namespace geodex::api
