// What every geodex command shares before it runs: argument parsing (repeated flags, point files),
// point SPECs resolved against a backend (map points dropped onto a DEM, snaps checked and said),
// query errors in the user's words and exit codes, travel weights from files, GIS output, and
// how MESH is read (cli_backend.h, cli_commands.h declare them).
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
#include "cli_commands.h"
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

bool ParseArgs(int argc, char** argv, int first, const std::vector<std::string>& boolean_flags,
               Args* out, std::string* error) {
  out->command_line = "geodex";
  for (int i = std::max(first - 1, 1); i < argc; ++i)
    absl::StrAppend(&out->command_line, " ", argv[i]);
  const std::set<std::string> booleans(boolean_flags.begin(), boolean_flags.end());
  const std::set<std::string> repeatable(std::begin(kRepeatableFlags), std::end(kRepeatableFlags));
  auto add = [&](const std::string& key, const std::string& value) {
    if (!out->options.count(key)) {
      out->options[key] = value;
    } else if (!repeatable.count(key)) {
      *error = absl::StrFormat(
          "option --%s given twice: it takes one value (only %s add up when repeated)", key,
          absl::StrJoin(repeatable, ", ",
                        [](std::string* o, const std::string& f) { absl::StrAppend(o, "--", f); }));
      return false;
    } else if (key == "sources" || key == "targets") {
      // A SPEC list: the repeats are more points of the same list.
      absl::StrAppend(&out->options[key], ",", value);
    }
    if (repeatable.count(key)) out->lists[key].push_back(value);
    return true;
  };
  for (int i = first; i < argc; ++i) {
    std::string a = argv[i];
    if (a.rfind("--", 0) != 0 || a == "--") {
      out->positional.push_back(a);
      continue;
    }
    a = a.substr(2);
    const size_t eq = a.find('=');
    bool ok = true;
    if (eq != std::string::npos) {
      ok = add(a.substr(0, eq), a.substr(eq + 1));
    } else if (booleans.count(a)) {
      ok = add(a, "");
    } else if (i + 1 < argc) {
      ok = add(a, argv[++i]);
    } else {
      *error = absl::StrFormat("option --%s needs a value", a);
      return false;
    }
    if (!ok) return false;
  }
  return true;
}

std::vector<std::string> Args::All(const std::string& key) const {
  if (auto it = lists.find(key); it != lists.end()) return it->second;
  if (auto it = options.find(key); it != options.end()) return {it->second};
  return {};
}

absl::Status ResolvePoints(Backend& backend, const Args& args, const std::string& option,
                           std::vector<SurfacePoint>* points, SnapReport* report) {
  double max_snap = std::numeric_limits<double>::infinity();
  std::string error;
  if (!GetDouble(args, "max-snap", &max_snap, &error)) return absl::InvalidArgumentError(error);
  if (!(max_snap > 0)) return absl::InvalidArgumentError("--max-snap must be positive");
  std::vector<std::array<double, 3>> xyz;
  for (const SurfacePoint& p : *points) {
    if (p.kind == SurfacePoint::Kind::kPosition) xyz.push_back(p.position);
  }
  if (!xyz.empty()) {
    absl::StatusOr<std::vector<LocatedPoint>> located = backend.Locate(xyz);
    if (!located.ok()) {
      return absl::Status(located.status().code(),
                          absl::StrFormat("--%s: %s", option, located.status().message()));
    }
    double warn_above = std::numeric_limits<double>::infinity();
    size_t k = 0;
    for (SurfacePoint& p : *points) {
      if (p.kind != SurfacePoint::Kind::kPosition) continue;
      const LocatedPoint& at = (*located)[k++];
      if (absl::Status s = CheckSnapDistance(p.position, at, max_snap); !s.ok()) {
        return absl::InvalidArgumentError(absl::StrFormat("--%s: %s", option, s.message()));
      }
      if (at.distance > 0 && !std::isfinite(warn_above)) {  // the mesh's size, on first need
        absl::StatusOr<InfoValues> info = backend.Info();
        if (!info.ok()) return info.status();
        double d2 = 0;
        for (int c = 0; c < 3; ++c) {
          d2 += (info->bbox_max[c] - info->bbox_min[c]) * (info->bbox_max[c] - info->bbox_min[c]);
        }
        warn_above = kSnapWarnRel * std::sqrt(d2);
      }
      if (at.distance > warn_above) {
        std::fprintf(
            stderr,
            "geodex: warning: --%s: %s is %.6g from the surface; snapped to %s (--max-snap "
            "D refuses such points)\n",
            option.c_str(), SurfacePointToString(p).c_str(), at.distance,
            SurfacePointToString(at.point).c_str());
      }
      if (report != nullptr && at.distance >= report->max_distance) {
        report->max_distance = at.distance;
        report->point = SurfacePointToString(p);
      }
      p = at.point;
    }
  }
  return backend.Check(option, *points);
}

