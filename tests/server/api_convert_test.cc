// proto/convert's mappings, both directions: the streamed geometry (geometry_convert.h) cut into
// many small messages (pieces split mid-polyline and mid-cell) and reassembled gives back exactly
// what core computed; a mesh's summary survives the Mesh resource (api_convert.h).

#include "api_convert.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "absl/strings/str_format.h"
#include "geodex/delaunay.h"
#include "geodex/geodesic_solver.h"
#include "geodex/isolines.h"
#include "geodex/shortest_path.h"
#include "geodex/voronoi.h"
#include "geometry_convert.h"
#include "gtest/gtest.h"
#include "util/test_meshes.h"

namespace geodex {
namespace {

constexpr size_t kTinyBudget = 300;  // bytes per message: forces pieces

std::string Text(const std::vector<PathPoint>& points) {
  std::string s;
  for (const PathPoint& p : points) {
    s += absl::StrFormat("%s@%.17g,%.17g,%.17g;", SurfacePointToString(p.where), p.position[0],
                         p.position[1], p.position[2]);
  }
  return s;
}

struct Field {
  TriangleMesh mesh;
  DistanceField field;
  std::vector<SurfacePoint> sites;
};

Field Solve() {
  absl::StatusOr<TriangleMesh> mesh = LoadTestMesh("kitten.off");
  EXPECT_TRUE(mesh.ok());
  std::vector<SurfacePoint> sites = {SurfacePoint::AtVertex(0), SurfacePoint::AtVertex(800),
                                     SurfacePoint::InFace(100, 0.2, 0.3, 0.5),
                                     SurfacePoint::AtVertex(2400), SurfacePoint::AtVertex(1600)};
  absl::StatusOr<DistanceField> field = ComputeDistanceField(*mesh, sites);
  EXPECT_TRUE(field.ok());
  return Field{*std::move(mesh), *std::move(field), sites};
}

template <typename Message>
bool AnyContinued(const std::vector<Message>& messages, bool (*piece_continued)(const Message&)) {
  for (const Message& m : messages) {
    if (piece_continued(m)) return true;
  }
  return false;
}

TEST(ApiConvertTest, IsolinesRoundTripThroughManyMessages) {
  const Field f = Solve();
  IsolineOptions options;
  options.count = 7;
  const Isolines iso = *ExtractIsolines(f.mesh, f.field, options);
  const std::vector<v1::ComputeIsolinesResponse> messages = api::IsolinesToProto(iso, kTinyBudget);
  ASSERT_GT(messages.size(), 10u);
  EXPECT_TRUE(
      AnyContinued<v1::ComputeIsolinesResponse>(messages, [](const v1::ComputeIsolinesResponse& m) {
        for (const auto& piece : m.isolines()) {
          if (piece.continued()) return true;
        }
        return false;
      }));
  api::IsolinesAssembler back;
  for (const auto& m : messages) back.Add(m);
  const Isolines& got = back.result();
  EXPECT_EQ(got.levels, iso.levels);
  ASSERT_EQ(got.polylines.size(), iso.polylines.size());
  for (size_t i = 0; i < iso.polylines.size(); ++i) {
    EXPECT_EQ(got.polylines[i].level, iso.polylines[i].level);
    EXPECT_EQ(got.polylines[i].closed, iso.polylines[i].closed);
    EXPECT_EQ(Text(got.polylines[i].points), Text(iso.polylines[i].points)) << i;
  }
}

TEST(ApiConvertTest, VoronoiRoundTripsWithCellsSplitAcrossMessages) {
  const Field f = Solve();
  const VoronoiDiagram vd = *BuildVoronoi(f.mesh, f.field);
  const std::vector<v1::ComputeVoronoiResponse> messages =
      api::VoronoiToProto(vd, f.sites, /*omit_cell_faces=*/false, kTinyBudget);
  EXPECT_TRUE(
      AnyContinued<v1::ComputeVoronoiResponse>(messages, [](const v1::ComputeVoronoiResponse& m) {
        for (const auto& piece : m.cells()) {
          if (piece.continued()) return true;
        }
        return false;
      }));
  api::VoronoiAssembler back;
  for (const auto& m : messages) back.Add(m);
  const VoronoiDiagram& got = back.result();
  ASSERT_EQ(back.resolved_sources().size(), f.sites.size());
  for (size_t i = 0; i < f.sites.size(); ++i) {
    EXPECT_EQ(SurfacePointToString(back.resolved_sources()[i]), SurfacePointToString(f.sites[i]));
  }
  EXPECT_EQ(got.total_area, vd.total_area);
  EXPECT_EQ(got.junction_faces, vd.junction_faces);
  EXPECT_EQ(got.adjacency, vd.adjacency);
  ASSERT_EQ(got.cells.size(), vd.cells.size());
  for (size_t i = 0; i < vd.cells.size(); ++i) {
    EXPECT_EQ(got.cells[i].site, vd.cells[i].site);
    EXPECT_EQ(got.cells[i].area, vd.cells[i].area);
    EXPECT_EQ(got.cells[i].whole_faces, vd.cells[i].whole_faces);
    ASSERT_EQ(got.cells[i].fragments.size(), vd.cells[i].fragments.size());
    for (size_t k = 0; k < vd.cells[i].fragments.size(); ++k) {
      EXPECT_EQ(got.cells[i].fragments[k].face, vd.cells[i].fragments[k].face);
      EXPECT_EQ(Text(got.cells[i].fragments[k].polygon), Text(vd.cells[i].fragments[k].polygon));
    }
  }
  ASSERT_EQ(got.boundaries.size(), vd.boundaries.size());
  for (size_t i = 0; i < vd.boundaries.size(); ++i) {
    EXPECT_EQ(got.boundaries[i].site_a, vd.boundaries[i].site_a);
    EXPECT_EQ(got.boundaries[i].site_b, vd.boundaries[i].site_b);
    EXPECT_EQ(got.boundaries[i].closed, vd.boundaries[i].closed);
    EXPECT_EQ(Text(got.boundaries[i].points), Text(vd.boundaries[i].points));
  }
  // Without cell faces: the cells' sites and areas only.
  api::VoronoiAssembler light;
  for (const auto& m : api::VoronoiToProto(vd, f.sites, true, kTinyBudget)) light.Add(m);
  ASSERT_EQ(light.result().cells.size(), vd.cells.size());
  EXPECT_TRUE(light.result().cells[0].whole_faces.empty());
  EXPECT_EQ(light.result().cells[0].area, vd.cells[0].area);
}

TEST(ApiConvertTest, DelaunayRoundTrips) {
  const Field f = Solve();
  const DelaunayTriangulation dt = *BuildDelaunay(f.mesh, f.field);
  ASSERT_FALSE(dt.edges.empty());
  const std::vector<v1::ComputeDelaunayResponse> messages =
      api::DelaunayToProto(dt, f.sites, kTinyBudget);
  ASSERT_GT(messages.size(), 1u);
  api::DelaunayAssembler back;
  for (const auto& m : messages) back.Add(m);
  const DelaunayTriangulation& got = back.result();
  EXPECT_EQ(back.resolved_sources().size(), f.sites.size());
  EXPECT_EQ(got.triangles, dt.triangles);
  auto same_edges = [](const std::vector<DelaunayEdge>& a, const std::vector<DelaunayEdge>& b) {
    ASSERT_EQ(a.size(), b.size());
    for (size_t i = 0; i < a.size(); ++i) {
      EXPECT_EQ(a[i].site_a, b[i].site_a);
      EXPECT_EQ(a[i].site_b, b[i].site_b);
      EXPECT_EQ(a[i].vertex_a, b[i].vertex_a);
      EXPECT_EQ(a[i].vertex_b, b[i].vertex_b);
      EXPECT_EQ(a[i].length, b[i].length);
      EXPECT_EQ(a[i].edge_start, b[i].edge_start);
      EXPECT_EQ(Text(a[i].points), Text(b[i].points));
    }
  };
  same_edges(got.edges, dt.edges);
  same_edges(got.removed_edges, dt.removed_edges);
  ASSERT_EQ(got.xl_edges.size(), dt.xl_edges.size());
  for (size_t i = 0; i < dt.xl_edges.size(); ++i) {
    EXPECT_EQ(got.xl_edges[i].witness, dt.xl_edges[i].witness);
    EXPECT_EQ(Text({got.xl_edges[i].point}), Text({dt.xl_edges[i].point}));
  }
}

// A mesh's geometry as geodexd holds it (TriangleMesh::ToMeshData) through GetMeshGeometry's
// messages: the file's faces exactly (flipped faces and split vertices undone), its positions
// within round-off.
TEST(ApiConvertTest, MeshGeometryRoundTripsToTheFile) {
  // A messy one too: a bowtie vertex (split into two copies) and a face against its neighbour's
  // orientation (flipped by Build).
  MeshData messy;
  messy.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0, -1, 0, 0, 0, -1, 0, 1, 1, 0.5};
  messy.faces = {0, 1, 2, 0, 3, 4, 1, 2, 5};
  {
    absl::StatusOr<TriangleMesh> mesh = TriangleMesh::Build(messy);
    ASSERT_TRUE(mesh.ok());
    ASSERT_GT(mesh->vertex_count(), mesh->file_vertex_count());  // the bowtie was split
    ASSERT_TRUE(mesh->FaceFlipped(2));
    EXPECT_EQ(mesh->ToMeshData().faces, messy.faces);
  }
  for (const char* name : {"kitten.off", "three-peaks.off"}) {
    absl::StatusOr<MeshData> file = LoadTestMeshData(name);
    ASSERT_TRUE(file.ok());
    absl::StatusOr<TriangleMesh> mesh = TriangleMesh::Build(*file);
    ASSERT_TRUE(mesh.ok());
    const std::vector<v1::MeshGeometry> messages =
        api::MeshGeometryToProto(mesh->ToMeshData(), kTinyBudget);
    ASSERT_GT(messages.size(), 10u);
    api::MeshGeometryAssembler back;
    for (const auto& m : messages) back.Add(m);
    EXPECT_EQ(back.result().faces, file->faces) << name;
    ASSERT_EQ(back.result().positions.size(), file->positions.size());
    for (size_t i = 0; i < file->positions.size(); ++i) {
      EXPECT_NEAR(back.result().positions[i], file->positions[i],
                  1e-14 * (1 + std::abs(file->positions[i])))
          << name << " " << i;
    }
  }
}

// A mesh's summary through the Mesh resource and back (what `geodex info` prints remotely).
TEST(ApiConvertTest, MeshSummaryRoundTrips) {
  absl::StatusOr<TriangleMesh> mesh = LoadTestMesh("three-peaks.off");
  ASSERT_TRUE(mesh.ok());
  const MeshSummary s = Summarize(*mesh);
  ASSERT_GT(s.report.boundary_vertices, 0u);  // a mesh with a boundary: every count non-trivial
  v1::Mesh proto;
  api::MeshSummaryToProto(s, &proto);
  const MeshSummary back = api::MeshSummaryFromProto(proto);
  const MeshReport &a = s.report, &b = back.report;
  EXPECT_EQ(std::vector<uint64_t>({a.file_vertices, a.file_faces, a.boundary_edges,
                                   a.boundary_loops, a.components, a.vertex_connected_components,
                                   a.isolated_vertices, a.non_manifold_edges,
                                   a.non_manifold_vertices, a.degenerate_faces, a.flipped_faces,
                                   a.orientation_cuts, a.saddle_vertices, a.boundary_vertices}),
            std::vector<uint64_t>({b.file_vertices, b.file_faces, b.boundary_edges,
                                   b.boundary_loops, b.components, b.vertex_connected_components,
                                   b.isolated_vertices, b.non_manifold_edges,
                                   b.non_manifold_vertices, b.degenerate_faces, b.flipped_faces,
                                   b.orientation_cuts, b.saddle_vertices, b.boundary_vertices}));
  EXPECT_EQ(back.internal_vertices, s.internal_vertices);
  EXPECT_EQ(back.mean_edge_length, s.mean_edge_length);
  EXPECT_EQ(back.max_edge_length, s.max_edge_length);
  EXPECT_EQ(back.bbox_min, s.bbox_min);
  EXPECT_EQ(back.bbox_max, s.bbox_max);
  EXPECT_EQ(back.bytes, s.bytes);
}

// EstimateDistances' exact part: the query into the request, core's answer through the response
// and back, every member (what `distances --at` prints remotely).
TEST(ApiConvertTest, PointQueryAndValuesRoundTrip) {
  absl::StatusOr<TriangleMesh> mesh = LoadTestMesh("three-peaks.off");
  ASSERT_TRUE(mesh.ok());
  PointQuery query;
  query.sources = {SurfacePoint::AtVertex(0), SurfacePoint::InFace(5, 0.2, 0.3, 0.5)};
  query.points = {SurfacePoint::AtVertex(40), SurfacePoint::OnEdge(1, 2, 0.25),
                  SurfacePoint::AtVertex(0)};
  query.options.lambda = 0.125;
  query.options.max_distance = 1e9;
  v1::EstimateDistancesRequest request;
  api::PointQueryToProto(query, &request);
  ASSERT_EQ(request.sources_size(), 2);
  ASSERT_EQ(request.points_size(), 3);
  for (int i = 0; i < 2; ++i) {
    EXPECT_EQ(SurfacePointToString(api::SurfacePointFromProto(request.sources(i))),
              SurfacePointToString(query.sources[i]));
  }
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(SurfacePointToString(api::SurfacePointFromProto(request.points(i))),
              SurfacePointToString(query.points[i]));
  }
  EXPECT_EQ(request.options().lambda(), 0.125);
  EXPECT_EQ(request.options().max_distance(), 1e9);

