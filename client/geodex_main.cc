// geodex: the command line. Thin: parses the command and runs it on a backend (cli_backend.h):
// this process, or a geodexd with --server.

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "cli_backend.h"
#include "cli_commands.h"
#include "cli_common.h"
#include "cli_remote.h"

namespace {

// `geodex --help`: this header, each command's entry (kept with its code: QueryCommands), then
// the point grammar, JSON and exit codes (kUsageTail).
constexpr char kUsageHead[] =
    R"(geodex - exact geodesic distances on triangle meshes (improved Chen-Han)

usage: geodex [--server HOST:PORT] COMMAND MESH [options]

MESH is a mesh file (OFF, OBJ, PLY, STL, optionally .gz), a built-in sample (sample:terrain,
sample:torus, sample:sphere), or a DEM: a raster GDAL reads (.tif, .tiff, .asc, .img, .hgt, .dem,
.bil, .nc; a .vrt is refused: its sources may name other files or URLs), triangulated cell centre by cell centre, nodata cells left out, in metres (a
longitude/latitude grid is projected to the UTM zone of its centre). --dem-step N uses every Nth
cell (a quick look). --z-tolerance Z makes the DEM an adaptive TIN: the few cells needed for the
surface to stay within Z (the DEM's height unit) of every cell, Delaunay-triangulated; far fewer
vertices on smooth terrain, rasters still on the DEM's grid (docs/terrain.md). --barrier-below Z (any MESH) removes what lies below Z (the sea at 0): a DEM's
cells, a mesh's faces with a corner below Z; paths go around it, exactly, and beyond it is inf.
--barrier FILE (GeoJSON; on a DEM also Shapefile, GeoPackage, FlatGeobuf) cuts its polygons exactly
out of the surface (on a DEM in the file's CRS, WGS 84 when it names none; on a mesh in its own
x y); its lines are slits (both sides kept, paths go around their ends), or with --barrier-width W
walls W metres wide, as are its points (docs/barriers.md). A barrier that cuts nothing, or splits
the surface, is said on stderr.

Local by default; remote with --server HOST:PORT (or GEODEX_SERVER=HOST:PORT), plus --tls,
--ca FILE (PEM roots; implies --tls) and --token-file FILE (or GEODEX_TOKEN) for a server with TLS
and bearer tokens. The command runs on
a geodexd and prints the same output. There MESH may also be a mesh id or a name known to the
server; a file is uploaded once (only if the server does not have it, by content hash).
  mesh upload FILE [--name NAME] | mesh list | mesh get MESH | mesh delete MESH   [--format json]
  health [--service NAME]      prints SERVING (exit 0) or NOT_SERVING (exit 1)
isolines, voronoi, delaunay and render take the mesh's coordinates from the file when MESH is one,
else from the server (GetMeshGeometry).

commands:
)";

constexpr char kUsageTail[] = R"(
SPEC: comma-separated points: 17 (vertex), e:V1:V2:T (the point (1-T)*V1 + T*V2 on an edge),
      f:FACE:B0:B1:B2 (barycentric in the face's vertex order as in the file),
      g:X:Y and ll:LON:LAT (on a DEM: map coordinates in the DEM's CRS, or WGS 84 longitude and
      latitude, dropped vertically onto the surface; outside the DEM or in a nodata hole is an
      error naming the point as written, with the DEM's extent and a hint when x and y, or
      longitude and latitude, look swapped),
      p:X:Y:Z (a 3D position, snapped to the nearest point of the surface). Snapping is never
      silent: --stats reports the farthest snap (snap_max), a snap beyond 1% of the mesh's
      diagonal is warned about on stderr, and --max-snap D (every command taking a SPEC)
      refuses a point farther than D from the surface.
--sources-file F, --targets-file F (on a DEM): the points of a GeoJSON, GeoPackage, Shapefile,
      FlatGeobuf or CSV file (x,y columns in the DEM's CRS, or lon,lat), in its own CRS, added to
      --sources / --targets; messages name them as the file's features.

Travel time (distances, path, matrix, isolines, voronoi; docs/travel.md): --speed constant:KMH
      answers in SECONDS instead of metres, from the weighted engine, within (1 + E) of the
      least time (--cost-epsilon E, default 0.01, in (0, 1)); a straight piece in a face takes
      its 3D length x the face's friction / the speed. --friction FILE on a DEM: GeoJSON
      polygons with a numeric "friction" property, or a raster in the DEM's CRS (nodata
      impassable); each face takes the value under its centroid (--friction-boundaries exact:
      polygons' outlines cut into the DEM's mesh, exact boundaries, often far slower, and
      --friction-snap F in [0, 0.25] first moves them onto the vertices within F x the
      vertex's shortest edge: much faster, boundaries moved that little; faces: the default).
      --face-weights FILE: one
      weight per face, a number a line (inf: impassable). --max-slope DEG: faces steeper than
      DEG (from the x-y plane, z up) are impassable. --max-steiner-points N bounds the engine's
      memory (about 32 bytes a point; default 50000000, 0: none). Answers say so: a '# travel
      time in seconds ...' first line, or JSON "unit": "s", "approximate" or "exact",
      "epsilon", and "time_s" for values.
      Isoline levels may carry a unit: --levels 10min,20min (s, min, h). Not with --lambda,
      --directions or delaunay.
      --speed tobler (Tobler's hiking function of the slope along the way) or --speed
      table:FILE.csv (slope_deg,speed_kmh rows, linear between them; steeper slopes cannot be
      walked): the speed depends on the direction, walkers zigzag up and down steep faces
      (switchbacks), matrices are row to column, --inbound gives times to reach the sources;
      approximate with no proven bound (--cost-epsilon is the Steiner points' spacing along
      each edge, default 0.125: within about 1% of the finest run; "bound": false).

--format json (distances, path, matrix, locate, info) prints one JSON object instead of text:
      distances {"distances": [...]} (or {"points": [...]} with --at), path {"length", "points"
      with each point's simplex}, matrix {"rows", "cols", "values"}; null for unreachable.

geodex COMMAND --help prints that command's part of this text.

exit codes: 0 ok; 1 the computation failed (cancelled, budget, target unreachable); 2 bad command
            line or argument;
            3 the mesh could not be read or is invalid.
)";

std::string Usage() {
  std::string usage = kUsageHead;
  for (const geodex::cli::Command& c : geodex::cli::QueryCommands()) usage += c.help;
  return usage + kUsageTail;
}

// `geodex COMMAND --help`: that command's entry, then the point grammar and the exit codes; the
// whole text for a command it does not know.
std::string CommandHelp(const std::string& command) {
  for (const geodex::cli::Command& c : geodex::cli::QueryCommands()) {
    if (command == c.name) {
      return std::string("usage: geodex [--server HOST:PORT] COMMAND MESH [options]\n\n") + c.help +
             kUsageTail;
    }
  }
  return Usage();
}

// Every command's value-less flags: a command given another's (`info --stats`) is told the option
// is unknown to it, rather than that it needs a value.
std::vector<std::string> ValueLessFlags() {
  std::vector<std::string> flags;
  for (const geodex::cli::Command& c : geodex::cli::QueryCommands()) {
    flags.insert(flags.end(), c.flags.begin(), c.flags.end());
  }
  return flags;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace geodex::cli;
  if (argc < 2 || !std::strcmp(argv[1], "--help") || !std::strcmp(argv[1], "-h") ||
      !std::strcmp(argv[1], "help")) {
    std::fputs(Usage().c_str(), argc < 2 ? stderr : stdout);
    return argc < 2 ? kExitUsage : kExitOk;
  }
  if (!std::strcmp(argv[1], "--version")) {
    std::puts("geodex " GEODEX_VERSION);  // CMake's project version
    return kExitOk;
  }
  // Global options before the command: --server HOST:PORT (else GEODEX_SERVER), --tls, --ca FILE,
  // --token-file FILE (else the token in GEODEX_TOKEN).
  int first = 1;
  RemoteOptions remote;
  if (const char* env = std::getenv("GEODEX_SERVER")) remote.target = env;
  while (first < argc) {
    const std::string a = argv[first];
    auto value = [&](const char* name, std::string* out) {
      const std::string flag = std::string("--") + name;
      if (a == flag && first + 1 < argc) {
        *out = argv[first + 1];
        first += 2;
        return true;
      }
      if (a.rfind(flag + "=", 0) == 0) {
        *out = a.substr(flag.size() + 1);
        first += 1;
        return true;
      }
      return false;
    };
    if (value("server", &remote.target) || value("ca", &remote.ca_file) ||
        value("token-file", &remote.token_file)) {
      continue;
    }
    if (a == "--tls") {
      remote.tls = true;
      ++first;
      continue;
    }
    break;
  }
  if (first >= argc) {
    std::fputs(
        "geodex: usage: geodex [--server HOST:PORT [--tls] [--ca FILE] [--token-file FILE]] "
        "COMMAND ...\n",
        stderr);
    return kExitUsage;
  }
  SetRemoteOptions(remote);
  const std::string server = remote.target;
  const std::string command = argv[first];
  for (int i = first + 1; i < argc; ++i) {  // help wins over anything else on the line
    if (!std::strcmp(argv[i], "--help") || !std::strcmp(argv[i], "-h")) {
      std::fputs(CommandHelp(command).c_str(), stdout);
      return kExitOk;
    }
  }
  Args args;
  std::string error;
  if (!ParseArgs(argc, argv, first + 1, ValueLessFlags(), &args, &error)) {
    std::fprintf(stderr, "geodex: %s\n", error.c_str());
    return kExitUsage;
  }
  if (absl::Status points = ExpandPointFiles(&args); !points.ok()) {
    std::fprintf(stderr, "geodex: %s\n", std::string(points.message()).c_str());
    return absl::IsNotFound(points) ? kExitInput : kExitUsage;
  }
  // A terminal sees elapsed time for anything that takes more than a second.
  Progress progress(server.empty() ? command : command + " on " + server);
  if (command == "mesh" || command == "health") {
    if (!server.empty()) return RunServerCommand(server, command, args);
    std::fprintf(stderr, "geodex: '%s' talks to a server: use --server HOST:PORT\n",
                 command.c_str());
    return kExitUsage;
  }
  // Every query command is written once against a backend: this process, or the server.
  for (const Command& c : QueryCommands()) {
    if (command != c.name) continue;
    std::unique_ptr<Backend> backend =
        server.empty() ? MakeLocalBackend() : MakeRemoteBackend(server);
    if (backend == nullptr) return RunServerCommand(server, command, args);  // built without gRPC
    return c.run(*backend, args);
  }
  std::fprintf(stderr, "geodex: unknown command '%s' (see geodex --help)\n", command.c_str());
  return kExitUsage;
}
