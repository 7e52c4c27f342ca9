// geodex isolines / voronoi / delaunay: solve the multi-source field, derive the approximate
// geometry (paper section 6) and write it as JSON (default, stdout), OBJ lines or an SVG top view.
// With a server the geometry is computed there and written here exactly the same way.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <memory>
#include <set>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_split.h"
#include "cli_backend.h"
#include "cli_common.h"
#include "geodex/delaunay.h"
#include "geodex/geodesic_solver.h"
#include "geodex/gis_formats.h"
#include "geodex/isolines.h"
#include "geodex/locate.h"
#include "geodex/mesh_io.h"
#include "geodex/samples.h"
#include "geodex/surface_point.h"
#include "geodex/triangle_mesh.h"
#include "geodex/voronoi.h"

namespace geodex::cli {
namespace {

using Point3 = std::array<double, 3>;

// Everything a command needs: the mesh as read (file coordinates, for drawing and placing sites)
// and its points.
struct Solved {
  const MeshData* data = nullptr;
  std::vector<SurfacePoint> points;
};

// Opens the mesh on the backend, parses and resolves --`key` (and the travel weights into
// `options`). Returns 0 or an exit code (after
// printing the one-line message).
int Prepare(Backend& backend, const Args& args, const std::string& key, Solved* out,
            GeodesicOptions* options) {
  absl::StatusOr<std::vector<SurfacePoint>> points = ParseSpec(nullptr, key, args.options.at(key));
  if (!points.ok()) return Fail(kExitUsage, std::string(points.status().message()));
  if (int code = OpenMesh(backend, args, args.positional[0], MeshBuildOptions{})) return code;
  if (int code = ResolveTravelWeights(backend, args, options)) return code;
  points = ParseSpec(&backend, key, args.options.at(key));  // map points onto the DEM
  if (!points.ok()) return FailQuery(points.status());
  if (absl::Status s = ResolvePoints(backend, args, key, &*points, nullptr); !s.ok()) {
    return FailQuery(s);
  }
  out->points = *std::move(points);
  absl::StatusOr<const MeshData*> data = backend.Geometry();
  if (!data.ok()) return FailQuery(data.status());
  out->data = *data;
  return 0;
}

// --output: "" (stdout JSON) or a file whose extension picks the format.
enum class Format { kJson, kObj, kSvg, kGeoJson };
bool OutputFormat(const Args& args, Format* format, std::string* error) {
  *format = Format::kJson;
  if (!args.options.count("output")) return true;
  const std::string& path = args.options.at("output");
  auto ends = [&](const char* ext) {
    const std::string e(ext);
    return path.size() > e.size() && path.compare(path.size() - e.size(), e.size(), e) == 0;
  };
  if (IsVectorPath(args)) {
    *format = Format::kGeoJson;
    return true;
  }
  if (ends(".json")) return true;
  if (ends(".obj")) {
    *format = Format::kObj;
    return true;
  }
  if (ends(".svg")) {
    *format = Format::kSvg;
    return true;
  }
  *error = absl::StrFormat(
      "--output: '%s' must end in .json, .obj, .svg or, on a DEM, a vector file's %s", path,
      terrain::GisExtensions(terrain::GisFileKind::kVector));
  return false;
}

// --- JSON ------------------------------------------------------------------------------------

std::string Num(double x) { return absl::StrFormat("%.17g", x); }

std::string PointsJson(const std::vector<PathPoint>& points) {
  std::string s = "[";
  for (size_t i = 0; i < points.size(); ++i) s += (i ? ", " : "") + PathPointJson(points[i]);
  return s + "]";
}

std::string SitesJson(const Solved& s) {
  std::string json = "[";
  for (size_t i = 0; i < s.points.size(); ++i) {
    json += absl::StrFormat("%s{\"site\": %d, \"spec\": \"%s\", \"p\": %s}", i ? ", " : "", i,
                            SurfacePointToString(s.points[i]),
                            JsonXyz(PositionOf(*s.data, s.points[i])));
  }
  return json + "]";
}

// --- OBJ and SVG -----------------------------------------------------------------------------

struct Line {
  std::vector<Point3> points;
  bool closed = false;
  std::string name;   // OBJ group
  std::string color;  // SVG stroke
  double width = 1.5;
  bool dashed = false;
};

std::vector<Point3> Positions(const std::vector<PathPoint>& points) {
  std::vector<Point3> out;
  for (const PathPoint& p : points) out.push_back(p.position);
  return out;
}

std::string Obj(const std::string& title, const std::vector<Line>& lines) {
  std::string s = "# geodex " + title + " (approximate, paper section 6)\n";
  size_t next = 1;
  for (const Line& l : lines) {
    s += "g " + l.name + "\n";
    for (const Point3& p : l.points)
      s += absl::StrFormat("v %.17g %.17g %.17g\n", p[0], p[1], p[2]);
    s += "l";
    for (size_t i = 0; i < l.points.size(); ++i) s += absl::StrFormat(" %d", next + i);
    if (l.closed) s += absl::StrFormat(" %d", next);
    s += "\n";
    next += l.points.size();
  }
  return s;
}

// A top view (x right, y up) of the mesh's edges in light grey, the lines in colour and the sites
// as dots, scaled to 1000 pixels. Meshes with more than kMaxWireEdges edges show only their
// boundary edges.
constexpr size_t kMaxWireEdges = 200000;

std::string Svg(const std::string& title, const MeshData& mesh, const std::vector<Line>& lines,
                const std::vector<Point3>& sites) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  double lo[2] = {kInf, kInf}, hi[2] = {-kInf, -kInf};
  for (size_t i = 0; i < mesh.vertex_count(); ++i) {
    for (int k = 0; k < 2; ++k) {
      lo[k] = std::min(lo[k], mesh.positions[3 * i + k]);
      hi[k] = std::max(hi[k], mesh.positions[3 * i + k]);
    }
  }
  const double extent = std::max({hi[0] - lo[0], hi[1] - lo[1], 1e-300});
  const double scale = 1000 / extent, margin = 20;
  const double width = (hi[0] - lo[0]) * scale + 2 * margin;
  const double height = (hi[1] - lo[1]) * scale + 2 * margin;
  auto xy = [&](double x, double y) {
    return absl::StrFormat("%.2f,%.2f", (x - lo[0]) * scale + margin, (hi[1] - y) * scale + margin);
  };
  std::string s = absl::StrFormat(
      "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%.0f\" height=\"%.0f\" "
      "viewBox=\"0 0 %.2f %.2f\">\n<title>geodex %s (approximate)</title>\n"
      "<rect width=\"100%%\" height=\"100%%\" fill=\"white\"/>\n",
      width, height, width, height, title);
  // Mesh edges, each once; a count of faces per edge finds the boundary.
  std::vector<std::pair<uint32_t, uint32_t>> edges;
  for (size_t f = 0; f < mesh.face_count(); ++f) {
    for (int k = 0; k < 3; ++k) {
      const uint32_t a = mesh.faces[3 * f + k], b = mesh.faces[3 * f + (k + 1) % 3];
      edges.push_back({std::min(a, b), std::max(a, b)});
    }
  }
  std::sort(edges.begin(), edges.end());
  size_t unique = 0;
  for (size_t i = 0; i < edges.size(); ++i) unique += !i || edges[i] != edges[i - 1];
  const bool all = unique <= kMaxWireEdges;
  if (!all) s += "<!-- large mesh: only boundary edges are drawn -->\n";
  std::string d;
  for (size_t i = 0; i < edges.size(); ++i) {
    if (i && edges[i] == edges[i - 1]) continue;
    const bool boundary = i + 1 == edges.size() || edges[i + 1] != edges[i];
    if (!all && !boundary) continue;
    const auto [a, b] = edges[i];
    // StrAppend rather than chains of operator+ (GCC 12 -O3 warns falsely on those, -Wrestrict).
    absl::StrAppend(&d, "M", xy(mesh.positions[3 * a], mesh.positions[3 * a + 1]), "L",
                    xy(mesh.positions[3 * b], mesh.positions[3 * b + 1]));
  }
  absl::StrAppend(&s, "<path fill=\"none\" stroke=\"#d0d0d0\" stroke-width=\"0.5\" d=\"", d,
                  "\"/>\n");
  for (const Line& l : lines) {
    std::string pts;
    for (const Point3& p : l.points) absl::StrAppend(&pts, pts.empty() ? "" : " ", xy(p[0], p[1]));
    s += absl::StrFormat(
        "<%s fill=\"none\" stroke=\"%s\" stroke-width=\"%.1f\"%s points=\"%s\"><title>%s</title>"
        "</%s>\n",
        l.closed ? "polygon" : "polyline", l.color, l.width,
        l.dashed ? " stroke-dasharray=\"6,4\"" : "", pts, l.name,
        l.closed ? "polygon" : "polyline");
  }
  for (size_t i = 0; i < sites.size(); ++i) {
    const std::string c = xy(sites[i][0], sites[i][1]);
    const size_t comma = c.find(',');
    s += absl::StrFormat(
        "<circle cx=\"%s\" cy=\"%s\" r=\"4\" fill=\"black\"><title>site %d"
        "</title></circle>\n",
        c.substr(0, comma), c.substr(comma + 1), i);
  }
  return s + "</svg>\n";
}

// Blue (low) to red (high).
std::string LevelColor(double x) {
  return absl::StrFormat("hsl(%.0f,80%%,45%%)", 240 * (1 - std::min(1.0, std::max(0.0, x))));
}

std::vector<Point3> SitePositions(const Solved& s) {
  std::vector<Point3> out;
  for (const SurfacePoint& p : s.points) out.push_back(PositionOf(*s.data, p));
  return out;
}

int Usage(const std::string& command, const std::string& key, const std::string& extra) {
  return Fail(kExitUsage, absl::StrFormat("usage: geodex %s MESH --%s SPEC%s [--output FILE]",
                                          command, key, extra));
}

// geodex isolines: its entry of `geodex --help`.
constexpr char kIsolinesHelp[] =
    R"(  isolines MESH --sources SPEC (--levels L1,L2,... | --count K) [--output FILE.json|.obj|.svg]
                [--lambda L] [--lambda-scale max|mean] [--max-distance D] [--max-windows N]
      Approximate geodesic offsets (paper section 6.1; linear along edges): polylines of edge
      points per level. --count K: the levels D*j/K, j = 1..K-1, D the largest distance.
      The solver flags (as for distances) apply to the field the lines are drawn on; voronoi
      and delaunay take them too.
)";