  query.options = GeodesicOptions{};
  query.directions = true;
  api::PointQueryToProto(query, &request);
  EXPECT_TRUE(request.want_directions());
  absl::StatusOr<PointValues> values = ComputePointValues(*mesh, query);
  ASSERT_TRUE(values.ok()) << values.status();
  ASSERT_EQ(values->distance.size(), 3u);
  EXPECT_EQ(values->distance[2], 0);  // a source
  v1::EstimateDistancesResponse response;
  api::PointValuesToProto(*values, &response);
  api::StatsToProto(values->stats, response.mutable_exact_stats());
  const PointValues back = api::PointValuesFromProto(response);
  EXPECT_EQ(back.distance, values->distance);
  EXPECT_EQ(back.source, values->source);
  EXPECT_EQ(back.stats.windows_processed, values->stats.windows_processed);
  ASSERT_EQ(values->direction.size(), 3u);
  ASSERT_EQ(back.direction.size(), 3u);
  for (size_t i = 0; i < 3; ++i) EXPECT_EQ(back.direction[i], values->direction[i]);
  const PointEstimate estimate{1.25, 1};
  api::PointEstimateToProto(estimate, &response);
  const std::vector<PointEstimate> estimates = api::PointEstimatesFromProto(response);
  ASSERT_EQ(estimates.size(), 1u);
  EXPECT_EQ(estimates[0].distance, 1.25);
  EXPECT_EQ(estimates[0].source, 1u);
}

