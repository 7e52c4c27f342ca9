// geodex: the command line. Thin: parses the command and runs it on a backend (cli_backend.h):
// this process, or a geodexd with --server.

#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <utility>

#include "cli_backend.h"
#include "cli_commands.h"
#include "cli_common.h"
#include "cli_geometry.h"
#include "cli_remote.h"
#include "cli_render.h"

namespace {

constexpr char kUsage[] = R"(geodex - exact geodesic distances on triangle meshes (improved Chen-Han)

usage: geodex [--server HOST:PORT] COMMAND MESH [options]

MESH is a mesh file (OFF, OBJ, PLY, STL, optionally .gz), a built-in sample (sample:terrain,
sample:torus, sample:sphere), or a DEM: a raster GDAL reads (.tif, .tiff, .vrt, .asc, .img, .hgt,
.dem, .bil, .nc), triangulated cell centre by cell centre, nodata cells left out, in metres (a
longitude/latitude grid is projected to the UTM zone of its centre). --dem-step N uses every Nth
cell (a quick look). --barrier-below Z (any MESH) removes what lies below Z (the sea at 0): a DEM's
cells, a mesh's faces with a corner below Z; paths go around it, exactly, and beyond it is inf.
--barrier FILE.geojson (a DEM) removes the triangles whose centre lies inside its polygons (in
the file's CRS, WGS 84 when it names none).

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
  info MESH [--format text|json] [--strict]
      One 'key: value' line per property (vertices, faces, boundary_loops, components,
      isolated_vertices, non_manifold_edges, non_manifold_vertices, degenerate_faces,
      saddle_vertices, bytes, ...). Reports on any readable mesh, valid or messy.
  distances MESH --sources SPEC [--method exact|ich|dijkstra] [--lambda L] [--lambda-scale max|mean]
                 [--max-distance D] [--max-windows N] [--stats] [--output FILE] [--format json]
                 [--directions] [--labels-output FILE.tif]
      One distance per vertex in the file's vertex order (%.17g; 'inf' if unreachable).
      On a DEM, --output FILE.tif writes a float32 GeoTIFF aligned with the DEM's grid (same
      geotransform and CRS; nodata -1 where unreachable or no data) and --labels-output
      FILE.tif the nearest source's index (int32, nodata -1).
      --stats prints one JSON object with counters and times (*_ms) on stderr.
      --no-filter / --no-one-split switch off Lemma 2 / Lemma 1 (slower; same answer).
      --at SPEC: instead, one line per surface point: its unfolding estimate (paper section 4)
      and its exact distance ('POINT<TAB>estimate D<TAB>exact D<TAB>source I').
      --directions: also the geodesic direction field, 'D<TAB>X Y Z' per vertex: the unit
      tangent of the vertex's shortest path towards its nearest source (0 0 0 at a source,
      nan where unreachable), what a vector-field planner follows.
  path MESH --from SPEC --to SPEC [--method astar|full] [--stats] [--lambda L]
       [--max-distance D] [--format json]
      The exact shortest path: line 1 its length; then one line per polyline point,
      'x y z' and the simplex it lies on ('v ID', 'e V1 V2 T' or 'f FACE B0 B1 B2').
      astar (default) uses the paper's section 5 heuristic and stops at the target.
      --lambda L (as for distances) trades exactness for speed; --max-distance D: a target
      farther than D is unreachable.
  matrix MESH --sources SPEC --targets SPEC [--stats] [--lambda L] [--max-distance D]
         [--k-nearest K] [--threads N] [--format json]
      Exact distances, one row per source, tab-separated. Rows run in parallel on every usable
      core (--threads N to limit). The same points as sources and targets give a symmetric
      matrix, each pair solved once. --max-distance D: entries beyond D are inf. --k-nearest K:
      per source only its K nearest targets are filled in, the rest inf. A progress bar shows
      on a terminal for calls longer than a second.
  locate MESH --points p:X:Y:Z,... [--max-snap D] [--format text|json]
      The nearest surface point to each 3D position: 'QUERY<TAB>SPEC<TAB>x y z<TAB>snap D', D
      the distance it moved. --max-snap D refuses a position farther than D from the surface.
  isolines MESH --sources SPEC (--levels L1,L2,... | --count K) [--output FILE.json|.obj|.svg]
      Approximate geodesic offsets (paper section 6.1; linear along edges): polylines of edge
      points per level. --count K: the levels D*j/K, j = 1..K-1, D the largest distance.
  voronoi MESH --sites SPEC [--output FILE.json|.obj|.svg]
      Approximate Voronoi diagram (section 6.2): boundaries, cells (faces, fragments, areas),
      adjacency.
  delaunay MESH --sites SPEC [--output FILE.json|.obj|.svg]
      Approximate Delaunay triangulation (sections 6.3-6.4): edges as polylines, triangles, XL
      edges found and the Delaunay edges removed because of them.
      These three print JSON ("approximate": true) unless --output names an .obj (lines) or
      .svg (top view) file; see docs/geometry.md.

  render MESH --sources SPEC [--isolines K] [--voronoi] [--delaunay] [--path A B]
         --output out.png|.ply|.gltf [--view auto|iso|top|bottom|front|back|left|right]
         [--size WxH]
      A picture of the field: the shaded mesh coloured by distance (viridis; grey where
      unreachable) with a colour bar (0 to the largest distance, labelled, at least 320 pixels
      wide), isolines (dark), Voronoi boundaries (white), Delaunay edges (orange), the path (red)
      and the sources (black dots), framed automatically (z up; 800x600). The default view, auto,
      is the one of iso and the six axis views that shows the most sources, then the most of the
      lines.
      .ply and .gltf write the coloured mesh for 3D viewers instead.

