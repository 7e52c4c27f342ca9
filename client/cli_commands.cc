#include "cli_commands.h"

#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <memory>
#include <set>

#include "absl/container/flat_hash_map.h"
#include "absl/strings/match.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "absl/strings/str_replace.h"
#include "absl/strings/str_split.h"
#include "absl/strings/strip.h"
#include "cli_backend.h"
#include "cli_common.h"
#include "geodex/distance_matrix.h"
#include "geodex/friction.h"
#include "geodex/geodesic_solver.h"
#include "geodex/gis_formats.h"
#include "geodex/limits.h"
#include "geodex/locate.h"
#include "geodex/mesh_io.h"
#include "geodex/point_distance.h"
#include "geodex/samples.h"
#include "geodex/shortest_path.h"
#include "geodex/surface_point.h"
#include "geodex/triangle_mesh.h"

namespace geodex::cli {

namespace {

// A SPEC that must name exactly one point.
absl::Status OnePoint(Backend& backend, const Args& args, const std::string& key, SurfacePoint* out,
                      SnapReport* report) {
  std::vector<SurfacePoint> p;
  if (absl::Status s = ResolveOption(backend, args, key, &p, report); !s.ok()) return s;
  if (p.size() != 1) {
    return absl::InvalidArgumentError(
        absl::StrFormat("--%s: expected one point, got %d", key, p.size()));
  }
  *out = p.front();
  return absl::OkStatus();
}

}  // namespace

namespace {

std::string FormatInfo(const InfoValues& v, bool json) {
  const MeshReport& r = v.report;
  const std::vector<std::pair<std::string, std::string>> rows = {
      {"vertices", absl::StrFormat("%d", r.file_vertices)},
      {"faces", absl::StrFormat("%d", r.file_faces)},
      {"boundary_edges", absl::StrFormat("%d", r.boundary_edges)},
      {"boundary_loops", absl::StrFormat("%d", r.boundary_loops)},
      {"components", absl::StrFormat("%d", r.components)},
      {"vertex_connected_components", absl::StrFormat("%d", r.vertex_connected_components)},
      {"isolated_vertices", absl::StrFormat("%d", r.isolated_vertices)},
      {"non_manifold_edges", absl::StrFormat("%d", r.non_manifold_edges)},
      {"non_manifold_vertices", absl::StrFormat("%d", r.non_manifold_vertices)},
      {"degenerate_faces", absl::StrFormat("%d", r.degenerate_faces)},
      {"flipped_faces", absl::StrFormat("%d", r.flipped_faces)},
      {"orientation_cuts", absl::StrFormat("%d", r.orientation_cuts)},
      {"saddle_vertices", absl::StrFormat("%d", r.saddle_vertices)},
      {"boundary_vertices", absl::StrFormat("%d", r.boundary_vertices)},
      {"internal_vertices", absl::StrFormat("%d", v.internal_vertices)},
      {"mean_edge_length", absl::StrFormat("%.17g", v.mean_edge_length)},
      {"max_edge_length", absl::StrFormat("%.17g", v.max_edge_length)},
      {"bbox_min",
       absl::StrFormat("%.17g %.17g %.17g", v.bbox_min[0], v.bbox_min[1], v.bbox_min[2])},
      {"bbox_max",
       absl::StrFormat("%.17g %.17g %.17g", v.bbox_max[0], v.bbox_max[1], v.bbox_max[2])},
      {"bytes", absl::StrFormat("%d", v.bytes)},
      {"load_ms", absl::StrFormat("%.3f", v.load_ms)},
      {"build_ms", absl::StrFormat("%.3f", v.build_ms)},
  };
  // A DEM's map (strings are quoted in JSON).
  std::vector<std::pair<std::string, std::string>> dem_rows;
  if (v.dem != nullptr) {
    const terrain::DemInfo& d = *v.dem;
    dem_rows = {
        {"barrier_cells", absl::StrFormat("%d", d.barrier_cells)},
        {"barrier_faces", absl::StrFormat("%d", d.barrier_faces)},
        {"crs", d.file_crs_name},
        {"mesh_crs", d.mesh_crs_name},
        {"units", "m"},
        {"raster", absl::StrFormat("%d %d", d.raster_width, d.raster_height)},
        {"dem_step", absl::StrFormat("%d", d.step)},
        {"grid", absl::StrFormat("%d %d", d.grid_width, d.grid_height)},
        {"nodata_cells", absl::StrFormat("%d", d.nodata_cells)},
        {"vertical_unit", d.vertical_unit.empty() ? "m (assumed)" : d.vertical_unit},
        {"driver", d.driver},
    };
    if (d.z_tolerance > 0) {  // an adaptive TIN: how far it is from the cells (metres)
      dem_rows.push_back({"z_tolerance", absl::StrFormat("%.17g", d.z_tolerance)});
      dem_rows.push_back(
          {"max_vertical_deviation", absl::StrFormat("%.17g", d.max_vertical_deviation)});
      dem_rows.push_back(
          {"rms_vertical_deviation", absl::StrFormat("%.17g", d.rms_vertical_deviation)});
    }
  }
  std::string out;
  if (!json) {
    for (const auto& [k, value] : rows) absl::StrAppend(&out, k, ": ", value, "\n");
    for (const auto& [k, value] : dem_rows) absl::StrAppend(&out, k, ": ", value, "\n");
    return out;
  }
  out = "{";
  for (size_t i = 0; i < rows.size(); ++i) {
    // A bounding-box corner is an array of three numbers in JSON.
    const bool triple = rows[i].first.rfind("bbox_", 0) == 0;
    out += absl::StrFormat(
        "%s\"%s\": %s%s%s", i ? ", " : "", rows[i].first, triple ? "[" : "",
        triple ? absl::StrJoin(absl::StrSplit(rows[i].second, ' '), ", ") : rows[i].second,
        triple ? "]" : "");
  }
  for (const auto& [k, value] : dem_rows) {
    const bool pair = k == "raster" || k == "grid";
    const bool number = k == "dem_step" || k == "nodata_cells" || k == "barrier_cells" ||
                        k == "barrier_faces" || absl::StrContains(k, "_deviation") ||
                        k == "z_tolerance";
    out += absl::StrFormat(
        ", \"%s\": %s", k,
        pair     ? absl::StrCat("[", absl::StrJoin(absl::StrSplit(value, ' '), ", "), "]")
        : number ? value
                 : JsonString(value));
  }
  return out + "}\n";
}

// geodex info: its entry of `geodex --help`.
constexpr char kInfoHelp[] = R"(  info MESH [--format text|json] [--strict]
      One 'key: value' line per property (vertices, faces, boundary_loops, components,
      isolated_vertices, non_manifold_edges, non_manifold_vertices, degenerate_faces,
      saddle_vertices, bytes, ...). Reports on any readable mesh, valid or messy.
)";

int RunInfo(Backend& backend, const Args& args) {
  std::string error;
  if (!CheckKnown(args, {"format", "strict"}, &error) || !backend.Supports(args, &error)) {
    return Fail(kExitUsage, error);
  }
  if (args.positional.size() != 1)
    return Fail(kExitUsage, "usage: geodex info MESH [--format json]");
  const std::string format = args.options.count("format") ? args.options.at("format") : "text";
  if (format != "text" && format != "json") {
    return Fail(kExitUsage, "--format must be text or json");
  }
  MeshBuildOptions options;
  options.strict = args.options.count("strict") > 0;
  if (int code = OpenMesh(backend, args, args.positional[0], options)) return code;
  absl::StatusOr<InfoValues> info = backend.Info();
  if (!info.ok()) return FailQuery(info.status());
  std::fputs(FormatInfo(*info, format == "json").c_str(), stdout);
  return kExitOk;
}

// --stats members for the farthest snap of a p:X:Y:Z point (none without positions).
std::string SnapJson(const SnapReport& snap) {
  if (snap.point.empty()) return "";
  return absl::StrFormat("\"snap_max\": %.17g, \"snap_point\": \"%s\", ", snap.max_distance,
                         snap.point);
}

// The counters every --stats line carries, after the backend's context.
std::string StatsJson(const Backend& backend, const std::string& leading, const SolveStats& s,
                      const std::string& trailing) {
  return absl::StrFormat(
      "{%s%s\"windows_created\": %llu, \"windows_filtered_at_creation\": %llu, "
      "\"windows_filtered_at_pop\": %llu, \"windows_filtered_overfilter\": %llu, "
      "\"children_skipped_one_split\": %llu, \"windows_deleted_one_split\": %llu, "
      "\"windows_processed\": %llu, \"pseudo_sources\": %llu, \"pseudo_sources_full_fan\": %llu, "
      "\"pseudo_sources_shadow_only\": %llu, \"edge_relaxations\": %llu, \"max_level\": %u, "
      "\"peak_live_windows\": %llu, \"peak_bytes\": %llu, %s\"solve_ms\": %.3f}\n",
      leading, backend.StatsContext(), (unsigned long long)s.windows_created,
      (unsigned long long)s.windows_filtered_at_creation,
      (unsigned long long)s.windows_filtered_at_pop,
      (unsigned long long)s.windows_filtered_overfilter,
      (unsigned long long)s.children_skipped_one_split,
      (unsigned long long)s.windows_deleted_one_split, (unsigned long long)s.windows_processed,
      (unsigned long long)s.pseudo_sources, (unsigned long long)s.pseudo_sources_full_fan,
      (unsigned long long)s.pseudo_sources_shadow_only, (unsigned long long)s.edge_relaxations,
      s.max_level, (unsigned long long)s.peak_live_windows, (unsigned long long)s.peak_bytes,
      trailing, s.solve_ms);
}

std::string FormatDistances(const std::vector<double>& distances,
                            const std::vector<std::array<double, 3>>& directions) {
  std::string text;
  text.reserve(distances.size() * (directions.empty() ? 24 : 96));
  char buf[160];
  for (size_t i = 0; i < distances.size(); ++i) {
    const int n = directions.empty()
                      ? std::snprintf(buf, sizeof(buf), "%.17g\n", distances[i])
                      : std::snprintf(buf, sizeof(buf), "%.17g\t%.17g %.17g %.17g\n", distances[i],
                                      directions[i][0], directions[i][1], directions[i][2]);
    text.append(buf, n);
  }
  return text;
}

// How a travel-cost answer says what it is (seconds, approximate, its bound), as the geometry
// commands say they are approximate: a first comment line of text output, leading members of a
// JSON object. Both "" without a travel cost.
// A slope-dependent speed has no proven bound: the header says so and JSON's "bound" is false.
std::string TravelTextHeader(const GeodesicOptions& options) {
  if (!options.travel.has_value()) return "";
  const TravelCost& t = *options.travel;
  if (TravelIsExact(t)) {
    return absl::StrFormat("# travel time in seconds at %g km/h on friction 1; exact\n",
                           t.speed_kmh);
  }
  if (!IsDirectional(t)) {
    return absl::StrFormat(
        "# travel time in seconds at %g km/h on friction 1; approximate: at most (1 + %g) x the "
        "least time\n",
        t.speed_kmh, TravelEpsilon(t));
  }
  return absl::StrFormat(
      "# travel time in seconds %s, %s; approximate (epsilon %g, no proven bound)\n",
      t.inbound ? "to reach the sources" : "from the sources",
      t.speed_model == SpeedModel::kTobler ? "Tobler's hiking function" : "speed table",
      TravelEpsilon(t));
}
std::string TravelJsonMembers(const GeodesicOptions& options) {
  if (!options.travel.has_value()) return "";
  const TravelCost& t = *options.travel;
  // Exact answers (a constant speed, one weight: the exact engine) say so, with epsilon 0.
  const bool exact = TravelIsExact(t);
  return absl::StrFormat(
      "\"unit\": \"s\", \"approximate\": %s, \"exact\": %s, \"epsilon\": %s, \"bound\": %s, "
      "\"speed\": \"%s\", \"inbound\": %s, ",
      exact ? "false" : "true", exact ? "true" : "false", JsonNumber(StatedTravelEpsilon(t)),
      IsDirectional(t) ? "false" : "true", SpeedModelName(t.speed_model),
      t.inbound ? "true" : "false");
}

// `distances --at`: one line per point, "POINT<TAB>estimate D<TAB>exact D<TAB>source I" (I = -1
// when unreachable) and with --directions "<TAB>direction X Y Z", or {"points": [{"point": SPEC,
// "estimate": e, "exact": d, "source": i, "direction": [x, y, z] | null}, ...]}.
// With a travel cost: "POINT<TAB>time_s T<TAB>source I" and {"unit": "s", ..., "points":
// [{"point": SPEC, "time_s": t, "source": i}, ...]} (no unfolding estimate: it is geometry).
std::string FormatAt(const std::vector<SurfacePoint>& points, const AtValues& v, bool json,
                     const GeodesicOptions& options) {
  const bool travel = options.travel.has_value();
  std::string text =
      json ? "{" + TravelJsonMembers(options) + "\"points\": [" : TravelTextHeader(options);
  if (travel) {
    for (size_t i = 0; i < points.size(); ++i) {
      const uint32_t source = v.exact.source[i];
      text += json ? absl::StrFormat("%s{\"point\": \"%s\", \"time_s\": %s, \"source\": %s}",
                                     i ? ", " : "", SurfacePointToString(points[i]),
                                     JsonNumber(v.exact.distance[i]),
                                     source == kNoIndex ? "null" : absl::StrCat(source))
                   : absl::StrFormat("%s\ttime_s %.17g\tsource %d\n",
                                     SurfacePointToString(points[i]), v.exact.distance[i],
                                     source == kNoIndex ? int64_t{-1} : int64_t{source});
    }
    return json ? text + "]}\n" : text;
  }
  const std::vector<std::array<double, 3>>& direction = v.exact.direction;
  for (size_t i = 0; i < points.size(); ++i) {
    const uint32_t source = v.exact.source[i];
    if (json) {
      text += absl::StrFormat(
          "%s{\"point\": \"%s\", \"estimate\": %s, \"exact\": %s, \"source\": %s", i ? ", " : "",
          SurfacePointToString(points[i]), JsonNumber(v.estimate[i]),
          JsonNumber(v.exact.distance[i]), source == kNoIndex ? "null" : absl::StrCat(source));
      if (!direction.empty()) {
        absl::StrAppend(&text, ", \"direction\": ",
                        std::isnan(direction[i][0]) ? "null" : JsonXyz(direction[i]));
      }
      text += "}";
    } else {
      text += absl::StrFormat("%s\testimate %.17g\texact %.17g\tsource %d",
                              SurfacePointToString(points[i]), v.estimate[i], v.exact.distance[i],
                              source == kNoIndex ? int64_t{-1} : int64_t{source});
      if (!direction.empty()) {
        absl::StrAppend(&text, absl::StrFormat("\tdirection %.17g %.17g %.17g", direction[i][0],
                                               direction[i][1], direction[i][2]));
      }
      text += "\n";
    }
  }
  return json ? text + "]}\n" : text;
}

std::string FormatDistancesJson(const std::vector<double>& distances,
                                const std::vector<std::array<double, 3>>& directions) {
  std::string text = "{\"distances\": [";
  text.reserve(distances.size() * (directions.empty() ? 24 : 96));
  for (size_t i = 0; i < distances.size(); ++i) {
    if (i) text += ", ";
    text += JsonNumber(distances[i]);
  }
  if (!directions.empty()) {
    text += "], \"directions\": [";
    for (size_t i = 0; i < directions.size(); ++i) {
      if (i) text += ", ";
      text += std::isnan(directions[i][0]) ? "null" : JsonXyz(directions[i]);
    }
  }
  return text + "]}\n";
}

// geodex distances: its entry of `geodex --help`.
constexpr char kDistancesHelp[] =
    R"(  distances MESH --sources SPEC [--method exact|ich|dijkstra] [--lambda L] [--lambda-scale max|mean]
                 [--max-distance D] [--max-windows N] [--stats] [--output FILE] [--format json]
                 [--directions] [--labels-output FILE.tif]
      One distance per vertex in the file's vertex order (%.17g; 'inf' if unreachable).
      On a DEM, --output FILE.tif (.asc, .nc) writes float32 distances aligned with the DEM's
      grid (same geotransform and CRS; -1, the nodata, where there is no surface, -2 where it
      is unreachable) and --labels-output FILE.tif the nearest source's index (int32, the
      same -1 and -2). docs/gis-files.md lists the formats.
      --stats prints one JSON object with counters and times (*_ms) on stderr.
      --no-filter / --no-one-split switch off Lemma 2 / Lemma 1 (slower; same answer).
      --at SPEC: instead, one line per surface point: its unfolding estimate (paper section 4)
      and its exact distance ('POINT<TAB>estimate D<TAB>exact D<TAB>source I').
      --directions: also the geodesic direction field, 'D<TAB>X Y Z' per vertex: the unit
      tangent of the vertex's shortest path towards its nearest source (0 0 0 at a source,
      nan where unreachable), what a vector-field planner follows. With --at, each point's own
      direction (exact, its path's first step), '<TAB>direction X Y Z' after its line: where a
      robot standing there heads.
)";

