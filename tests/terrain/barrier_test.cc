// Barrier polygons cut exactly into the surface (terrain/src/barrier_cut.h, issue 32), checked
// against analytic answers: a tilted plane is flat in its own metric, so the shortest path around
// a polygonal hole is the taut string through the hole's corners, found here by Dijkstra on the
// visibility graph; the cut mesh must conform (no T-junctions) and keep exactly the plane's area
// outside the polygons.

#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <queue>
#include <string>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "gdal_priv.h"
#include "geodex/geodesic_solver.h"
#include "geodex/terrain.h"
#include "geodex/triangle_mesh.h"
#include "gtest/gtest.h"
#include "ogr_spatialref.h"

namespace geodex::terrain {
namespace {

using Point2 = std::array<double, 2>;
constexpr double kSlopeX = 0.3, kSlopeY = -0.2;  // the plane z = 0.3 x - 0.2 y

// An N x N grid of unit cells on the plane, two triangles a block (split along alternating
// diagonals, so both kinds of crossing are met).
MeshData TiltedGrid(int n) {
  MeshData mesh;
  for (int j = 0; j <= n; ++j) {
    for (int i = 0; i <= n; ++i)
      mesh.positions.insert(mesh.positions.end(), {1.0 * i, 1.0 * j, kSlopeX * i + kSlopeY * j});
  }
  auto id = [n](int i, int j) { return static_cast<uint32_t>(j * (n + 1) + i); };
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const uint32_t a = id(i, j), b = id(i + 1, j), c = id(i, j + 1), d = id(i + 1, j + 1);
      if ((i + j) % 2 == 0) {
        mesh.faces.insert(mesh.faces.end(), {a, b, d, a, d, c});
      } else {
        mesh.faces.insert(mesh.faces.end(), {a, b, c, b, d, c});
      }
    }
  }
  return mesh;
}

double Cross(const Point2& o, const Point2& a, const Point2& b) {
  return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
}

std::array<double, 3> OnPlane(const Point2& p) {
  return {p[0], p[1], kSlopeX * p[0] + kSlopeY * p[1]};
}
double Length3(const Point2& p, const Point2& q) {
  const auto a = OnPlane(p), b = OnPlane(q);
  return std::hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);
}

// Does segment p-q pass through the open interior of the convex counter-clockwise polygon?
bool Blocked(const Point2& p, const Point2& q, const std::vector<Point2>& polygon) {
  double lo = 0, hi = 1;
  for (size_t k = 0; k < polygon.size(); ++k) {
    const Point2 &a = polygon[k], &b = polygon[(k + 1) % polygon.size()];
    const double nx = -(b[1] - a[1]), ny = b[0] - a[0];  // inward normal
    const double at_p = nx * (p[0] - a[0]) + ny * (p[1] - a[1]);
    const double slope = nx * (q[0] - p[0]) + ny * (q[1] - p[1]);
    if (std::abs(slope) < 1e-15) {
      if (at_p <= 1e-12) return false;
      continue;
    }
    const double t = -at_p / slope;
    if (slope > 0)
      lo = std::max(lo, t);
    else
      hi = std::min(hi, t);
  }
  return hi - lo > 1e-9;
}

// The taut string from s to t around convex holes: Dijkstra on the visibility graph.
double TautString(const Point2& s, const Point2& t, const std::vector<std::vector<Point2>>& holes) {
  std::vector<Point2> nodes = {s, t};
  for (const auto& h : holes) nodes.insert(nodes.end(), h.begin(), h.end());
  std::vector<double> best(nodes.size(), std::numeric_limits<double>::infinity());
  std::priority_queue<std::pair<double, size_t>, std::vector<std::pair<double, size_t>>,
                      std::greater<>>
      queue;
  best[0] = 0;
  queue.push({0, 0});
  while (!queue.empty()) {
    auto [d, u] = queue.top();
    queue.pop();
    if (d > best[u]) continue;
    for (size_t v = 0; v < nodes.size(); ++v) {
      bool visible = v != u;
      for (const auto& h : holes) visible = visible && !Blocked(nodes[u], nodes[v], h);
      if (visible && d + Length3(nodes[u], nodes[v]) < best[v]) {
        best[v] = d + Length3(nodes[u], nodes[v]);
        queue.push({best[v], v});
      }
    }
  }
  return best[1];
}

std::string PolygonJson(const std::vector<std::vector<Point2>>& polygons) {
  std::string parts;
  for (const auto& ring : polygons) {
    std::string coordinates;
    for (size_t k = 0; k <= ring.size(); ++k) {
      absl::StrAppendFormat(&coordinates, "%s[%.17g, %.17g]", k == 0 ? "" : ", ",
                            ring[k % ring.size()][0], ring[k % ring.size()][1]);
    }
    absl::StrAppend(&parts, parts.empty() ? "" : ", ", "[[", coordinates, "]]");
  }
  return absl::StrCat(R"({"type": "MultiPolygon", "coordinates": [)", parts, "]}");
}