// The points written as map coordinates, by the face point each was dropped to, so that messages
// quote them as the user wrote them (`ll:-84.3:36.6`, not `f:222302:0.5:...`). One CLI run, one
// table.
absl::flat_hash_map<std::string, std::string>& WrittenPoints() {
  static auto* written = new absl::flat_hash_map<std::string, std::string>();
  return *written;
}

// Map points read from --sources-file / --targets-file, by their SPEC item: the feature that gave
// each, for messages.
absl::flat_hash_map<std::string, std::string>& FilePointNames() {
  static auto* names = new absl::flat_hash_map<std::string, std::string>();
  return *names;
}

absl::Status ExpandPointFiles(Args* args) {
  for (const auto& [flag, option] :
       {std::pair<std::string, std::string>{"sources-file", "sources"},
        std::pair<std::string, std::string>{"targets-file", "targets"}}) {
    for (const std::string& path : args->All(flag)) {
      const std::string name = absl::StrCat("--", flag, " ", path);
      absl::StatusOr<std::vector<terrain::FilePoint>> points = terrain::ReadPointsFile(path, name);
      if (!points.ok()) return points.status();
      std::string spec = args->options.count(option) ? args->options.at(option) : "";
      for (const terrain::FilePoint& p : *points) {
        absl::StatusOr<std::string> item = terrain::FilePointSpec(p);
        if (!item.ok())
          return absl::InvalidArgumentError(absl::StrCat(p.name, ": ", item.status().message()));
        absl::StrAppend(&spec, spec.empty() ? "" : ",", *item);
        FilePointNames()[*item] = p.name;
      }
      args->options[option] = spec;
    }
  }
  return absl::OkStatus();
}

std::string InWrittenTerms(std::string message) {
  for (const auto& [dropped, written] : WrittenPoints()) {
    message = absl::StrReplaceAll(message, {{dropped, written}});
  }
  return message;
}

// Map coordinates in a SPEC list (`g:X:Y` in the DEM's CRS, `ll:LON:LAT` in WGS 84) dropped
// vertically onto the DEM, each rewritten as the face point it lands on (lossless, %.17g).
// Without a backend (before the mesh is open) only their syntax is checked (they become "0").
absl::StatusOr<std::string> DropMapPoints(const Backend* backend, const std::string& spec) {
  std::vector<std::string> items = absl::StrSplit(spec, ',');
  for (std::string& item : items) {
    const bool native = absl::StartsWith(item, "g:"), lonlat = absl::StartsWith(item, "ll:");
    if (!native && !lonlat) continue;
    std::vector<std::string> parts = absl::StrSplit(item, ':');
    double a = 0, b = 0;
    if (parts.size() != 3 || !absl::SimpleAtod(parts[1], &a) || !absl::SimpleAtod(parts[2], &b) ||
        !std::isfinite(a) || !std::isfinite(b)) {
      return absl::InvalidArgumentError(
          absl::StrFormat("bad point '%s' (expected %s)", item, native ? "g:X:Y" : "ll:LON:LAT"));
    }
    if (backend == nullptr) {
      item = "0";
      continue;
    }
    const terrain::Dem* dem = backend->Terrain();
    if (dem == nullptr) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "point %s: map coordinates need a DEM as MESH (a raster such as .tif)", item));
    }
    absl::StatusOr<SurfacePoint> p = native ? dem->DropMapPoint(a, b) : dem->DropLonLat(a, b);
    if (!p.ok()) {
      auto from_file = FilePointNames().find(item);
      return absl::InvalidArgumentError(absl::StrCat(
          "point ", from_file != FilePointNames().end() ? from_file->second + " at " : "",
          p.status().message()));
    }
    auto from_file = FilePointNames().find(item);
    const std::string written = from_file != FilePointNames().end() ? from_file->second : item;
    item = SurfacePointToString(*p);
    WrittenPoints()[item] = written;
  }
  return absl::StrJoin(items, ",");
}

absl::StatusOr<std::vector<SurfacePoint>> ParseSpec(const Backend* backend,
                                                    const std::string& option,
                                                    const std::string& spec) {
  absl::StatusOr<std::string> dropped = DropMapPoints(backend, spec);
  if (!dropped.ok()) {
    return absl::InvalidArgumentError(
        absl::StrFormat("--%s: %s", option, dropped.status().message()));
  }
  absl::StatusOr<std::vector<SurfacePoint>> p = ParseSurfacePoints(*dropped);
  if (!p.ok()) {
    return absl::InvalidArgumentError(absl::StrFormat("--%s: %s", option, p.status().message()));
  }
  return p;
}