// ComputeDistanceField's stream: a field with its directions cut into many messages (what
// geodexd sends) and put back together (what the client does) is the field, bit for bit; the
// query survives the request.
TEST(ApiConvertTest, FieldRoundTripsThroughManyMessages) {
  absl::StatusOr<TriangleMesh> mesh = LoadTestMesh("kitten.off");
  ASSERT_TRUE(mesh.ok());
  FieldQuery query;
  query.sources = {SurfacePoint::AtVertex(0), SurfacePoint::InFace(100, 0.2, 0.3, 0.5)};
  query.options.max_distance = 40;  // some vertices unreachable: inf, no label, NaN directions
  query.directions = true;
  v1::ComputeDistanceFieldRequest request;
  api::FieldQueryToProto(query, &request);
  EXPECT_EQ(request.sources_size(), 2);
  EXPECT_EQ(request.options().max_distance(), 40);
  EXPECT_TRUE(request.want_directions());

  absl::StatusOr<DistanceField> field = ComputeDistanceField(*mesh, query.sources, query.options);
  ASSERT_TRUE(field.ok());
  DistanceField products;
  ASSERT_TRUE(ComputeFieldProducts(*mesh, *field, query, &products).ok());
  ASSERT_EQ(products.direction.size(), field->distance.size());
  ASSERT_GT(std::count_if(field->distance.begin(), field->distance.end(),
                          [](double d) { return std::isinf(d); }),
            0);
  for (bool f32 : {false, true}) {
    api::FieldEncoding encoding;
    encoding.f32 = f32;
    const size_t n = field->distance.size(), chunk = 97;  // many messages, the last one short
    api::FieldAssembler assembler;
    int messages = 0;
    for (size_t begin = 0; begin < n; begin += chunk) {
      v1::ComputeDistanceFieldResponse message;
      api::FieldChunkToProto(*field, products, begin, std::min(n, begin + chunk), encoding,
                             &message);
      EXPECT_EQ(message.resolved_sources_size(), begin == 0 ? 2 : 0);
      v1::ComputeDistanceFieldResponse wire;  // through bytes, as on the wire
      ASSERT_TRUE(wire.ParseFromString(message.SerializeAsString()));
      assembler.Add(wire);
      ++messages;
    }
    EXPECT_GT(messages, 20);
    const DistanceField& back = assembler.result();
    ASSERT_EQ(back.distance.size(), n);
    for (size_t v = 0; v < n; ++v) {
      const double want =
          f32 ? static_cast<double>(static_cast<float>(field->distance[v])) : field->distance[v];
      ASSERT_EQ(std::memcmp(&back.distance[v], &want, sizeof want), 0) << v;
      for (int c = 0; c < 3; ++c) {
        ASSERT_EQ(std::memcmp(&back.direction[v][c], &products.direction[v][c], sizeof(double)), 0);
      }
    }
    EXPECT_EQ(back.source, field->source);
    ASSERT_EQ(back.sources.size(), 2u);
    EXPECT_EQ(SurfacePointToString(back.sources[1]), SurfacePointToString(query.sources[1]));
  }
}