int RunDistances(Backend& backend, const Args& args) {
  std::string error;
  bool json = false;
  if (!CheckKnown(args,
                  {"sources", "method", "lambda", "lambda-scale", "max-distance", "max-windows",
                   "stats", "output", "no-filter", "no-one-split", "at", "max-snap", "format",
                   "directions", "labels-output"},
                  &error) ||
      !GetFormat(args, &json, &error) || !backend.Supports(args, &error)) {
    return Fail(kExitUsage, error);
  }
  if (args.positional.size() != 1 || !args.options.count("sources")) {
    return Fail(kExitUsage, "usage: geodex distances MESH --sources SPEC [options]");
  }
  // The field asked whole; its sources are filled in once the mesh is open.
  FieldQuery query;
  const std::string method = args.options.count("method") ? args.options.at("method") : "exact";
  if (method == "exact") {
    query.options.method = Method::kExact;
  } else if (method == "ich") {
    query.options.method = Method::kIch;
  } else if (method == "dijkstra") {
    query.options.method = Method::kDijkstra;
  } else {
    return Fail(kExitUsage, "--method must be exact, ich or dijkstra");
  }
  if (!GetSolverFlags(args, &query.options, &error)) return Fail(kExitUsage, error);
  query.directions = args.options.count("directions") > 0;
  if (query.directions && args.options.count("at") && IsVectorPath(args)) {
    return Fail(kExitUsage, "--directions: not in GeoJSON (print them, or --format json)");
  }
  query.options.use_filter = !args.options.count("no-filter");
  query.options.use_one_angle_one_split = !args.options.count("no-one-split");
  absl::StatusOr<std::vector<SurfacePoint>> parsed =
      ParseSpec(nullptr, "sources", args.options.at("sources"));
  if (!parsed.ok()) return Fail(kExitUsage, std::string(parsed.status().message()));
  // Rasters (GeoTIFF, aligned with the DEM's grid): the distances with --output X.tif, the
  // nearest source's index with --labels-output X.tif.
  auto is_raster = [](const std::string& path) {
    const terrain::GisFormat* format = terrain::GisFormatOf(path);
    return format != nullptr && format->kind == terrain::GisFileKind::kRaster;
  };
  const std::string output = args.options.count("output") ? args.options.at("output") : "";
  const std::string labels_output =
      args.options.count("labels-output") ? args.options.at("labels-output") : "";
  const bool raster = is_raster(output);
  if (terrain::IsOtherGisExtension(output)) {
    return Fail(kExitUsage,
                absl::StrCat("--output ", output, ": not a format geodex writes; rasters: ",
                             terrain::GisExtensions(terrain::GisFileKind::kRaster),
                             "; vectors (with --at): ",
                             terrain::GisExtensions(terrain::GisFileKind::kVector),
                             "; text: .txt (or any name no GIS format uses)"));
  }
  if (!labels_output.empty() && !is_raster(labels_output)) {
    return Fail(kExitUsage,
                absl::StrCat("--labels-output: a raster is expected (",
                             terrain::GisExtensions(terrain::GisFileKind::kRaster), ")"));
  }
  if ((raster && (args.options.count("at") || query.directions || json)) ||
      (!labels_output.empty() && args.options.count("at"))) {
    return Fail(kExitUsage,
                "--output X.tif (a raster) and --labels-output: per-vertex values only (a "
                "raster has no --at points, --directions or JSON)");
  }
  if (IsVectorPath(args) && !args.options.count("at")) {
    return Fail(kExitUsage,
                "--output X.geojson (a vector file): distances in a vector file are per point: use "
                "--at SPEC (or --output X.tif for a raster)");
  }
  if (int code = OpenMesh(backend, args, args.positional[0], MeshBuildOptions{})) return code;
  if (int code = ResolveTravelWeights(backend, args, &query.options)) return code;
  const terrain::Dem* dem = backend.Terrain();
  if ((raster || !labels_output.empty()) && dem == nullptr) {
    return Fail(kExitUsage, absl::StrCat(raster ? "--output " : "--labels-output ",
                                         raster ? output : labels_output,
                                         ": a raster needs a DEM as MESH (a raster such as .tif)"));
  }
  std::vector<SurfacePoint> sources, at;
  SnapReport snap;
  if (absl::Status s = ResolveOption(backend, args, "sources", &sources, &snap); !s.ok()) {
    return FailQuery(s);
  }
  if (args.options.count("at")) {
    if (absl::Status s = ResolveOption(backend, args, "at", &at, &snap); !s.ok()) {
      return FailQuery(s);
    }
  }
  std::string text;
  SolveStats stats;
  const auto t_solve = std::chrono::steady_clock::now();
  if (args.options.count("at")) {
    // Surface points: the unfolding estimate and the exact value, one line each.
    absl::StatusOr<AtValues> values =
        backend.DistancesAt({sources, at, query.options, query.directions});
    if (!values.ok()) return FailQuery(values.status());
    text = FormatAt(at, *values, json, query.options);
    if (IsVectorPath(args)) {  // Point features with the exact distance and the nearest source
      absl::StatusOr<const MeshData*> data = backend.Geometry();
      if (!data.ok()) return FailQuery(data.status());
      // Each feature names its point as the user wrote it (g:, ll:, a vertex...), and where it is.
      const std::vector<std::string> written = absl::StrSplit(args.options.at("at"), ',');
      std::vector<terrain::PointValue> points;
      for (size_t i = 0; i < at.size(); ++i) {
        const uint32_t source = values->exact.source[i];
        points.push_back({PositionOf(**data, at[i]),
                          written.size() == at.size() ? written[i] : SurfacePointToString(at[i]),
                          SurfacePointToString(at[i]), values->exact.distance[i],
                          source == kNoIndex ? -1 : int64_t{source}});
      }
      if (int code = WriteVectorOutput(
              backend, args,
              terrain::PointFeatures(
                  points, query.options.travel.has_value() ? &*query.options.travel : nullptr),
              &query.options);
          code != kExitOk) {
        return code;
      }
      text.clear();
    }
  } else {
    query.sources = sources;
    absl::StatusOr<const DistanceField*> field = backend.Field(query);
    if (!field.ok()) return FailQuery(field.status());
    stats = (*field)->stats;
    if (stats.solve_ms == 0) stats.solve_ms = MsSince(t_solve);
    absl::Status written = absl::OkStatus();
    if (raster || !labels_output.empty()) {  // the used grid's cells (on a TIN: sampled)
      absl::StatusOr<terrain::CellValues> cells =
          terrain::SampleCells(*dem, **field, nullptr, &query.options);
      if (!cells.ok()) return FailQuery(cells.status());
      cells->provenance = terrain::MakeProvenance(args.command_line, &query.options);
      if (raster) written = dem->WriteDistanceRaster(output, *cells);
      if (written.ok() && !labels_output.empty()) {
        written = dem->WriteLabelRaster(labels_output, *cells);
      }
    }
    if (!written.ok()) return Fail(kExitUsage, std::string(written.message()));
    if (!raster) {
      text = json ? FormatDistancesJson((*field)->distance, (*field)->direction)
                  : TravelTextHeader(query.options) +
                        FormatDistances((*field)->distance, (*field)->direction);
      if (json && query.options.travel.has_value()) {  // {"unit": "s", ..., "time_s": [...]}
        text = "{" + TravelJsonMembers(query.options) + "\"time_s\"" + text.substr(12);
      }
    }
  }
  if (stats.solve_ms == 0) stats.solve_ms = MsSince(t_solve);
  const auto t_out = std::chrono::steady_clock::now();
  if (!raster && !IsVectorPath(args)) {
    if (int code = WriteOutput(args, text); code != kExitOk) return code;
  }
  if (args.options.count("stats")) {
    const std::string leading = absl::StrFormat("\"method\": \"%s\", \"sources\": %d, %s", method,
                                                sources.size(), SnapJson(snap));
    const std::string trailing = absl::StrFormat("\"output_ms\": %.3f, ", MsSince(t_out));
    std::fputs(StatsJson(backend, leading, stats, trailing).c_str(), stderr);
  }
  return kExitOk;
}