int RunIsolines(Backend& backend, const Args& args) {
  std::string error;
  if (!CheckKnown(args,
                  {"sources", "levels", "count", "output", "max-snap", "lambda", "lambda-scale",
                   "max-distance", "max-windows"},
                  &error)) {
    return Fail(kExitUsage, error);
  }
  if (args.positional.size() != 1 || !args.options.count("sources") ||
      args.options.count("levels") == args.options.count("count")) {
    return Usage("isolines", "sources", " (--levels L1,L2,... | --count K)");
  }
  IsolineQuery query;
  if (!GetLevels(args, "count", &query.levels, &error) ||
      !GetSolverFlags(args, &query.options, &error)) {
    return Fail(kExitUsage, error);
  }
  Format format;
  if (!OutputFormat(args, &format, &error)) return Fail(kExitUsage, error);
  Solved s;
  absl::StatusOr<Isolines> iso;
  if (int code = Prepare(backend, args, "sources", &s, &query.options)) return code;
  query.sources = s.points;
  // Solved just past the top level, by both calls below (one field): never cut by --max-distance.
  query.options = IsolineFieldOptions(*s.data, query.options, query.levels);
  iso = backend.ComputeIsolines(query);
  if (!iso.ok()) return FailQuery(iso.status());

  const double top = iso->levels.empty() ? 1 : std::max(iso->levels.back(), 1e-300);
  std::vector<Line> lines;
  std::string json = "{\"approximate\": true, \"kind\": \"isolines\", \"levels\": [";
  for (size_t i = 0; i < iso->levels.size(); ++i) json += (i ? ", " : "") + Num(iso->levels[i]);
  json += "], \"sources\": " + SitesJson(s) + ", \"polylines\": [";
  for (size_t i = 0; i < iso->polylines.size(); ++i) {
    const IsolinePolyline& p = iso->polylines[i];
    json += absl::StrFormat("%s\n{\"level\": %.17g, \"closed\": %s, \"points\": %s}", i ? "," : "",
                            p.level, p.closed ? "true" : "false", PointsJson(p.points));
    lines.push_back({Positions(p.points), p.closed, absl::StrFormat("level_%g", p.level),
                     LevelColor(p.level / top)});
  }
  json += "]}\n";
  if (format == Format::kGeoJson) {
    // Isochrones: per level, the area within that distance (union of each face's part below it).
    absl::StatusOr<const DistanceField*> field = backend.Field({s.points, query.options, false});
    if (!field.ok()) return FailQuery(field.status());
    return WriteVectorOutput(
        backend, args,
        terrain::IsochroneFeatures(
            *s.data, (*field)->distance, iso->levels,
            query.options.travel.has_value() ? &*query.options.travel : nullptr),
        &query.options);
  }
  if (format == Format::kObj) return WriteOutput(args, Obj("isolines", lines));
  if (format == Format::kSvg)
    return WriteOutput(args, Svg("isolines", *s.data, lines, SitePositions(s)));
  return WriteOutput(args, json);
}

