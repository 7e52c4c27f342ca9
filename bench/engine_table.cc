// The engine table (the default, without a mode flag): geodex's exact engine, the paper's ICH,
// Dijkstra on the edge graph, CGAL's Surface_mesh_shortest_path and any --peer code from the same
// sources in one run, each measurement in its own child, with the difference from CGAL (or from
// geodex's exact engine), and the line to beat of bench/data/peer_figures.tsv.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "child_tasks.h"
#include "config.h"
#include "harness/machine.h"
#include "harness/peer_figures.h"
#include "harness/peer_runner.h"
#include "harness/stats.h"
#include "harness/table.h"
#include "measurements.h"
#include "meshes.h"
#include "sections.h"
#ifdef GEODEX_BENCH_WITH_CGAL
#include "testkit/cgal_reference.h"
#endif

#ifndef GEODEX_SOURCE_DIR
#define GEODEX_SOURCE_DIR "."
#endif

namespace geodex::bench {
namespace {

// Figures of other projects, with their provenance (harness/peer_figures.h).
std::string PeerFiguresPath() { return GEODEX_SOURCE_DIR "/bench/data/peer_figures.tsv"; }

// The peers' single-source times over Dijkstra's for `mesh` (figure time_over_dijkstra), in file
// order: the line to beat. None when the file could not be read.
std::vector<const PeerFigure*> LinesToBeat(const absl::StatusOr<std::vector<PeerFigure>>& figures,
                                           const std::string& mesh) {
  std::vector<const PeerFigure*> out;
  if (!figures.ok()) return out;
  for (const PeerFigure& f : *figures) {
    if (f.mesh == mesh && f.figure == "time_over_dijkstra" && f.value > 0) out.push_back(&f);
  }
  return out;
}

// A --peer code's run (harness/peer_runner.h) as an Outcome, a row like ours.
Outcome RunPeerOnMesh(const std::string& command, const MeshInfo& mesh, uint32_t source, int repeat,
                      const Config& config) {
  const PeerRun run =
      RunPeer(command, mesh.path, source, repeat, config.timeout_s, config.wait_idle_s);
  Outcome outcome;
  switch (run.kind) {
    case PeerRun::kError:
      outcome.kind = Outcome::kError;
      break;
    case PeerRun::kOk:
      outcome.kind = Outcome::kOk;
      break;
    case PeerRun::kTimeout:
      outcome.kind = Outcome::kTimeout;
      break;
    case PeerRun::kFailed:
      outcome.kind = Outcome::kCrashed;
      break;
  }
  outcome.message = run.message;
  outcome.elapsed_s = run.elapsed_s;
  outcome.maxrss_kb = run.maxrss_kb;
  if (run.kind == PeerRun::kOk) {
    outcome.report.ok = 1;
    outcome.report.runs = run.runs;
    outcome.report.solve_ms = run.median_ms;
    outcome.report.wall_ms = run.median_ms;
    outcome.distance = run.distance;
  }
  return outcome;
}

}  // namespace

// kCgal: CgalDistances from job.sources, `repeat` times (medians of its time split); the last
// distances go back when job.want_distances.
void CgalChild(const Job& job, const MeshData& data, ChildReport& report,
               std::vector<double>& values) {
#ifdef GEODEX_BENCH_WITH_CGAL
  const std::vector<SurfacePoint> sources = AsSurfacePoints(job.sources);
  std::vector<double> solve, wall, cpu, setup, query;
  for (int r = 0; r < job.repeat; ++r) {
    values.clear();
    values.shrink_to_fit();
    CgalTiming timing;
    const auto start = std::chrono::steady_clock::now();
    const double cpu_start = CpuMs();
    values = CgalDistances(data, sources, &timing);
    cpu.push_back(CpuMs() - cpu_start);
    wall.push_back(MsSince(start));
    if (values.empty()) {
      SetError(report, "CGAL refused the mesh (not a consistently oriented 2-manifold?)");
      break;
    }
    solve.push_back(timing.solve_ms);
    setup.push_back(timing.setup_ms);
    query.push_back(timing.query_ms);
  }
  report.runs = static_cast<int32_t>(solve.size());
  report.solve_ms = Median(solve);
  report.solve_ms_min = solve.empty() ? 0 : *std::min_element(solve.begin(), solve.end());
  report.wall_ms = Median(wall);
  report.cpu_ms = Median(cpu);
  report.cgal_setup_ms = Median(setup);
  report.cgal_query_ms = Median(query);
  if (!job.want_distances) values.clear();
#else
  static_cast<void>(job);
  static_cast<void>(data);
  static_cast<void>(values);
  SetError(report, "built without CGAL");
#endif
}

std::vector<Section> RunEngineTable(const Config& config, const std::vector<MeshInfo>& meshes) {
  const absl::StatusOr<std::vector<PeerFigure>> peer_figures = ReadPeerFigures(PeerFiguresPath());
  Section s{"ICH vs Dijkstra vs CGAL",
            "solve ms: median of the repeats, propagation only (SolveStats.solve_ms; for CGAL "
            "build_sequence_tree()). wall ms: the whole call (source setup, result arrays; for "
            "CGAL also building its Surface_mesh, reading the distances back and destroying its "
            "sequence tree). cpu ms: CPU time of the whole call (immune to time slicing, not to "
            "a busy sibling core). x Dijkstra = solve ms / Dijkstra's solve ms; CGAL/ICH = "
            "CGAL's solve ms / ICH's. filtered = Lemma 2 filter removals (at creation + at pop + "
            "lambda over-filter). peak MiB = SolveStats.peak_bytes. RSS MiB = the child's peak "
            "resident size while solving (mesh included); delta = RSS minus the mesh-only "
            "baseline child. vs CGAL abs / rel: max |ICH - CGAL| over all vertices, and that "
            "divided by the largest distance. other load: cores used by other processes during "
            "the measurement (from /proc/stat; near 1 on a 2-core machine, the times are "
            "unreliable).",
            Table({"mesh",       "faces",         "source",          "method",
                   "R",          "solve ms",      "wall ms",         "cpu ms",
                   "x Dijkstra", "CGAL/ICH",      "windows created", "filtered",
                   "processed",  "max level",     "peak live",       "peak MiB",
                   "RSS MiB",    "delta RSS MiB", "vs CGAL abs",     "vs CGAL rel",
                   "other load"},
                  "lrrl"),
            {}};
  bool first = true;
  for (const MeshInfo& mesh : meshes) {
    const int repeat = RepeatFor(config, mesh);
    const bool cgal = config.run_cgal && mesh.report.faces <= config.cgal_max_faces;
    for (uint32_t source : mesh.sources) {
      if (!first) s.table.AddBreak();
      first = false;
      const std::vector<uint32_t> src = {source};
      std::fprintf(stderr, "%s (%llu faces), source %u, R = %d\n", mesh.name.c_str(),
                   static_cast<unsigned long long>(mesh.report.faces), source, repeat);
      std::optional<Outcome> dijkstra, ich, paper, cgal_run;
      std::vector<std::pair<std::string, Outcome>> peer_runs;
      if (config.run_dijkstra) {
        GeodesicOptions options;
        options.method = Method::kDijkstra;
        dijkstra = RunGeodex(mesh, src, options, repeat, config.run_ich, config);
        Progress("dijkstra", *dijkstra);
      }
      if (config.run_ich) {
        ich = RunGeodex(mesh, src, GeodesicOptions{}, repeat, true, config);
        Progress("exact", *ich);
      }
      if (config.run_paper) {
        GeodesicOptions options;
        options.method = Method::kIch;
        paper = RunGeodex(mesh, src, options, repeat, true, config);
        Progress("ich (paper)", *paper);
      }
      for (const auto& [name, command] : config.peers) {
        peer_runs.emplace_back(name, RunPeerOnMesh(command, mesh, source, repeat, config));
        Progress(name, peer_runs.back().second);
      }
#ifdef GEODEX_BENCH_WITH_CGAL
      if (cgal) {
        Job job;
        job.task = Task::kCgal;
        job.path = mesh.path;
        job.sources = src;
        job.repeat = repeat;
        job.want_distances = config.run_ich;
        cgal_run = RunChild(job, config.timeout_s, config.wait_idle_s);
        Progress("cgal", *cgal_run);
      }
#endif
      const double dijkstra_ms =
          dijkstra && dijkstra->ok() ? dijkstra->report.solve_ms : std::nan("");
      const double cgal_ms = cgal_run && cgal_run->ok() ? cgal_run->report.solve_ms : std::nan("");
      auto row = [&](const std::string& method, const Outcome& o) {
        std::vector<std::string> cells = {mesh.name, Count(mesh.report.faces), Count(source),
                                          method, Count(repeat)};
        if (!o.ok()) {
          cells.push_back(o.StatusText());
          for (int i = 0; i < 11; ++i) cells.push_back("");
          cells.push_back(MiBOfKb(o.maxrss_kb));
          cells.push_back(DeltaMiB(o, mesh));
          cells.insert(cells.end(), {"", "", OtherLoad(o)});
          if (!o.message.empty()) {
            s.notes.push_back(
                absl::StrCat(mesh.name, " source ", source, " ", method, ": ", o.message));
          }
          return cells;
        }
        const ChildReport& r = o.report;
        const bool windows = method == "exact" || method == "ICH (paper)";
        cells.push_back(Ms(r.solve_ms));
        cells.push_back(Ms(r.wall_ms));
        cells.push_back(Ms(r.cpu_ms));
        cells.push_back(Ratio(r.solve_ms / dijkstra_ms));
        cells.push_back(method != "Dijkstra" && method != "CGAL" ? Ratio(cgal_ms / r.solve_ms)
                                                                 : "");
        cells.push_back(windows ? Count(r.stats.windows_created) : "");
        cells.push_back(windows ? Count(FilteredWindows(r.stats)) : "");
        cells.push_back(windows ? Count(r.stats.windows_processed) : "");
        cells.push_back(windows ? Count(r.stats.max_level) : "");
        cells.push_back(windows ? Count(r.stats.peak_live_windows) : "");
        cells.push_back(windows || method == "Dijkstra"
                            ? MiBOfBytes(static_cast<double>(r.stats.peak_bytes))
                            : "");
        cells.push_back(MiBOfKb(o.maxrss_kb));
        cells.push_back(DeltaMiB(o, mesh));
        cells.insert(cells.end(), {"", "", OtherLoad(o)});
        return cells;
      };
      if (dijkstra) s.table.AddRow(row("Dijkstra", *dijkstra));
      // An exact method's row, with its difference from CGAL (or, without CGAL, from geodex's
      // default engine) and a check against Dijkstra's upper bound.
      auto exact_row = [&](const std::string& method, const Outcome& o) {
        std::vector<std::string> cells = row(method, o);
        const Outcome* reference = cgal_run && cgal_run->ok()        ? &*cgal_run
                                   : ich && ich->ok() && &o != &*ich ? &*ich
                                                                     : nullptr;
        if (o.ok() && reference != nullptr && o.distance.size() == reference->distance.size()) {
          const FieldDiff d = Compare(o.distance, reference->distance);
          cells[cells.size() - 3] = Sci(d.max_abs);
          cells[cells.size() - 2] = Sci(d.max_rel);
          if (reference != &*cgal_run) {
            cells[cells.size() - 3] += " (vs exact)";
          }
          if (d.finiteness_mismatch > 0) {
            s.notes.push_back(absl::StrCat(mesh.name, " source ", source, " ", method, ": ",
                                           d.finiteness_mismatch,
                                           " vertices finite in only one of it and the reference"));
          }
        }
        if (o.ok() && dijkstra && dijkstra->ok() &&
            o.distance.size() == dijkstra->distance.size()) {
          // Dijkstra's edge paths are real paths: exact distances can only be shorter or equal.
          const FieldDiff d = Compare(dijkstra->distance, o.distance);
          if (d.below_reference > 0) {
            s.notes.push_back(absl::StrCat(mesh.name, " source ", source, ": ", method,
                                           " exceeds Dijkstra at ", d.below_reference,
                                           " vertices (not exact there)"));
          }
        }
        s.table.AddRow(cells);
      };
      if (ich) exact_row("exact", *ich);
      if (paper) exact_row("ICH (paper)", *paper);
      for (const auto& [name, o] : peer_runs) {
        exact_row(name, o);
        if (o.ok() && ich && ich->ok()) {
          s.notes.push_back(absl::StrFormat(
              "%s source %u: geodex exact / %s = %.2f in time, %.2f in peak RSS", mesh.name, source,
              name, ich->report.solve_ms / o.report.solve_ms,
              static_cast<double>(ich->maxrss_kb) / std::max<int64_t>(1, o.maxrss_kb)));
        }
      }
      for (const PeerFigure* f : LinesToBeat(peer_figures, mesh.name)) {
        if (ich && ich->ok()) {
          s.notes.push_back(absl::StrFormat(
              "%s: the line to beat, %s at %.0fx Dijkstra (%s); geodex exact here at %.1fx",
              mesh.name, f->peer, f->value, f->source, ich->report.solve_ms / dijkstra_ms));
        }
      }
      if (cgal_run) {
        s.table.AddRow(row("CGAL", *cgal_run));
        if (cgal_run->ok()) {
          s.notes.push_back(absl::StrFormat(
              "%s source %u CGAL: setup %s ms + build_sequence_tree %s ms + query %s ms", mesh.name,
              source, Ms(cgal_run->report.cgal_setup_ms), Ms(cgal_run->report.solve_ms),
              Ms(cgal_run->report.cgal_query_ms)));
        }
      }
    }
    if (config.run_cgal && !cgal) {
      s.notes.push_back(absl::StrFormat("%s: CGAL not run (%d faces > --cgal-max-faces %d)",
                                        mesh.name, mesh.report.faces, config.cgal_max_faces));
    }
  }
  if (!peer_figures.ok()) {
    s.notes.push_back(absl::StrCat("no line to beat: ", peer_figures.status().message()));
  }
  return {s};
}

}  // namespace geodex::bench