std::string SimplexText(const SurfacePoint& p) {
  switch (p.kind) {
    case SurfacePoint::Kind::kVertex:
      return absl::StrFormat("v %d", p.vertex);
    case SurfacePoint::Kind::kEdge:
      return absl::StrFormat("e %d %d %.17g", p.edge_from, p.edge_to, p.t);
    case SurfacePoint::Kind::kFace:
      return absl::StrFormat("f %d %.17g %.17g %.17g", p.face, p.bary[0], p.bary[1], p.bary[2]);
    case SurfacePoint::Kind::kPosition:
      break;
  }
  return "?";
}

// With a travel cost, line 1 is the time in seconds after the header line, and JSON has "time_s"
// beside the path's "length" in metres.
std::string FormatPath(const PathQueryResult& result, const GeodesicOptions& options) {
  std::string text = TravelTextHeader(options) + absl::StrFormat("%.17g\n", result.distance);
  for (const PathPoint& p : result.path.points) {
    text += absl::StrFormat("%.17g %.17g %.17g %s\n", p.position[0], p.position[1], p.position[2],
                            SimplexText(p.where));
  }
  return text;
}

std::string FormatPathJson(const PathQueryResult& result, const GeodesicOptions& options) {
  std::string text =
      options.travel.has_value()
          ? absl::StrCat("{", TravelJsonMembers(options),
                         "\"time_s\": ", JsonNumber(result.distance),
                         ", \"length_m\": ", JsonNumber(result.path.length),
                         ", \"length\": ", JsonNumber(result.path.length), ", \"points\": [")
          : absl::StrCat("{\"length_m\": ", JsonNumber(result.distance),
                         ", \"length\": ", JsonNumber(result.distance), ", \"points\": [");
  for (size_t i = 0; i < result.path.points.size(); ++i) {
    text += (i ? ", " : "") + PathPointJson(result.path.points[i]);
  }
  return text + "]}\n";
}