SPEC: comma-separated points: 17 (vertex), e:V1:V2:T (the point (1-T)*V1 + T*V2 on an edge),
      f:FACE:B0:B1:B2 (barycentric in the face's vertex order as in the file),
      g:X:Y and ll:LON:LAT (on a DEM: map coordinates in the DEM's CRS, or WGS 84 longitude and
      latitude, dropped vertically onto the surface; outside the DEM or in a nodata hole is an
      error naming the point),
      p:X:Y:Z (a 3D position, snapped to the nearest point of the surface). Snapping is never
      silent: --stats reports the farthest snap (snap_max), a snap beyond 1% of the mesh's
      diagonal is warned about on stderr, and --max-snap D (every command taking a SPEC)
      refuses a point farther than D from the surface.

--format json (distances, path, matrix, locate, info) prints one JSON object instead of text:
      distances {"distances": [...]} (or {"points": [...]} with --at), path {"length", "points"
      with each point's simplex}, matrix {"rows", "cols", "values"}; null for unreachable.

geodex COMMAND --help prints that command's part of this text.

exit codes: 0 ok; 1 the computation failed (cancelled, budget, target unreachable); 2 bad command
            line or argument;
            3 the mesh could not be read or is invalid.
)";

// `command`'s entry in kUsage (from its line to the next command's), then SPEC and the exit
// codes; the whole text for a command it does not list.
std::string CommandHelp(const std::string& command) {
  const std::string usage = kUsage;
  const size_t start = usage.find("\n  " + command + " ");
  if (start == std::string::npos) return usage;
  size_t end = start + 1;
  for (;;) {  // the next line indented by exactly two spaces and a letter, or a blank line
    end = usage.find('\n', end + 1);
    if (end == std::string::npos || end + 1 >= usage.size() || usage[end + 1] == '\n' ||
        (usage.compare(end + 1, 2, "  ") == 0 && std::isalpha(usage[end + 3]))) {
      break;
    }
  }
  const size_t spec = usage.find("\nSPEC:");
  return "usage: geodex [--server HOST:PORT] COMMAND MESH [options]\n" +
         usage.substr(start, end - start) + "\n" + usage.substr(spec);
}

}  // namespace

int main(int argc, char** argv) {
  using namespace geodex::cli;
  if (argc < 2 || !std::strcmp(argv[1], "--help") || !std::strcmp(argv[1], "-h") ||
      !std::strcmp(argv[1], "help")) {
    std::fputs(kUsage, argc < 2 ? stderr : stdout);
    return argc < 2 ? kExitUsage : kExitOk;
  }
  if (!std::strcmp(argv[1], "--version")) {
    std::puts("geodex 0.1.0");
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
    std::fputs("geodex: usage: geodex [--server HOST:PORT [--tls] [--ca FILE] [--token-file FILE]] "
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
  if (!ParseArgs(argc, argv, first + 1,
                 {"stats", "strict", "no-filter", "no-one-split", "voronoi", "delaunay", "directions"}, &args,
                 &error)) {
    std::fprintf(stderr, "geodex: %s\n", error.c_str());
    return kExitUsage;
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
  using Command = int (*)(Backend&, const Args&);
  static const std::pair<const char*, Command> kCommands[] = {
      {"info", RunInfo},         {"distances", RunDistances}, {"path", RunPath},
      {"matrix", RunMatrix},     {"locate", RunLocate},       {"isolines", RunIsolines},
      {"voronoi", RunVoronoi},   {"delaunay", RunDelaunay},   {"render", RunRender},
  };
  for (const auto& [name, run] : kCommands) {
    if (command != name) continue;
    std::unique_ptr<Backend> backend = server.empty() ? MakeLocalBackend() : MakeRemoteBackend(server);
    if (backend == nullptr) return RunServerCommand(server, command, args);  // built without gRPC
    return run(*backend, args);
  }
  std::fprintf(stderr, "geodex: unknown command '%s' (see geodex --help)\n", command.c_str());
  return kExitUsage;
}
