#include "geodex/geometry_queries.h"

namespace geodex {

absl::Status ValidateIsolineQuery(const IsolineQuery& query, uint64_t max_levels) {
  if (absl::Status s = ValidateGeodesicOptions(query.options); !s.ok()) return s;
  return ValidateIsolineOptions(query.levels, max_levels);
}

absl::StatusOr<Isolines> ComputeIsolines(const TriangleMesh& mesh, const IsolineQuery& query) {
  if (absl::Status s = ValidateIsolineQuery(query); !s.ok()) return s;
  absl::StatusOr<DistanceField> field = ComputeDistanceField(mesh, query.sources, query.options);
  if (!field.ok()) return field.status();
  return ExtractIsolines(mesh, *field, query.levels);
}

absl::StatusOr<VoronoiDiagram> ComputeVoronoi(const TriangleMesh& mesh, const VoronoiQuery& query) {
  absl::StatusOr<DistanceField> field = ComputeDistanceField(mesh, query.sites, query.options);
  if (!field.ok()) return field.status();
  return BuildVoronoi(mesh, *field);
}

absl::StatusOr<DelaunayTriangulation> ComputeDelaunay(const TriangleMesh& mesh,
                                                      const DelaunayQuery& query) {
  absl::StatusOr<DistanceField> field = ComputeDistanceField(mesh, query.sites, query.options);
  if (!field.ok()) return field.status();
  return BuildDelaunay(mesh, *field);
}

}  // namespace geodex