// geodex path: its entry of `geodex --help`.
constexpr char kPathHelp[] =
    R"(  path MESH --from SPEC --to SPEC [--method astar|full] [--stats] [--lambda L]
       [--max-distance D] [--format json]
      The exact shortest path: line 1 its length; then one line per polyline point,
      'x y z' and the simplex it lies on ('v ID', 'e V1 V2 T' or 'f FACE B0 B1 B2').
      astar (default) uses the paper's section 5 heuristic and stops at the target.
      --lambda L (as for distances) trades exactness for speed; --max-distance D: a target
      farther than D is unreachable. Several --from points: the path from the nearest (named
      on stderr).
)";

int RunPath(Backend& backend, const Args& args) {
  std::string error;
  bool json = false;
  if (!CheckKnown(args,
                  {"from", "to", "method", "stats", "lambda", "lambda-scale", "max-distance",
                   "max-windows", "max-snap", "format", "output"},
                  &error) ||
      !GetFormat(args, &json, &error) || !backend.Supports(args, &error)) {
    return Fail(kExitUsage, error);
  }
  if (args.positional.size() != 1 || !args.options.count("from") || !args.options.count("to")) {
    return Fail(kExitUsage,
                "usage: geodex path MESH --from SPEC[,SPEC...] --to SPEC [--method astar|full]");
  }
  PathQueryOptions options;
  const std::string method = args.options.count("method") ? args.options.at("method") : "astar";
  if (method == "astar") {
    options.use_heuristic = true;
  } else if (method == "full") {
    options.full_field = true;
  } else {
    return Fail(kExitUsage, "--method must be astar or full");
  }
  if (!GetSolverFlags(args, &options.solver, &error)) return Fail(kExitUsage, error);
  if (int code = OpenMesh(backend, args, args.positional[0], MeshBuildOptions{})) return code;
  if (int code = ResolveTravelWeights(backend, args, &options.solver)) return code;
  SurfacePoint to;
  std::vector<SurfacePoint> froms;
  SnapReport snap;
  if (absl::Status s = ResolveOption(backend, args, "from", &froms, &snap); !s.ok())
    return FailQuery(s);
  if (absl::Status s = OnePoint(backend, args, "to", &to, &snap); !s.ok()) return FailQuery(s);
  // Several --from points: the path from the nearest (an exact distance at `to` from all of them
  // names it; distances are symmetric), said on stderr.
  size_t nearest = 0;
  if (froms.size() > 1) {
    absl::StatusOr<AtValues> at = backend.DistancesAt({froms, {to}, options.solver, false});
    if (!at.ok()) return FailQuery(at.status());
    if (std::isfinite(at->exact.distance[0]) && at->exact.source[0] < froms.size()) {
      nearest = at->exact.source[0];
      const std::vector<std::string> written = absl::StrSplit(args.options.at("from"), ',');
      std::fprintf(stderr, "geodex: --from: the nearest is point %zu (%s), %.17g away\n", nearest,
                   written.size() == froms.size() ? written[nearest].c_str()
                                                  : SurfacePointToString(froms[nearest]).c_str(),
                   at->exact.distance[0]);
    }
  }
  absl::StatusOr<PathQueryResult> result = backend.Path({froms[nearest], to, options});
  if (!result.ok()) return FailQuery(result.status());
  if (IsVectorPath(args)) {  // a 3D LineString with its length
    if (int code = WriteVectorOutput(
            backend, args,
            {terrain::PathFeature(
                result->path.points, result->path.length,
                options.solver.travel.has_value() ? result->distance : std::nan(""))},
            &options.solver);
        code != kExitOk) {
      return code;
    }
  } else {
    const std::string text =
        json ? FormatPathJson(*result, options.solver) : FormatPath(*result, options.solver);
    if (int code = WriteOutput(args, text); code != kExitOk) return code;
  }
  if (args.options.count("stats")) {
    const std::string leading = absl::StrFormat("\"method\": \"%s\", \"path_points\": %d, %s",
                                                method, result->path.points.size(), SnapJson(snap));
    std::fputs(StatsJson(backend, leading, result->stats, "").c_str(), stderr);
  }
  return kExitOk;
}