// FindShortestPath's answer and LocatePoints' through their messages and back.
TEST(ApiConvertTest, PathAndLocatedPointRoundTrip) {
  absl::StatusOr<TriangleMesh> mesh = LoadTestMesh("kitten.off");
  ASSERT_TRUE(mesh.ok());
  absl::StatusOr<PathQueryResult> path = ComputeShortestPath(
      *mesh, SurfacePoint::AtVertex(0), SurfacePoint::InFace(100, 0.2, 0.3, 0.5));
  ASSERT_TRUE(path.ok());
  ASSERT_GT(path->path.points.size(), 3u);
  v1::FindShortestPathResponse response;
  api::PathResultToProto(path->distance, path->path.length, path->path.points, &response);
  api::StatsToProto(path->stats, response.mutable_stats());
  const PathQueryResult back = api::PathResultFromProto(response);
  EXPECT_EQ(back.distance, path->distance);
  EXPECT_EQ(back.path.length, path->path.length);

  // A travel-cost path: its cost is seconds, its length still metres, and both come back.
  v1::FindShortestPathResponse timed;
  api::PathResultToProto(2 * path->path.length, path->path.length, path->path.points, &timed);
  timed.set_travel_epsilon(0.01);
  const PathQueryResult timed_back = api::PathResultFromProto(timed);
  EXPECT_EQ(timed_back.distance, 2 * path->path.length);
  EXPECT_EQ(timed_back.path.length, path->path.length);
  EXPECT_EQ(Text(back.path.points), Text(path->path.points));
  EXPECT_EQ(back.stats.windows_processed, path->stats.windows_processed);

  const LocatedPoint located{SurfacePoint::OnEdge(3, 7, 0.25), {1.5, -2, 0.125}, 0.75};
  v1::LocatedPoint proto;
  api::LocatedPointToProto(located, &proto);
  const LocatedPoint again = api::LocatedPointFromProto(proto);
  EXPECT_EQ(SurfacePointToString(again.point), SurfacePointToString(located.point));
  EXPECT_EQ(again.position, located.position);
  EXPECT_EQ(again.distance, located.distance);
}