// geodex voronoi: its entry of `geodex --help`.
constexpr char kVoronoiHelp[] =
    R"(  voronoi MESH --sites SPEC [--output FILE.json|.obj|.svg] [--lambda L ...]
      Approximate Voronoi diagram (section 6.2): boundaries, cells (faces, fragments, areas),
      adjacency.
)";

int RunVoronoi(Backend& backend, const Args& args) {
  std::string error;
  if (!CheckKnown(
          args,
          {"sites", "output", "max-snap", "lambda", "lambda-scale", "max-distance", "max-windows"},
          &error)) {
    return Fail(kExitUsage, error);
  }
  if (args.positional.size() != 1 || !args.options.count("sites")) {
    return Usage("voronoi", "sites", "");
  }
  VoronoiQuery query;
  if (!GetSolverFlags(args, &query.options, &error)) return Fail(kExitUsage, error);
  Format format;
  if (!OutputFormat(args, &format, &error)) return Fail(kExitUsage, error);
  Solved s;
  absl::StatusOr<VoronoiDiagram> vd;
  if (int code = Prepare(backend, args, "sites", &s, &query.options)) return code;
  query.sites = s.points;
  vd = backend.ComputeVoronoi(query);
  if (!vd.ok()) return FailQuery(vd.status());

  std::vector<Line> lines;
  std::string json = absl::StrFormat(
      "{\"approximate\": true, \"kind\": \"voronoi\", \"sites\": %s, \"total_area\": %.17g, "
      "\"junction_faces\": %d, \"adjacency\": [",
      SitesJson(s), vd->total_area, vd->junction_faces);
  for (size_t i = 0; i < vd->adjacency.size(); ++i) {
    json += absl::StrFormat("%s[%d, %d]", i ? ", " : "", vd->adjacency[i][0], vd->adjacency[i][1]);
  }
  json += "], \"boundaries\": [";
  for (size_t i = 0; i < vd->boundaries.size(); ++i) {
    const VoronoiBoundary& b = vd->boundaries[i];
    json +=
        absl::StrFormat("%s\n{\"sites\": [%d, %d], \"closed\": %s, \"points\": %s}", i ? "," : "",
                        b.site_a, b.site_b, b.closed ? "true" : "false", PointsJson(b.points));
    lines.push_back({Positions(b.points), b.closed,
                     absl::StrFormat("boundary_%d_%d", b.site_a, b.site_b), "#c0392b", 2});
  }
  json += "], \"cells\": [";
  for (size_t i = 0; i < vd->cells.size(); ++i) {
    const VoronoiCell& c = vd->cells[i];
    json += absl::StrFormat("%s\n{\"site\": %d, \"area\": %.17g, \"whole_faces\": [", i ? "," : "",
                            c.site, c.area);
    for (size_t k = 0; k < c.whole_faces.size(); ++k) {
      json += absl::StrFormat("%s%d", k ? ", " : "", c.whole_faces[k]);
    }
    json += "], \"fragments\": [";
    for (size_t k = 0; k < c.fragments.size(); ++k) {
      const VoronoiFragment& f = c.fragments[k];
      json += absl::StrFormat("%s{\"face\": %d, \"area\": %.17g, \"polygon\": %s}", k ? ", " : "",
                              f.face, f.area, PointsJson(f.polygon));
    }
    json += "]}";
  }
  json += "]}\n";
  if (format == Format::kGeoJson) {
    // One (Multi)Polygon per site: its whole faces and its fragments, unioned.
    return WriteVectorOutput(backend, args, terrain::VoronoiFeatures(*s.data, *vd), &query.options);
  }
  if (format == Format::kObj) return WriteOutput(args, Obj("voronoi", lines));
  if (format == Format::kSvg)
    return WriteOutput(args, Svg("voronoi", *s.data, lines, SitePositions(s)));
  return WriteOutput(args, json);
}