absl::Status ResolveOption(Backend& backend, const Args& args, const std::string& option,
                           std::vector<SurfacePoint>* points, SnapReport* report) {
  absl::StatusOr<std::vector<SurfacePoint>> p =
      ParseSpec(&backend, option, args.options.at(option));
  if (!p.ok()) return p.status();
  if (absl::Status s = ResolvePoints(backend, args, option, &*p, report); !s.ok()) return s;
  *points = *std::move(p);
  return absl::OkStatus();
}

int QueryExitCode(const absl::Status& status) {
  switch (status.code()) {
    case absl::StatusCode::kInvalidArgument:
    case absl::StatusCode::kOutOfRange:
      return kExitUsage;
    case absl::StatusCode::kNotFound:
    case absl::StatusCode::kDataLoss:
      return kExitInput;
    default:
      return kExitSolveFailed;
  }
}

int FailQuery(const absl::Status& status) {
  // A core limit the CLI set from a flag: name it (geodexd names its own server flags).
  const std::optional<Limit> exceeded = ExceededLimit(status);
  const std::string limit = exceeded == Limit::kSteinerPoints ? " (--max-steiner-points)"
                            : exceeded == Limit::kWindows     ? " (--max-windows)"
                                                              : "";
  // A core option error names its option as data: say the flag.
  return Fail(QueryExitCode(status), InWrittenTerms(InFlagTerms(status)) + limit);
}

int ResolveTravelWeights(Backend& backend, const Args& args, GeodesicOptions* options) {
  if (!options->travel.has_value()) return 0;
  if (args.options.count("face-weights")) {
    const std::string& path = args.options.at("face-weights");
    std::ifstream in(path);
    if (!in) {
      return Fail(kExitInput,
                  absl::StrCat("--face-weights ", path, ": cannot open: ", std::strerror(errno)));
    }
    auto weights = std::make_shared<std::vector<double>>();
    std::string line;
    for (size_t n = 1; std::getline(in, line); ++n) {
      const absl::string_view text = absl::StripAsciiWhitespace(line);
      if (text.empty() || text[0] == '#') continue;
      double w = 0;
      if (!absl::SimpleAtod(text, &w)) {
        return Fail(kExitUsage, absl::StrFormat("--face-weights %s: line %d: '%s' is not a number",
                                                path, n, text));
      }
      weights->push_back(w);
    }
    options->travel->face_weight = std::move(weights);  // count and values: core's check
  } else if (args.options.count("friction")) {
    const std::string path = absl::StrJoin(args.All("friction"), ", --friction ");
    const terrain::Dem* dem = backend.Terrain();
    if (dem == nullptr) {
      return Fail(kExitUsage, absl::StrCat("--friction ", path,
                                           ": friction maps need a DEM as MESH (on another mesh, "
                                           "--face-weights FILE gives one weight per face)"));
    }
    if (!dem->face_friction().empty()) {  // --friction-boundaries exact: valued as cut in
      options->travel->face_weight = std::make_shared<std::vector<double>>(dem->face_friction());
      return 0;
    }
    absl::StatusOr<const MeshData*> data = backend.Geometry();
    if (!data.ok()) return FailQuery(data.status());
    absl::StatusOr<std::vector<double>> weights =
        terrain::ReadFrictionFiles(**data, args.All("friction"), dem->info());
    if (!weights.ok()) return FailQuery(weights.status());
    options->travel->face_weight = std::make_shared<std::vector<double>>(*std::move(weights));
  }
  return 0;
}

bool IsVectorPath(const Args& args) {
  if (!args.options.count("output")) return false;
  const terrain::GisFormat* format = terrain::GisFormatOf(args.options.at("output"));
  return format != nullptr && format->kind == terrain::GisFileKind::kVector;
}

int WriteVectorOutput(const Backend& backend, const Args& args,
                      const std::vector<terrain::GeoFeature>& features,
                      const GeodesicOptions* options) {
  const std::string& path = args.options.at("output");
  const terrain::Dem* dem = backend.Terrain();
  if (dem == nullptr) {
    return Fail(kExitUsage, absl::StrCat("--output ", path,
                                         ": a GIS file needs a DEM as MESH (map coordinates)"));
  }
  // --crs was checked with the mesh's other reading options (OpenMesh).
  const bool native = args.options.count("crs") && args.options.at("crs") == "native";
  const terrain::Provenance provenance = terrain::MakeProvenance(args.command_line, options);
  absl::Status written = terrain::WriteVectorFile(dem->info(), features, path, native, &provenance);
  if (!written.ok()) return Fail(kExitUsage, std::string(written.message()));
  return kExitOk;
}