std::string FormatMatrix(const DistanceMatrix& m) {
  std::string text;
  for (size_t i = 0; i < m.rows; ++i) {
    for (size_t j = 0; j < m.cols; ++j) {
      text += absl::StrFormat(j ? "\t%.17g" : "%.17g", m.values[i * m.cols + j]);
    }
    text += "\n";
  }
  return text;
}

std::string FormatMatrixJson(const DistanceMatrix& m) {
  std::string text = absl::StrFormat("{\"rows\": %d, \"cols\": %d, \"values\": [", m.rows, m.cols);
  for (size_t i = 0; i < m.rows; ++i) {
    text += i ? ", [" : "[";
    for (size_t j = 0; j < m.cols; ++j) {
      text += (j ? ", " : "") + JsonNumber(m.values[i * m.cols + j]);
    }
    text += "]";
  }
  return text + "]}\n";
}

// geodex matrix: its entry of `geodex --help`.
constexpr char kMatrixHelp[] =
    R"(  matrix MESH --sources SPEC --targets SPEC [--stats] [--lambda L] [--max-distance D]
         [--k-nearest K] [--threads N] [--format json]
      Exact distances, one row per source, tab-separated. Rows run in parallel on every usable
      core (--threads N to limit). The same points as sources and targets give a symmetric
      matrix, each pair solved once. --max-distance D: entries beyond D are inf. --k-nearest K:
      per source only its K nearest targets are filled in, the rest inf. A progress bar shows
      on a terminal for calls longer than a second.
)";