double Area3(const MeshData& m) {
  double total = 0;
  for (size_t f = 0; f < m.face_count(); ++f) {
    const double* p[3];
    for (int c = 0; c < 3; ++c) p[c] = &m.positions[3 * size_t{m.faces[3 * f + c]}];
    const double u[3] = {p[1][0] - p[0][0], p[1][1] - p[0][1], p[1][2] - p[0][2]};
    const double v[3] = {p[2][0] - p[0][0], p[2][1] - p[0][1], p[2][2] - p[0][2]};
    total += std::hypot(u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2],
                        u[0] * v[1] - u[1] * v[0]) /
             2;
  }
  return total;
}

double Shoelace(const std::vector<Point2>& ring) {
  double a = 0;
  for (size_t k = 0; k < ring.size(); ++k) {
    const Point2 &p = ring[k], &q = ring[(k + 1) % ring.size()];
    a += p[0] * q[1] - q[0] * p[1];
  }
  return a / 2;
}

double DistanceToBoundary(const Point2& p, const std::vector<Point2>& ring) {
  double best = std::numeric_limits<double>::infinity();
  for (size_t k = 0; k < ring.size(); ++k) {
    const Point2 &a = ring[k], &b = ring[(k + 1) % ring.size()];
    const double dx = b[0] - a[0], dy = b[1] - a[1];
    const double t =
        std::clamp(((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / (dx * dx + dy * dy), 0.0, 1.0);
    best = std::min(best, std::hypot(p[0] - a[0] - t * dx, p[1] - a[1] - t * dy));
  }
  return best;
}

// Conforming: each directed edge once; an edge with one face lies on the grid's outer boundary or
// on a polygon's boundary (a T-junction would leave one inside). Every vertex on the plane.
void ExpectConforming(const MeshData& cut, int n,
                      const std::vector<std::vector<Point2>>& polygons) {
  std::map<std::pair<uint32_t, uint32_t>, int> directed;
  for (size_t f = 0; f < cut.face_count(); ++f) {
    for (int c = 0; c < 3; ++c) ++directed[{cut.faces[3 * f + c], cut.faces[3 * f + (c + 1) % 3]}];
  }
  int boundary = 0, bad = 0;
  for (const auto& [edge, count] : directed) {
    EXPECT_EQ(count, 1) << edge.first << "-" << edge.second;
    if (directed.count({edge.second, edge.first}) != 0) continue;
    ++boundary;
    const double* a = &cut.positions[3 * size_t{edge.first}];
    const double* b = &cut.positions[3 * size_t{edge.second}];
    const Point2 mid = {(a[0] + b[0]) / 2, (a[1] + b[1]) / 2};
    bool ok = std::abs(mid[0]) < 1e-12 || std::abs(mid[1]) < 1e-12 ||
              std::abs(mid[0] - n) < 1e-12 || std::abs(mid[1] - n) < 1e-12;
    for (const auto& ring : polygons) {
      ok = ok ||
           (DistanceToBoundary(mid, ring) < 1e-9 && DistanceToBoundary({a[0], a[1]}, ring) < 1e-9 &&
            DistanceToBoundary({b[0], b[1]}, ring) < 1e-9);
    }
    bad += ok ? 0 : 1;
  }
  EXPECT_GT(boundary, 0);
  EXPECT_EQ(bad, 0) << "edges with one face inside the surface: T-junctions";
  for (size_t v = 0; v < cut.vertex_count(); ++v) {
    const double* p = &cut.positions[3 * v];
    EXPECT_NEAR(p[2], kSlopeX * p[0] + kSlopeY * p[1], 1e-12) << v;
  }
}

TEST(BarrierCutTest, SquareHoleGivesTheTautString) {
  const int n = 20;
  const MeshData grid = TiltedGrid(n);
  // A square turned 20 degrees, its corners inside cells.
  std::vector<Point2> hole;
  const double angle = 20 * M_PI / 180;
  for (int k = 0; k < 4; ++k) {
    const double a = angle + k * M_PI / 2;
    hole.push_back(
        {10.13 + 4.3 * std::cos(a) * std::sqrt(2.0), 9.87 + 4.3 * std::sin(a) * std::sqrt(2.0)});
  }
  ASSERT_GT(Shoelace(hole), 0);
  CutStats stats;
  absl::StatusOr<MeshData> cut =
      CutBarrierPolygons(grid, PolygonJson({hole}), nullptr, 0, "hole", &stats);
  ASSERT_TRUE(cut.ok()) << cut.status();
  EXPECT_GT(stats.faces_cut, 0u);
  EXPECT_GT(stats.faces_removed, 0u);
  EXPECT_GT(stats.vertices_added, 0u);
  ExpectConforming(*cut, n, {hole});
  const double sec = std::sqrt(1 + kSlopeX * kSlopeX + kSlopeY * kSlopeY);
  EXPECT_NEAR(Area3(*cut), (n * n - Shoelace(hole)) * sec, 1e-10 * n * n);
  absl::StatusOr<TriangleMesh> mesh = TriangleMesh::Build(*cut);
  ASSERT_TRUE(mesh.ok()) << mesh.status();

  // From grid vertices on one side to every grid vertex: the taut string wherever the hole is in
  // the way, the straight line elsewhere.
  for (const Point2 source : {Point2{1, 9}, Point2{10, 1}, Point2{3, 17}}) {
    const uint32_t s = static_cast<uint32_t>(source[1] * (n + 1) + source[0]);
    absl::StatusOr<DistanceField> field = ComputeDistanceField(*mesh, {SurfacePoint::AtVertex(s)});
    ASSERT_TRUE(field.ok()) << field.status();
    double worst = 0;
    int around = 0;
    for (int j = 0; j <= n; ++j) {
      for (int i = 0; i <= n; ++i) {
        const Point2 target = {1.0 * i, 1.0 * j};
        const double d = field->distance[j * (n + 1) + i];
        bool inside = true;  // a vertex inside the hole is unused: unreachable
        for (size_t k = 0; k < 4; ++k) inside &= Shoelace({hole[k], hole[(k + 1) % 4], target}) > 0;
        if (inside) {
          EXPECT_TRUE(std::isinf(d)) << i << " " << j;
          continue;
        }
        const double expected = TautString(source, target, {hole});
        around += Blocked(source, target, hole) ? 1 : 0;
        worst = std::max(worst, std::abs(d - expected) / std::max(expected, 1.0));
      }
    }
    EXPECT_GT(around, 5) << "the hole is in the way of some paths";
    EXPECT_LT(worst, 1e-9) << source[0] << " " << source[1];
  }
}

TEST(BarrierCutTest, AWallNarrowerThanACellSeparates) {
  const int n = 16;
  const MeshData grid = TiltedGrid(n);
  // 0.3 wide, across the whole grid at 17 degrees off its columns.
  const double angle = 17 * M_PI / 180, cx = 8.4, cy = 8;
  const Point2 along = {std::sin(angle), std::cos(angle)},
               across = {std::cos(angle), -std::sin(angle)};
  std::vector<Point2> wall;
  for (auto [u, w] :
       std::vector<std::pair<double, double>>{{-20, -0.15}, {-20, 0.15}, {20, 0.15}, {20, -0.15}}) {
    wall.push_back({cx + u * along[0] + w * across[0], cy + u * along[1] + w * across[1]});
  }
  if (Shoelace(wall) < 0) std::reverse(wall.begin(), wall.end());
  CutStats stats;
  absl::StatusOr<MeshData> cut =
      CutBarrierPolygons(grid, PolygonJson({wall}), nullptr, 0, "wall", &stats);
  ASSERT_TRUE(cut.ok()) << cut.status();
  ExpectConforming(*cut, n, {wall});
  absl::StatusOr<TriangleMesh> mesh = TriangleMesh::Build(*cut);
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  absl::StatusOr<DistanceField> field = ComputeDistanceField(*mesh, {SurfacePoint::AtVertex(0)});
  ASSERT_TRUE(field.ok()) << field.status();
  int near = 0, far = 0;
  for (int j = 0; j <= n; ++j) {
    for (int i = 0; i <= n; ++i) {
      const double side = (i - cx) * across[0] + (j - cy) * across[1];
      const double d = field->distance[j * (n + 1) + i];
      if (side < -0.15) {
        EXPECT_NEAR(d, Length3({0, 0}, {1.0 * i, 1.0 * j}), 1e-9 * n) << i << " " << j;
        ++near;
      } else if (side > 0.15) {
        EXPECT_TRUE(std::isinf(d)) << i << " " << j << ": " << d;
        ++far;
      }
    }
  }
  EXPECT_GT(near, 50);
  EXPECT_GT(far, 50);
  // The old rule (faces whose centre is inside) left this wall full of gaps.
  EXPECT_GT(stats.faces_cut, stats.faces_removed);
}

TEST(BarrierCutTest, LinesAreWallsOfTheirWidth) {
  const int n = 10;
  const MeshData grid = TiltedGrid(n);
  const std::string fence = R"({"type": "LineString", "coordinates": [[4.37, -1], [6.11, 11]]})";
  CutStats stats;
  absl::Status refused = CutBarrierPolygons(grid, R"({"type": "Point", "coordinates": [3, 3]})",
                                            nullptr, 0, "--barrier f", &stats)
                             .status();
  EXPECT_EQ(refused.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(refused.message().rfind("--barrier f: points are barriers with a width", 0), 0u)
      << refused;
  absl::StatusOr<MeshData> cut =
      CutBarrierPolygons(grid, fence, nullptr, 0.25, "--barrier f", &stats);
  ASSERT_TRUE(cut.ok()) << cut.status();
  // The wall's area is its length times its width plus its two round ends (GEOS's buffer: 8
  // segments a quarter circle, so a little less than pi r^2).
  const double length = std::hypot(6.11 - 4.37, 12.0), r = 0.125;
  const double sec = std::sqrt(1 + kSlopeX * kSlopeX + kSlopeY * kSlopeY);
  const double inside_length = length * (static_cast<double>(n) / 12);  // the part over the grid
  EXPECT_NEAR(Area3(*cut), (n * n - inside_length * 2 * r) * sec, 1e-6);
  absl::StatusOr<TriangleMesh> mesh = TriangleMesh::Build(*cut);
  ASSERT_TRUE(mesh.ok());
  EXPECT_EQ(mesh->report().components, 2u);
  absl::StatusOr<DistanceField> field = ComputeDistanceField(*mesh, {SurfacePoint::AtVertex(0)});
  ASSERT_TRUE(field.ok());
  EXPECT_TRUE(std::isfinite(field->distance[3]));
  EXPECT_TRUE(std::isinf(field->distance[n]));  // (10, 0), across the fence
}

// Lines without a width are slits: the surface is cut along them, both sides kept.
using Segment = std::array<Point2, 2>;

// Does p-q cross segment a-b (each passing through the other's inside)? Touching an end is not.
bool Crosses(const Point2& p, const Point2& q, const Segment& s) {
  const double eps = 1e-12;
  const double o1 = Cross(s[0], s[1], p), o2 = Cross(s[0], s[1], q), o3 = Cross(p, q, s[0]),
               o4 = Cross(p, q, s[1]);
  return ((o1 > eps && o2 < -eps) || (o1 < -eps && o2 > eps)) &&
         ((o3 > eps && o4 < -eps) || (o3 < -eps && o4 > eps));
}

// The shortest path from s to t on the plane around the slits, through their ends inside the grid.
double AroundSlits(const Point2& s, const Point2& t, const std::vector<Segment>& slits, int n) {
  std::vector<Point2> nodes = {s, t};
  for (const Segment& l : slits) {
    for (const Point2& e : l) {
      if (e[0] > 0 && e[0] < n && e[1] > 0 && e[1] < n) nodes.push_back(e);
    }
  }
  std::vector<double> best(nodes.size(), std::numeric_limits<double>::infinity());
  std::vector<bool> done(nodes.size(), false);
  best[0] = 0;
  for (size_t round = 0; round < nodes.size(); ++round) {
    size_t u = nodes.size();
    for (size_t k = 0; k < nodes.size(); ++k) {
      if (!done[k] && (u == nodes.size() || best[k] < best[u])) u = k;
    }
    if (u == nodes.size() || !std::isfinite(best[u])) break;
    done[u] = true;
    for (size_t v = 0; v < nodes.size(); ++v) {
      bool visible = v != u;
      for (const Segment& l : slits) visible = visible && !Crosses(nodes[u], nodes[v], l);
      if (visible) best[v] = std::min(best[v], best[u] + Length3(nodes[u], nodes[v]));
    }
  }
  return best[1];
}

double DistanceToSegment(const Point2& p, const Segment& s) {
  return DistanceToBoundary(p, {s[0], s[1]});
}

std::string LinesJson(const std::vector<Segment>& lines) {
  std::string parts;
  for (const Segment& l : lines) {
    absl::StrAppendFormat(&parts, "%s[[%.17g, %.17g], [%.17g, %.17g]]", parts.empty() ? "" : ", ",
                          l[0][0], l[0][1], l[1][0], l[1][1]);
  }
  return absl::StrCat(R"({"type": "MultiLineString", "coordinates": [)", parts, "]}");
}

TEST(BarrierCutTest, LinesWithoutAWidthAreExactSlits) {
  const int n = 16;
  const MeshData grid = TiltedGrid(n);
  // A wall with a gap (both inner ends inside faces), and a line lying along mesh edges through
  // two vertices (its ends on vertices).
  const std::vector<Segment> slits = {Segment{Point2{6.2, -1}, Point2{8.1, 7.35}},
                                      Segment{Point2{8.55, 9.3}, Point2{10.4, 17}},
                                      Segment{Point2{12, 2}, Point2{15, 5}}};
  CutStats stats;
  absl::StatusOr<MeshData> cut =
      CutBarrierPolygons(grid, LinesJson(slits), nullptr, 0, "slits", &stats);
  ASSERT_TRUE(cut.ok()) << cut.status();
  EXPECT_GT(stats.faces_cut, 0u);
  EXPECT_EQ(stats.faces_removed, 0u);
  // Nothing removed: the area is the plane's; every edge with one face lies on the grid's edge or
  // on a line (a slit's two sides).
  const double sec = std::sqrt(1 + kSlopeX * kSlopeX + kSlopeY * kSlopeY);
  EXPECT_NEAR(Area3(*cut), n * n * sec, 1e-10 * n * n);
  std::vector<std::vector<Point2>> as_rings;
  for (const Segment& l : slits) as_rings.push_back({l[0], l[1]});
  ExpectConforming(*cut, n, as_rings);
  absl::StatusOr<TriangleMesh> mesh = TriangleMesh::Build(*cut);
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  EXPECT_EQ(mesh->report().components, 1u);  // the gap and the ends keep it whole

  for (const Point2 source : {Point2{2, 8}, Point2{13, 1}, Point2{15, 3}}) {
    const uint32_t s = static_cast<uint32_t>(source[1] * (n + 1) + source[0]);
    absl::StatusOr<DistanceField> field = ComputeDistanceField(*mesh, {SurfacePoint::AtVertex(s)});
    ASSERT_TRUE(field.ok()) << field.status();
    double worst = 0;
    int around = 0;
    for (int j = 0; j <= n; ++j) {
      for (int i = 0; i <= n; ++i) {
        const Point2 target = {1.0 * i, 1.0 * j};
        bool on_line = false;
        for (const Segment& l : slits) on_line |= DistanceToSegment(target, l) < 1e-9;
        if (on_line) continue;  // a point of the slit itself is on both sides
        const double d = field->distance[j * (n + 1) + i];
        const double expected = AroundSlits(source, target, slits, n);
        bool blocked = false;
        for (const Segment& l : slits) blocked |= Crosses(source, target, l);
        around += blocked ? 1 : 0;
        worst = std::max(worst, std::abs(d - expected) / std::max(expected, 1.0));
      }
    }
    EXPECT_GT(around, 10) << "the lines are in the way of some paths";
    EXPECT_LT(worst, 1e-9) << source[0] << " " << source[1];
  }

  // A line across the whole grid separates.
  absl::StatusOr<MeshData> across = CutBarrierPolygons(
      grid, LinesJson({Segment{Point2{-1, 4.37}, Point2{17, 5.91}}}), nullptr, 0, "across", &stats);
  ASSERT_TRUE(across.ok()) << across.status();
  absl::StatusOr<TriangleMesh> halves = TriangleMesh::Build(*across);
  ASSERT_TRUE(halves.ok());
  EXPECT_EQ(halves->report().components, 2u);
  absl::StatusOr<DistanceField> field = ComputeDistanceField(*halves, {SurfacePoint::AtVertex(0)});
  ASSERT_TRUE(field.ok());
  EXPECT_NEAR(field->distance[3 * (n + 1) + 5], Length3({0, 0}, {5, 3}), 1e-9);
  EXPECT_TRUE(std::isinf(field->distance[8 * (n + 1) + 5]));
}

// Hostile or careless barriers: NaN coordinates are refused, a self-touching (invalid) polygon
// is made valid as areas, a line ending in a repeated point keeps its end, and a cut that would
// make more vertices than allowed stops with the vertex limit.
TEST(BarrierCutTest, BadBarriersAreClearErrorsOrRepaired) {
  const int n = 8;
  const MeshData grid = TiltedGrid(n);
  CutStats stats;
  absl::Status nan =
      CutBarrierPolygons(grid, R"({"type": "LineString", "coordinates": [[1, 1], [2, NaN]]})",
                         nullptr, 0, "--barrier f", &stats)
          .status();
  EXPECT_EQ(nan.code(), absl::StatusCode::kInvalidArgument) << nan;
  // A bow tie (self-intersecting ring): its two triangles are cut.
  absl::StatusOr<MeshData> bowtie = CutBarrierPolygons(
      grid,
      R"({"type": "Polygon", "coordinates": [[[1.3, 1.2], [4.7, 4.6], [4.7, 1.2], [1.3, 4.6], [1.3, 1.2]]]})",
      nullptr, 0, "bowtie", &stats);
  ASSERT_TRUE(bowtie.ok()) << bowtie.status();
  const double sec = std::sqrt(1 + kSlopeX * kSlopeX + kSlopeY * kSlopeY);
  EXPECT_NEAR(Area3(*bowtie), (n * n - 2 * (3.4 * 1.7 / 2)) * sec, 1e-9 * n * n);
  // A line whose last point repeats still ends where it ends (the slit reaches it).
  absl::StatusOr<MeshData> repeated = CutBarrierPolygons(
      grid, R"({"type": "LineString", "coordinates": [[-1, 3.3], [4.55, 3.3], [4.55, 3.3]]})",
      nullptr, 0, "line", &stats);
  absl::StatusOr<MeshData> plain =
      CutBarrierPolygons(grid, R"({"type": "LineString", "coordinates": [[-1, 3.3], [4.55, 3.3]]})",
                         nullptr, 0, "line", &stats);
  ASSERT_TRUE(repeated.ok() && plain.ok());
  EXPECT_EQ(repeated->faces, plain->faces) << repeated->face_count() << " " << plain->face_count();
  EXPECT_EQ(repeated->positions, plain->positions)
      << repeated->vertex_count() << " " << plain->vertex_count();
  // The vertex budget.
  absl::Status budget =
      CutBarrierPolygons(grid, R"({"type": "LineString", "coordinates": [[-1, 3.3], [9, 4.1]]})",
                         nullptr, 0, "line", &stats, grid.vertex_count() + 2)
          .status();
  EXPECT_EQ(budget.code(), absl::StatusCode::kResourceExhausted) << budget;
}

TEST(BarrierCutTest, TwoHolesAndAPolygonAlongGridLines) {
  const int n = 12;
  const MeshData grid = TiltedGrid(n);
  // One square exactly on grid lines (its faces go whole, its neighbours stay whole), and a
  // triangle with a corner on a grid vertex.
  const std::vector<Point2> square = {{2, 2}, {5, 2}, {5, 5}, {2, 5}};
  const std::vector<Point2> triangle = {{7, 7}, {10.5, 8.5}, {8.25, 10.5}};
  // Touching cases: the faces on the other side of a grid edge lose nothing but must take the
  // points put on it (a corner in the middle of an edge; an edge along part of a grid line).
  const std::vector<Point2> tip = {{3.5, 8}, {4.7, 9.6}, {2.6, 9.4}};
  // A corner a hair (1e-12) inside a face, next to its edge: put on the edge (GEOS's rounding is
  // far larger), so the face beyond, which the polygon does not reach, must take it too.
  const std::vector<Point2> hair = {{9.5, 5 + 1e-12}, {10.6, 6.4}, {8.7, 6.2}};
  const std::vector<Point2> ledge = {{6.5, 2}, {8.5, 2}, {8.5, 3.7}, {6.5, 3.7}};
  const std::vector<std::vector<Point2>> all = {square, triangle, tip, ledge, hair};
  CutStats stats;
  absl::StatusOr<MeshData> cut =
      CutBarrierPolygons(grid, PolygonJson(all), nullptr, 0, "holes", &stats);
  ASSERT_TRUE(cut.ok()) << cut.status();
  ExpectConforming(*cut, n, all);
  EXPECT_GT(stats.faces_split, 0u);
  const double sec = std::sqrt(1 + kSlopeX * kSlopeX + kSlopeY * kSlopeY);
  double holes = 0;
  for (const auto& ring : all) holes += Shoelace(ring);
  EXPECT_NEAR(Area3(*cut), (n * n - holes) * sec, 1e-10 * n * n);
  EXPECT_GE(stats.faces_removed, 18u);  // the square's 9 blocks, and what the triangle covers
  absl::StatusOr<TriangleMesh> mesh = TriangleMesh::Build(*cut);
  ASSERT_TRUE(mesh.ok()) << mesh.status();
  absl::StatusOr<DistanceField> field = ComputeDistanceField(*mesh, {SurfacePoint::AtVertex(0)});
  ASSERT_TRUE(field.ok());
  for (const Point2 target :
       {Point2{12, 12}, Point2{6, 3}, Point2{3, 12}, Point2{11, 9}, Point2{9, 4}, Point2{4, 10}}) {
    const double d = field->distance[static_cast<size_t>(target[1] * (n + 1) + target[0])];
    EXPECT_NEAR(d, TautString({0, 0}, target, all), 1e-9 * d) << target[0] << " " << target[1];
  }
  // A polygon that misses the mesh changes nothing.
  absl::StatusOr<MeshData> away = CutBarrierPolygons(
      grid, PolygonJson({{{30, 30}, {31, 30}, {31, 31}}}), nullptr, 0, "away", &stats);
  ASSERT_TRUE(away.ok());
  EXPECT_EQ(away->faces, grid.faces);
  EXPECT_EQ(away->positions, grid.positions);
}

// On a GDAL-made tilted plane (a DEM in UTM 33N, 10 m cells), a square hole turned 30 degrees,
// its corners inside cells, read from a GeoJSON file with --barrier's route (Dem::Read): map point
// to map point, the distance is the taut string around the hole's corners to 1e-9.
TEST(BarrierCutTest, DemHoleGivesTheTautString) {
  GDALAllRegister();
  const std::filesystem::path dir =
      std::filesystem::path(::testing::TempDir()) / "geodex-barrier-dem-hole";
  std::filesystem::create_directories(dir);
  const std::string tif = (dir / "plane.tif").string(), hole_file = (dir / "hole.geojson").string();
  const double ax = 0.12, ay = -0.07;  // z = ax (x - 500000) + ay (y - 5000000)
  GDALDataset* ds = GetGDALDriverManager()->GetDriverByName("GTiff")->Create(tif.c_str(), 40, 30, 1,
                                                                             GDT_Float64, nullptr);
  double gt[6] = {500000, 10, 0, 5000000, 0, -10};
  ds->SetGeoTransform(gt);
  OGRSpatialReference utm;
  utm.importFromEPSG(32633);
  ds->SetSpatialRef(&utm);
  std::vector<double> row(40);
  for (int j = 0; j < 30; ++j) {
    for (int i = 0; i < 40; ++i) row[i] = ax * (i + 0.5) * 10 + ay * -(j + 0.5) * 10;
    ASSERT_EQ(
        ds->GetRasterBand(1)->RasterIO(GF_Write, 0, j, 40, 1, row.data(), 40, 1, GDT_Float64, 0, 0),
        CE_None);
  }
  GDALClose(ds);
  std::vector<Point2> hole;
  for (int k = 0; k < 4; ++k) {
    const double a = (30 + 90 * k) * M_PI / 180;
    hole.push_back({500203.7 + 60 * std::cos(a), 4999851.3 + 60 * std::sin(a)});
  }
  std::string ring;
  for (size_t k = 0; k <= hole.size(); ++k) {
    absl::StrAppendFormat(&ring, "%s[%.17g, %.17g]", k == 0 ? "" : ", ", hole[k % 4][0],
                          hole[k % 4][1]);
  }
  std::ofstream(hole_file)
      << R"({"type": "Polygon", "crs": {"type": "name", "properties": {"name": "EPSG:32633"}}, "coordinates": [[)"
      << ring << "]]}";
  DemOptions options;
  options.barrier_files = {hole_file};
  absl::StatusOr<Dem> dem = Dem::Read(tif, options);
  ASSERT_TRUE(dem.ok()) << dem.status();
  EXPECT_GT(dem->info().barrier_faces, 0u);
  absl::StatusOr<TriangleMesh> mesh = TriangleMesh::Build(dem->mesh());
  ASSERT_TRUE(mesh.ok());
  auto on_plane = [&](const Point2& p) {
    return std::array<double, 3>{p[0], p[1], ax * (p[0] - 500000) + ay * (p[1] - 5000000)};
  };
  auto length = [&](const Point2& p, const Point2& q) {
    const auto a = on_plane(p), b = on_plane(q);
    return std::hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);
  };
  const Point2 source = {500063.1, 4999847.9};
  absl::StatusOr<SurfacePoint> from = dem->DropMapPoint(source[0], source[1]);
  ASSERT_TRUE(from.ok()) << from.status();
  absl::StatusOr<DistanceField> field = ComputeDistanceField(*mesh, {*from});
  ASSERT_TRUE(field.ok());
  int around = 0;
  double worst = 0;
  for (uint32_t j = 0; j < 30; ++j) {
    for (uint32_t i = 0; i < 40; ++i) {
      const Point2 target = {500005.0 + 10 * i, 4999995.0 - 10 * j};
      bool inside = true;
      for (size_t k = 0; k < 4; ++k) inside &= Cross(hole[k], hole[(k + 1) % 4], target) > 0;
      const double d = field->distance[dem->VertexAt(i, j)];
      if (inside) {
        EXPECT_TRUE(std::isinf(d)) << i << " " << j;
        continue;
      }
      // The taut string: straight, or through one or two of the hole's corners.
      double expected = Blocked(source, target, hole) ? std::numeric_limits<double>::infinity()
                                                      : length(source, target);
      for (size_t a = 0; a < 4; ++a) {
        if (!Blocked(source, hole[a], hole) && !Blocked(hole[a], target, hole)) {
          expected = std::min(expected, length(source, hole[a]) + length(hole[a], target));
        }
        for (size_t b = 0; b < 4; ++b) {
          if (a != b && !Blocked(source, hole[a], hole) && !Blocked(hole[a], hole[b], hole) &&
              !Blocked(hole[b], target, hole)) {
            expected = std::min(expected, length(source, hole[a]) + length(hole[a], hole[b]) +
                                              length(hole[b], target));
          }
        }
      }
      around += Blocked(source, target, hole) ? 1 : 0;
      worst = std::max(worst, std::abs(d - expected) / expected);
    }
  }
  EXPECT_GT(around, 20);
  EXPECT_LT(worst, 1e-9);
  std::filesystem::remove_all(dir);
}

// On a DEM, a barrier given in longitude/latitude and the same one in the DEM's own CRS make the
// same cut; the stored mesh (Dem::FromMesh) drops map points as the read one does.
TEST(BarrierCutTest, DemBarrierInEitherCrsAndStoredAgain) {
  GDALAllRegister();
  const std::string path =
      (std::filesystem::path(::testing::TempDir()) / "geodex-barrier-plane.tif").string();
  GDALDataset* ds = GetGDALDriverManager()->GetDriverByName("GTiff")->Create(
      path.c_str(), 30, 20, 1, GDT_Float64, nullptr);
  double gt[6] = {500000, 10, 0, 5000000, 0, -10};
  ds->SetGeoTransform(gt);
  OGRSpatialReference utm, wgs84;
  utm.importFromEPSG(32633);
  wgs84.importFromEPSG(4326);
  utm.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  wgs84.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  ds->SetSpatialRef(&utm);
  std::vector<double> row(30);
  for (int j = 0; j < 20; ++j) {
    for (int i = 0; i < 30; ++i) row[i] = 0.1 * i - 0.05 * j;
    ASSERT_EQ(
        ds->GetRasterBand(1)->RasterIO(GF_Write, 0, j, 30, 1, row.data(), 30, 1, GDT_Float64, 0, 0),
        CE_None);
  }
  GDALClose(ds);
  absl::StatusOr<Dem> dem = Dem::Read(path);
  ASSERT_TRUE(dem.ok()) << dem.status();

  const std::vector<Point2> ring = {
      {500083.3, 4999912.1}, {500191.7, 4999897.4}, {500172.2, 4999832.6}, {500101.9, 4999851.5}};
  std::string native, lonlat;
  OGRCoordinateTransformation* to_ll = OGRCreateCoordinateTransformation(&utm, &wgs84);
  for (size_t k = 0; k <= ring.size(); ++k) {
    double x = ring[k % ring.size()][0], y = ring[k % ring.size()][1];
    absl::StrAppendFormat(&native, "%s[%.17g, %.17g]", k == 0 ? "" : ", ", x, y);
    ASSERT_TRUE(to_ll->Transform(1, &x, &y));
    absl::StrAppendFormat(&lonlat, "%s[%.17g, %.17g]", k == 0 ? "" : ", ", x, y);
  }
  OGRCoordinateTransformation::DestroyCT(to_ll);
  CutStats a_stats, b_stats;
  absl::StatusOr<MeshData> a = CutBarrierPolygons(
      dem->mesh(),
      absl::StrCat(
          R"({"type": "Polygon", "crs": {"type": "name", "properties": {"name": "EPSG:32633"}}, "coordinates": [[)",
          native, "]]}"),
      &dem->info(), 0, "native", &a_stats);
  absl::StatusOr<MeshData> b = CutBarrierPolygons(
      dem->mesh(), absl::StrCat(R"({"type": "Polygon", "coordinates": [[)", lonlat, "]]}"),
      &dem->info(), 0, "lonlat", &b_stats);
  ASSERT_TRUE(a.ok()) << a.status();
  ASSERT_TRUE(b.ok()) << b.status();
  EXPECT_EQ(a->faces, b->faces);
  ASSERT_EQ(a->positions.size(), b->positions.size());
  double worst = 0;
  for (size_t k = 0; k < a->positions.size(); ++k)
    worst = std::max(worst, std::abs(a->positions[k] - b->positions[k]));
  EXPECT_LT(worst, 1e-6);
  EXPECT_GT(a_stats.faces_cut, 0u);

  absl::StatusOr<Dem> stored = Dem::FromMesh(*a, dem->info());
  ASSERT_TRUE(stored.ok()) << stored.status();
  // Map points beside the barrier land in its pieces, on the plane; inside it they are in a hole.
  int landed = 0;
  for (double x = 500080; x < 500200; x += 3.7) {
    for (double y = 4999820; y < 4999920; y += 4.1) {
      absl::StatusOr<SurfacePoint> p = stored->DropMapPoint(x, y);
      std::vector<Point2> local;
      for (const Point2& q : ring) local.push_back({q[0], q[1]});
      bool inside = true;
      for (size_t k = 0; k < 4; ++k)
        inside &= Shoelace({local[k], local[(k + 1) % 4], Point2{x, y}}) < 0;
      if (inside) {
        EXPECT_FALSE(p.ok()) << x << " " << y;
        continue;
      }
      ASSERT_TRUE(p.ok()) << x << " " << y << ": " << p.status();
      double pos[3] = {0, 0, 0};
      for (int c = 0; c < 3; ++c) {
        for (int d = 0; d < 3; ++d)
          pos[d] += p->bary[c] * a->positions[3 * size_t{a->faces[3 * size_t{p->face} + c]} + d];
      }
      EXPECT_NEAR(pos[0], x, 1e-6);
      EXPECT_NEAR(pos[1], y, 1e-6);
      ++landed;
    }
  }
  EXPECT_GT(landed, 100);

  // A line along a column of cell centres slits the grid through its vertices: the stored mesh
  // takes the copies (at cell centres, each its cell vertex's twin) and the two sides part.
  absl::StatusOr<MeshData> slit = CutBarrierPolygons(
      dem->mesh(),
      R"({"type": "LineString", "crs": {"type": "name", "properties": {"name": "EPSG:32633"}}, "coordinates": [[500105, 5000010], [500105, 4999790]]})",
      &dem->info(), 0, "column", &a_stats);
  ASSERT_TRUE(slit.ok()) << slit.status();
  EXPECT_EQ(slit->vertex_count(), dem->mesh().vertex_count() + 20);  // one copy a row
  absl::StatusOr<Dem> slit_dem = Dem::FromMesh(*slit, dem->info());
  ASSERT_TRUE(slit_dem.ok()) << slit_dem.status();
  absl::StatusOr<TriangleMesh> halves = TriangleMesh::Build(*slit);
  ASSERT_TRUE(halves.ok());
  EXPECT_EQ(halves->report().components, 2u);
  absl::StatusOr<SurfacePoint> west = slit_dem->DropMapPoint(500051, 4999901),
                               east = slit_dem->DropMapPoint(500161, 4999901);
  ASSERT_TRUE(west.ok() && east.ok());
  absl::StatusOr<DistanceField> field = ComputeDistanceField(*halves, {*west});
  ASSERT_TRUE(field.ok());
  EXPECT_TRUE(std::isinf(field->distance[slit->faces[3 * size_t{east->face}]]));
}

}  // namespace
}  // namespace geodex::terrain