absl::StatusOr<terrain::DemOptions> MeshReadOptions(const Args& args, const std::string& mesh) {
  terrain::DemOptions dem;
  uint64_t step = 1;
  std::string error;
  if (!GetUint(args, "dem-step", &step, &error)) return absl::InvalidArgumentError(error);
  dem.step = static_cast<uint32_t>(std::min<uint64_t>(step, uint64_t{1} << 31));  // (checked below)
  if (!GetDouble(args, "barrier-below", &dem.barrier_below, &error)) {
    return absl::InvalidArgumentError(error);
  }
  dem.barrier_files = args.All("barrier");
  if (!GetDouble(args, "barrier-width", &dem.barrier_width, &error))
    return absl::InvalidArgumentError(error);
  if (args.options.count("barrier-width") && dem.barrier_files.empty()) {
    return absl::InvalidArgumentError(
        "--barrier-width goes with --barrier (the width of its lines and points)");
  }
  if (!GetDouble(args, "z-tolerance", &dem.z_tolerance, &error)) {
    return absl::InvalidArgumentError(error);
  }
  if (args.options.count("z-tolerance") && !terrain::IsDemPath(mesh)) {
    return absl::InvalidArgumentError(
        absl::StrCat("--z-tolerance: ", mesh, " is not a DEM (a raster such as .tif)"));
  }
  if (args.options.count("dem-step") && !terrain::IsDemPath(mesh)) {
    return absl::InvalidArgumentError(
        absl::StrCat("--dem-step: ", mesh, " is not a DEM (a raster such as .tif)"));
  }
  if (args.options.count("crs") && args.options.at("crs") != "wgs84" &&
      args.options.at("crs") != "native") {
    return absl::InvalidArgumentError("--crs must be wgs84 or native");
  }
  // --friction-boundaries exact: friction polygons' outlines are cut into the DEM's mesh as it is
  // read, so that ResolveTravelWeights, reading the same file on it, gives exact region
  // boundaries. Not the default: slivers the outlines make multiply the bounded engine's Steiner
  // points (docs/travel.md has the measured cost).
  if (args.options.count("friction-boundaries")) {
    const std::string& how = args.options.at("friction-boundaries");
    if (how != "exact" && how != "faces") {
      return absl::InvalidArgumentError(
          absl::StrCat("--friction-boundaries must be exact or faces, not '", how, "'"));
    }
    const std::string path = args.options.count("friction") ? args.options.at("friction") : "";
    const terrain::GisFormat* format = terrain::GisFormatOf(path);
    const bool polygons =
        !path.empty() && (format == nullptr || format->kind != terrain::GisFileKind::kRaster);
    if (how == "exact" && (!polygons || !terrain::IsDemPath(mesh))) {
      return absl::InvalidArgumentError(
          "--friction-boundaries exact: cuts friction polygons (--friction F.geojson, .gpkg, "
          ".shp, .fgb) into a DEM's mesh");
    }
    if (how == "exact" && args.All("friction").size() > 1) {
      return absl::InvalidArgumentError(
          "--friction-boundaries exact: cuts one --friction file in (merge the polygon files into "
          "one, or leave out --friction-boundaries: repeated polygon files add up by faces)");
    }
    if (how == "exact") dem.friction_file = path;
  }
  // --friction-snap F: those outlines snapped onto the vertices within F x the shortest edge at
  // the vertex.
  if (!GetDouble(args, "friction-snap", &dem.friction_snap, &error)) {
    return absl::InvalidArgumentError(error);
  }
  // The values' rules are terrain's (one check); their errors name the flag here.
  if (absl::Status s = terrain::ValidateDemOptions(dem); !s.ok()) {
    return absl::InvalidArgumentError(InFlagTerms(s));
  }
  return dem;
}

int OpenMesh(Backend& backend, const Args& args, const std::string& mesh,
             const MeshBuildOptions& build) {
  absl::StatusOr<terrain::DemOptions> dem = MeshReadOptions(args, mesh);
  if (!dem.ok()) return Fail(kExitUsage, std::string(dem.status().message()));
  absl::Status s = backend.Open(mesh, build, *dem);
  if (s.ok()) return kExitOk;
  switch (s.code()) {  // the service failed, not the mesh
    case absl::StatusCode::kUnauthenticated:
    case absl::StatusCode::kUnavailable:
    case absl::StatusCode::kDeadlineExceeded:
    case absl::StatusCode::kResourceExhausted:
    case absl::StatusCode::kCancelled:
      return Fail(kExitSolveFailed, std::string(s.message()));
    default:  // (a DEM option terrain refused while reading, a TIN's z_tolerance: its flag)
      return Fail(kExitInput, InFlagTerms(s));
  }
}

}  // namespace geodex::cli