int RunMatrix(Backend& backend, const Args& args) {
  std::string error;
  bool json = false;
  if (!CheckKnown(args,
                  {"sources", "targets", "stats", "lambda", "lambda-scale", "max-distance",
                   "max-windows", "k-nearest", "threads", "max-snap", "format"},
                  &error) ||
      !GetFormat(args, &json, &error) || !backend.Supports(args, &error)) {
    return Fail(kExitUsage, error);
  }
  if (args.positional.size() != 1 || !args.options.count("sources") ||
      !args.options.count("targets")) {
    return Fail(kExitUsage, "usage: geodex matrix MESH --sources SPEC --targets SPEC");
  }
  MatrixOptions options;
  uint64_t k_nearest = 0, threads = 0;
  if (!GetSolverFlags(args, &options.solver, &error) ||
      !GetUint(args, "k-nearest", &k_nearest, &error) ||
      !GetUint(args, "threads", &threads, &error)) {
    return Fail(kExitUsage, error);
  }
  if (k_nearest > UINT32_MAX) return Fail(kExitUsage, "--k-nearest is too large");
  if (threads > 1024) return Fail(kExitUsage, "--threads must be at most 1024");
  options.k_nearest = static_cast<uint32_t>(k_nearest);
  options.threads = static_cast<unsigned>(threads);
  RowProgress progress;
  options.on_row = [&progress](size_t done, size_t total) { progress.Update(done, total); };
  if (int code = OpenMesh(backend, args, args.positional[0], MeshBuildOptions{})) return code;
  if (int code = ResolveTravelWeights(backend, args, &options.solver)) return code;
  std::vector<SurfacePoint> sources, targets;
  SnapReport snap;
  if (absl::Status s = ResolveOption(backend, args, "sources", &sources, &snap); !s.ok()) {
    return FailQuery(s);
  }
  if (absl::Status s = ResolveOption(backend, args, "targets", &targets, &snap); !s.ok()) {
    return FailQuery(s);
  }
  absl::StatusOr<DistanceMatrix> m = backend.Matrix({sources, targets, options});
  progress.Finish();
  if (!m.ok()) return FailQuery(m.status());
  const std::string text =
      json ? "{" + TravelJsonMembers(options.solver) + FormatMatrixJson(*m).substr(1)
           : TravelTextHeader(options.solver) + FormatMatrix(*m);
  std::fwrite(text.data(), 1, text.size(), stdout);
  if (args.options.count("stats")) {
    const std::string leading =
        absl::StrFormat("\"rows\": %d, \"cols\": %d, \"threads\": %u, %s", m->rows, m->cols,
                        options.threads > 0 ? options.threads : UsableCores(), SnapJson(snap));
    std::fputs(StatsJson(backend, leading, m->stats, "").c_str(), stderr);
  }
  return kExitOk;
}

