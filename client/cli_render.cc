// geodex render: a picture of a distance field (and optionally its isolines, Voronoi boundaries,
// Delaunay edges and a shortest path) as PNG, or the coloured mesh as PLY or glTF, on either
// backend (with --server the mesh file is read here too: it is what gets drawn).

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>

#include "absl/strings/numbers.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_split.h"
#include "cli_backend.h"
#include "cli_common.h"
#include "geodex/delaunay.h"
#include "geodex/geodesic_solver.h"
#include "geodex/isolines.h"
#include "geodex/voronoi.h"
#include "render.h"

namespace geodex::cli {
namespace {

using render::Polyline;
using render::Rgb;

std::vector<render::Point3> Positions(const std::vector<PathPoint>& points) {
  std::vector<render::Point3> out;
  for (const PathPoint& p : points) out.push_back(p.position);
  return out;
}

bool EndsWith(const std::string& s, const std::string& suffix) {
  return s.size() > suffix.size() &&
         s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// What the picture shows, computed locally or by a server.
struct Layers {
  const DistanceField* field = nullptr;  // the backend's
  Isolines isolines;
  VoronoiDiagram voronoi;
  DelaunayTriangulation delaunay;
  PathQueryResult path;
};

// geodex render: its entry of `geodex --help`.
constexpr char kRenderHelp[] =
    R"(  render MESH --sources SPEC [--isolines K | --levels L1,L2,...] [--voronoi] [--delaunay]
         [--path A B] --output out.png|.ply|.gltf [--view auto|iso|top|bottom|front|back|left|right]
         [--size WxH]
      A picture of the field: the shaded mesh coloured by distance (viridis; grey where
      unreachable) with a colour bar (0 to the largest distance, ticks at round values that
      always fit, m or km on a DEM; at least 320 pixels wide), isolines (dark, each labelled
      with its level; --isolines K or --levels as for isolines), Voronoi boundaries (white),
      Delaunay edges (orange), the path (red) and the sources (black dots), framed
      automatically (z up; 800x600); on a DEM a scale bar at the bottom left. The default view,
      auto, is the one of iso and the six axis views that shows the most sources, then the most
      of the lines.
      .ply and .gltf write the coloured mesh for 3D viewers instead. With --speed (and the
      other travel flags) a travel-time map: the bar in s, or min from 10 minutes on.
)";

int RunRender(Backend& backend, const Args& args) {
  std::string error;
  // "lambda" etc.: the solver's flags, which also admit the travel flags (kTravelFlags): with
  // --speed the picture is a travel-time map.
  if (!CheckKnown(args,
                  {"sources", "isolines", "levels", "voronoi", "delaunay", "path", "output", "view",
                   "size", "max-snap", "lambda", "lambda-scale", "max-distance", "max-windows"},
                  &error)) {
    return Fail(kExitUsage, error);
  }
  // --path A B: B arrives as a second positional argument; --path A,B works too.
  std::vector<std::string> positional = args.positional;
  std::string path_spec = args.options.count("path") ? args.options.at("path") : "";
  if (!path_spec.empty() && path_spec.find(',') == std::string::npos && positional.size() == 2) {
    path_spec += "," + positional[1];
    positional.pop_back();
  }
  if (positional.size() != 1 || !args.options.count("sources") || !args.options.count("output")) {
    return Fail(
        kExitUsage,
        "usage: geodex render MESH --sources SPEC [--isolines K | --levels L,...] [--voronoi] "
        "[--delaunay] "
        "[--path A B] --output out.png|.ply|.gltf [--view auto|iso|top|front|...] [--size WxH]");
  }
  const std::string output = args.options.at("output");
  if (!EndsWith(output, ".png") && !EndsWith(output, ".ply") && !EndsWith(output, ".gltf")) {
    return Fail(kExitUsage,
                absl::StrFormat("--output: '%s' must end in .png, .ply or .gltf", output));
  }
  absl::StatusOr<render::View> view =
      render::ParseView(args.options.count("view") ? args.options.at("view") : "auto");
  if (!view.ok()) return Fail(kExitUsage, std::string(view.status().message()));
  int width = 800, height = 600;
  if (args.options.count("size")) {
    std::vector<std::string> wh = absl::StrSplit(args.options.at("size"), 'x');
    if (wh.size() != 2 || !absl::SimpleAtoi(wh[0], &width) || !absl::SimpleAtoi(wh[1], &height) ||
        width < 16 || height < 16 || width > 8192 || height > 8192) {
      return Fail(kExitUsage, absl::StrFormat("--size: '%s' is not WxH with 16..8192 pixels each",
                                              args.options.at("size")));
    }
  }
  IsolineOptions levels;  // --isolines K or --levels L1,L2,... as for `geodex isolines`
  if (args.options.count("isolines") && args.options.count("levels")) {
    return Fail(kExitUsage, "--isolines K and --levels L1,L2,...: one or the other");
  }
  if (!GetLevels(args, "isolines", &levels, &error)) return Fail(kExitUsage, error);
  const bool isolines = levels.count > 0 || !levels.levels.empty();
  GeodesicOptions solver;  // --speed, --friction, --lambda, ... (a travel-time map with --speed)
  if (!GetSolverFlags(args, &solver, &error)) return Fail(kExitUsage, error);
  const bool voronoi = args.options.count("voronoi") > 0,
             delaunay = args.options.count("delaunay") > 0;

  absl::StatusOr<std::vector<SurfacePoint>> sources =
      ParseSpec(nullptr, "sources", args.options.at("sources"));
  if (!sources.ok()) return Fail(kExitUsage, std::string(sources.status().message()));
  std::vector<SurfacePoint> ends;
  if (!path_spec.empty()) {
    absl::StatusOr<std::vector<SurfacePoint>> p = ParseSpec(nullptr, "path", path_spec);
    if (!p.ok() || p->size() != 2) {
      return Fail(kExitUsage, "--path: expected two points (--path A B or --path A,B)");
    }
  }
  if (int code = OpenMesh(backend, args, positional[0], MeshBuildOptions{})) return code;
  if (int code = ResolveTravelWeights(backend, args, &solver)) return code;
  sources = ParseSpec(&backend, "sources", args.options.at("sources"));  // map points onto the DEM
  if (!sources.ok()) return FailQuery(sources.status());
  if (!path_spec.empty()) {
    absl::StatusOr<std::vector<SurfacePoint>> p = ParseSpec(&backend, "path", path_spec);
    if (!p.ok()) return FailQuery(p.status());
    ends = *std::move(p);
  }
  absl::StatusOr<const MeshData*> data = backend.Geometry();
  if (!data.ok()) return FailQuery(data.status());
  if (absl::Status s = ResolvePoints(backend, args, "sources", &*sources, nullptr); !s.ok()) {
    return FailQuery(s);
  }
  if (!ends.empty()) {
    if (absl::Status s = ResolvePoints(backend, args, "path", &ends, nullptr); !s.ok()) {
      return FailQuery(s);
    }
  }

  // A local backend solves the field once and derives the layers from it.
  Layers layers;
  absl::StatusOr<const DistanceField*> field = backend.Field({*sources, solver, false});
  if (!field.ok()) return FailQuery(field.status());
  layers.field = *field;
  if (isolines) {
    absl::StatusOr<Isolines> iso = backend.ComputeIsolines({*sources, solver, levels});
    if (!iso.ok()) return FailQuery(iso.status());
    layers.isolines = *std::move(iso);
  }
  if (voronoi) {
    absl::StatusOr<VoronoiDiagram> v = backend.ComputeVoronoi({*sources, solver});
    if (!v.ok()) return FailQuery(v.status());
    layers.voronoi = *std::move(v);
  }
  if (delaunay) {
    absl::StatusOr<DelaunayTriangulation> d = backend.ComputeDelaunay({*sources, solver});
    if (!d.ok()) return FailQuery(d.status());
    layers.delaunay = *std::move(d);
  }
  if (!ends.empty()) {
    PathQueryOptions path_options;
    path_options.solver = solver;
    absl::StatusOr<PathQueryResult> p = backend.Path({ends[0], ends[1], path_options});
    if (!p.ok()) return FailQuery(p.status());
    layers.path = *std::move(p);
  }

  render::Scene scene;
  scene.mesh = *data;
  if (backend.Terrain() != nullptr) {  // a DEM is in metres, and gets a scale bar
    scene.units = "m";
    scene.scale_bar = true;
  }
  if (solver.travel.has_value()) {
    scene.units = "s";  // a travel-time map: the bar and the isoline labels in s, or min
    scene.caption = "travel time";
  }
  scene.vertex_colors = render::FieldColors(layers.field->distance);
  for (double d : layers.field->distance) {
    if (std::isfinite(d)) scene.max_distance = std::max(scene.max_distance, d);
  }
  for (const IsolinePolyline& line : layers.isolines.polylines) {  // labelled with its level
    scene.lines.push_back({Positions(line.points), line.closed, Rgb{25, 25, 25}, 1.5,
                           render::NiceLabel(line.level, scene.units)});
  }
  for (const VoronoiBoundary& b : layers.voronoi.boundaries) {
    scene.lines.push_back({Positions(b.points), b.closed, Rgb{255, 255, 255}, 2.5, ""});
  }
  for (const DelaunayEdge& e : layers.delaunay.edges) {
    scene.lines.push_back({Positions(e.points), false, Rgb{255, 140, 0}, 2, ""});
  }
  if (!layers.path.path.points.empty()) {
    scene.lines.push_back({Positions(layers.path.path.points), false, Rgb{220, 20, 60}, 3, ""});
    for (const SurfacePoint& p : ends) scene.markers.push_back(PositionOf(**data, p));
  }
  for (const SurfacePoint& p : *sources) scene.markers.push_back(PositionOf(**data, p));

  absl::Status written;
  if (EndsWith(output, ".png")) {
    written = render::WritePng(output, render::Render(scene, *view, width, height));
  } else if (EndsWith(output, ".ply")) {
    written = render::WriteColoredPly(output, **data, scene.vertex_colors, layers.field->distance);
  } else {
    written = render::WriteGltf(output, **data, scene.vertex_colors);
  }
  if (!written.ok()) {  // a path we cannot write is a bad argument; a libpng failure is not
    return Fail(absl::IsInternal(written) ? kExitInput : kExitUsage,
                std::string(written.message()));
  }
  return kExitOk;
}

}  // namespace

const Command& RenderCommand() {
  static const Command command{"render", kRenderHelp, {"voronoi", "delaunay"}, RunRender};
  return command;
}

}  // namespace geodex::cli