// ComputeDistanceMatrix's stream: a matrix cut mid-row into many messages and put back together.
TEST(ApiConvertTest, MatrixRoundTripsThroughManyMessages) {
  DistanceMatrix m;
  m.rows = 7;
  m.cols = 5;
  for (size_t i = 0; i < m.rows * m.cols; ++i) {
    m.values.push_back(i % 6 ? 0.1 * i + 1e-17 : kUnreachable);
  }
  for (bool f32 : {false, true}) {
    api::MatrixAssembler assembler;
    for (size_t begin = 0; begin < m.values.size(); begin += 3) {
      v1::ComputeDistanceMatrixResponse message;
      api::MatrixChunkToProto(m.rows, m.cols, m.values, begin, std::min(m.values.size(), begin + 3),
                              f32, &message);
      assembler.Add(message);
      EXPECT_EQ(assembler.rows_done(), std::min(m.values.size(), begin + 3) / m.cols);
    }
    const DistanceMatrix& back = assembler.result();
    EXPECT_EQ(back.rows, m.rows);
    EXPECT_EQ(back.cols, m.cols);
    ASSERT_EQ(back.values.size(), m.values.size());
    for (size_t i = 0; i < m.values.size(); ++i) {
      EXPECT_EQ(back.values[i],
                f32 ? static_cast<double>(static_cast<float>(m.values[i])) : m.values[i]);
    }
  }
}