// geodex locate: its entry of `geodex --help`.
constexpr char kLocateHelp[] =
    R"(  locate MESH --points p:X:Y:Z,g:X:Y,ll:LON:LAT,... [--max-snap D] [--format text|json]
      The nearest surface point to each 3D position: 'QUERY<TAB>SPEC<TAB>x y z<TAB>snap D', D
      the distance it moved. --max-snap D refuses a position farther than D from the surface.
      On a DEM, map points (g:X:Y in its CRS, ll:LON:LAT) are dropped vertically onto it
      (snap 0); QUERY is the point as written.
)";

int RunLocate(Backend& backend, const Args& args) {
  std::string error;
  bool json = false;
  if (!CheckKnown(args, {"points", "max-snap", "format"}, &error) ||
      !GetFormat(args, &json, &error) || !backend.Supports(args, &error)) {
    return Fail(kExitUsage, error);
  }
  if (args.positional.size() != 1 || !args.options.count("points")) {
    return Fail(kExitUsage,
                "usage: geodex locate MESH --points p:X:Y:Z,g:X:Y,ll:LON:LAT,... [--max-snap D]");
  }
  double max_snap = std::numeric_limits<double>::infinity();
  if (!GetDouble(args, "max-snap", &max_snap, &error)) return Fail(kExitUsage, error);
  if (!(max_snap > 0)) return Fail(kExitUsage, "--max-snap must be positive");
  const std::vector<std::string> items = absl::StrSplit(args.options.at("points"), ',');
  auto is_map = [](const std::string& item) {
    return absl::StartsWith(item, "g:") || absl::StartsWith(item, "ll:");
  };
  // Positions are snapped (Locate); map points, checked here, are dropped once the mesh is open.
  std::vector<std::array<double, 3>> xyz;
  for (const std::string& item : items) {
    absl::StatusOr<std::vector<SurfacePoint>> p = ParseSpec(nullptr, "points", item);
    if (!p.ok()) return Fail(kExitUsage, std::string(p.status().message()));
    if (is_map(item)) continue;
    if (p->size() != 1 || p->front().kind != SurfacePoint::Kind::kPosition) {
      return Fail(
          kExitUsage,
          absl::StrFormat(
              "--points: %s is not a position (locate takes p:X:Y:Z, g:X:Y, ll:LON:LAT)", item));
    }
    xyz.push_back(p->front().position);
  }
  if (int code = OpenMesh(backend, args, args.positional[0], MeshBuildOptions{})) return code;
  std::vector<LocatedPoint> located;
  if (!xyz.empty()) {
    absl::StatusOr<std::vector<LocatedPoint>> snapped = backend.Locate(xyz);
    if (!snapped.ok()) return FailQuery(snapped.status());
    located = *std::move(snapped);
  }
  std::string text = json ? "{\"points\": [" : "";
  size_t next_position = 0;
  for (size_t i = 0; i < items.size(); ++i) {
    LocatedPoint at;
    if (is_map(items[i])) {
      absl::StatusOr<std::vector<SurfacePoint>> dropped = ParseSpec(&backend, "points", items[i]);
      if (!dropped.ok()) return FailQuery(dropped.status());
      absl::StatusOr<const MeshData*> data = backend.Geometry();
      if (!data.ok()) return FailQuery(data.status());
      at.point = dropped->front();
      at.position = PositionOf(**data, at.point);
      at.distance = 0;
    } else {
      const std::array<double, 3>& p = xyz[next_position];
      at = located[next_position++];
      if (absl::Status s = CheckSnapDistance(p, at, max_snap); !s.ok()) {
        return Fail(kExitUsage, absl::StrFormat("--points: %s", s.message()));
      }
    }
    const std::string& query = items[i];
    if (json) {
      text += absl::StrFormat(
          "%s{\"query\": \"%s\", \"point\": \"%s\", \"p\": %s, \"snap_distance\": %.17g}",
          i ? ", " : "", query, SurfacePointToString(at.point), JsonXyz(at.position), at.distance);
    } else {
      text += absl::StrFormat("%s\t%s\t%.17g %.17g %.17g\tsnap %.17g\n", query,
                              SurfacePointToString(at.point), at.position[0], at.position[1],
                              at.position[2], at.distance);
    }
  }
  if (json) text += "]}\n";
  std::fwrite(text.data(), 1, text.size(), stdout);
  return kExitOk;
}

}  // namespace

const std::vector<Command>& QueryCommands() {
  static const std::vector<Command>* commands = new std::vector<Command>{
      {"info", kInfoHelp, {"strict"}, RunInfo},
      {"distances",
       kDistancesHelp,
       {"stats", "no-filter", "no-one-split", "directions", "inbound"},
       RunDistances},
      {"path", kPathHelp, {"stats", "inbound"}, RunPath},
      {"matrix", kMatrixHelp, {"stats", "inbound"}, RunMatrix},
      {"locate", kLocateHelp, {}, RunLocate},
      IsolinesCommand(),
      VoronoiCommand(),
      DelaunayCommand(),
      RenderCommand(),
  };
  return *commands;
}

}  // namespace geodex::cli