std::string EdgeJson(const DelaunayEdge& e) {
  return absl::StrFormat(
      "{\"sites\": [%d, %d], \"mesh_edge\": [%d, %d], \"length\": %.17g, \"edge_start\": %d, "
      "\"points\": %s}",
      e.site_a, e.site_b, e.vertex_a, e.vertex_b, e.length, e.edge_start, PointsJson(e.points));
}

// geodex delaunay: its entry of `geodex --help`.
constexpr char kDelaunayHelp[] =
    R"(  delaunay MESH --sites SPEC [--output FILE.json|.obj|.svg] [--lambda L ...]
      Approximate Delaunay triangulation (sections 6.3-6.4): edges as polylines, triangles, XL
      edges found and the Delaunay edges removed because of them.
      These three print JSON ("approximate": true) unless --output names an .obj (lines) or
      .svg (top view) file; see docs/geometry.md.
)";

int RunDelaunay(Backend& backend, const Args& args) {
  std::string error;
  if (!CheckKnown(
          args,
          {"sites", "output", "max-snap", "lambda", "lambda-scale", "max-distance", "max-windows"},
          &error)) {
    return Fail(kExitUsage, error);
  }
  if (args.positional.size() != 1 || !args.options.count("sites")) {
    return Usage("delaunay", "sites", "");
  }
  DelaunayQuery query;
  if (!GetSolverFlags(args, &query.options, &error)) return Fail(kExitUsage, error);
  Format format;
  if (!OutputFormat(args, &format, &error)) return Fail(kExitUsage, error);
  Solved s;
  absl::StatusOr<DelaunayTriangulation> dt;
  if (int code = Prepare(backend, args, "sites", &s, &query.options)) return code;
  query.sites = s.points;
  dt = backend.ComputeDelaunay(query);
  if (!dt.ok()) return FailQuery(dt.status());

  std::vector<Line> lines;
  std::string json = "{\"approximate\": true, \"kind\": \"delaunay\", \"sites\": " + SitesJson(s) +
                     ", \"triangles\": [";
  for (size_t i = 0; i < dt->triangles.size(); ++i) {
    const auto& t = dt->triangles[i];
    json += absl::StrFormat("%s[%d, %d, %d]", i ? ", " : "", t[0], t[1], t[2]);
  }
  json += "], \"edges\": [";
  for (size_t i = 0; i < dt->edges.size(); ++i) {
    const DelaunayEdge& e = dt->edges[i];
    json += (i ? ",\n" : "\n") + EdgeJson(e);
    lines.push_back({Positions(e.points), false, absl::StrFormat("edge_%d_%d", e.site_a, e.site_b),
                     "#1f5fbf", 2});
  }
  json += "], \"removed_edges\": [";
  for (size_t i = 0; i < dt->removed_edges.size(); ++i) {
    const DelaunayEdge& e = dt->removed_edges[i];
    json += (i ? ",\n" : "\n") + EdgeJson(e);
    Line l{Positions(e.points), false, absl::StrFormat("removed_%d_%d", e.site_a, e.site_b),
           "#888888", 1.5};
    l.dashed = true;
    lines.push_back(l);
  }
  json += "], \"xl_edges\": [";
  for (size_t i = 0; i < dt->xl_edges.size(); ++i) {
    const XlEdge& x = dt->xl_edges[i];
    json += absl::StrFormat(
        "%s\n{\"edge\": [%d, %d], \"sites\": [%d, %d], \"witness\": %d, "
        "\"point\": %s}",
        i ? "," : "", x.vertex_a, x.vertex_b, x.site_a, x.site_b, x.witness,
        PathPointJson(x.point));
    const Point3 a = PositionOf(*s.data, SurfacePoint::AtVertex(x.vertex_a));
    const Point3 b = PositionOf(*s.data, SurfacePoint::AtVertex(x.vertex_b));
    lines.push_back(
        {{a, b}, false, absl::StrFormat("xl_%d_%d", x.vertex_a, x.vertex_b), "#ff8c00", 4});
  }
  json += "]}\n";
  if (format == Format::kGeoJson) {
    // One 3D LineString per Delaunay edge: the geodesic between its two sites.
    return WriteVectorOutput(backend, args, terrain::DelaunayFeatures(*dt), &query.options);
  }
  if (format == Format::kObj) return WriteOutput(args, Obj("delaunay", lines));
  if (format == Format::kSvg)
    return WriteOutput(args, Svg("delaunay", *s.data, lines, SitePositions(s)));
  return WriteOutput(args, json);
}

}  // namespace

const Command& IsolinesCommand() {
  static const Command command{"isolines", kIsolinesHelp, {"inbound"}, RunIsolines};
  return command;
}
const Command& VoronoiCommand() {
  static const Command command{"voronoi", kVoronoiHelp, {"inbound"}, RunVoronoi};
  return command;
}
const Command& DelaunayCommand() {
  static const Command command{"delaunay", kDelaunayHelp, {"inbound"}, RunDelaunay};
  return command;
}

}  // namespace geodex::cli