// The path and matrix requests asked whole: every member the wire carries arrives.
TEST(ApiConvertTest, PathAndMatrixQueriesFillTheirRequests) {
  PathQuery path{SurfacePoint::AtVertex(3), SurfacePoint::InFace(9, 0.5, 0.25, 0.25), {}};
  path.options.solver.lambda = 0.25;
  path.options.solver.max_distance = 7;
  v1::FindShortestPathRequest path_request;
  api::PathQueryToProto(path, &path_request);
  EXPECT_EQ(SurfacePointToString(api::SurfacePointFromProto(path_request.from())), "3");
  EXPECT_EQ(SurfacePointToString(api::SurfacePointFromProto(path_request.to())),
            SurfacePointToString(path.to));
  EXPECT_EQ(path_request.options().lambda(), 0.25);
  EXPECT_EQ(path_request.options().max_distance(), 7);

  MatrixQuery matrix{{SurfacePoint::AtVertex(1), SurfacePoint::AtVertex(2)},
                     {SurfacePoint::OnEdge(4, 5, 0.5)},
                     {}};
  matrix.options.k_nearest = 1;
  matrix.options.solver.lambda = 0.5;
  v1::ComputeDistanceMatrixRequest matrix_request;
  api::MatrixQueryToProto(matrix, &matrix_request);
  ASSERT_EQ(matrix_request.sources_size(), 2);
  ASSERT_EQ(matrix_request.targets_size(), 1);
  EXPECT_EQ(SurfacePointToString(api::SurfacePointFromProto(matrix_request.sources(1))), "2");
  EXPECT_EQ(SurfacePointToString(api::SurfacePointFromProto(matrix_request.targets(0))),
            SurfacePointToString(matrix.targets[0]));
  EXPECT_EQ(matrix_request.k_nearest(), 1u);
  EXPECT_EQ(matrix_request.options().lambda(), 0.5);
}

TEST(ApiConvertTest, GeometryQueriesFillTheirRequests) {
  IsolineQuery iso{{SurfacePoint::AtVertex(3), SurfacePoint::OnEdge(4, 5, 0.25)}, {}, {}};
  iso.options.lambda = 0.5;
  iso.options.lambda_scale = LambdaScale::kMeanEdge;
  iso.options.max_distance = 9;
  iso.levels.levels = {0.5, 0.25};
  v1::ComputeIsolinesRequest iso_request;
  api::IsolineQueryToProto(iso, &iso_request);
  ASSERT_EQ(iso_request.sources_size(), 2);
  EXPECT_EQ(SurfacePointToString(api::SurfacePointFromProto(iso_request.sources(1))),
            SurfacePointToString(iso.sources[1]));
  EXPECT_EQ(iso_request.options().lambda(), 0.5);
  EXPECT_EQ(iso_request.options().lambda_scale(), v1::LAMBDA_SCALE_MEAN_EDGE);
  EXPECT_EQ(iso_request.options().max_distance(), 9);
  const IsolineOptions levels =
      api::IsolineLevelsFromProto(iso_request.levels(), iso_request.count());
  EXPECT_EQ(levels.levels, iso.levels.levels);
  EXPECT_EQ(levels.count, 0);
  iso.levels = {{}, 6};
  iso_request.Clear();
  api::IsolineQueryToProto(iso, &iso_request);
  EXPECT_EQ(iso_request.levels_size(), 0);
  EXPECT_EQ(iso_request.count(), 6);

  VoronoiQuery voronoi{{SurfacePoint::AtVertex(1), SurfacePoint::AtVertex(2)}, {}};
  voronoi.options.lambda = 1;
  v1::ComputeVoronoiRequest voronoi_request;
  api::VoronoiQueryToProto(voronoi, &voronoi_request);
  EXPECT_EQ(voronoi_request.sources_size(), 2);
  EXPECT_EQ(voronoi_request.options().lambda(), 1);

  DelaunayQuery delaunay{{SurfacePoint::AtVertex(1), SurfacePoint::AtVertex(2)}, {}};
  delaunay.options.max_distance = 3;
  v1::ComputeDelaunayRequest delaunay_request;
  api::DelaunayQueryToProto(delaunay, &delaunay_request);
  EXPECT_EQ(delaunay_request.sources_size(), 2);
  EXPECT_EQ(delaunay_request.options().max_distance(), 3);
}

}  // namespace
}  // namespace geodex
