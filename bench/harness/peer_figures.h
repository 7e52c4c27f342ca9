#pragma once

// Figures of other projects that a bench prints next to its own measurements (the line to beat),
// kept as data with their provenance: bench/data/peer_figures.tsv, read at run time.
//
// The file is tab-separated. Lines that are empty or start with '#' are comments; the first other
// line names the columns (in any order, all of kPeerFigureColumns required, others ignored); every
// line after it is one figure.

#include <string>
#include <vector>

#include "absl/status/statusor.h"

namespace geodex::bench {

struct PeerFigure {
  std::string mesh;    // the mesh's name (its file name without extensions)
  std::string figure;  // what `value` is, e.g. time_over_dijkstra
  double value = 0;
  std::string peer;           // the other project, as printed
  std::string peer_version;   // its repository @ commit, and how it was built
  std::string measured;       // when (a date, UTC)
  std::string geodex_commit;  // the geodex commit measured next to it
  std::string machine;        // where, and how (cores, repeats)
  std::string source;         // where the figure is written down (printed with it)
  std::string remark;         // anything else a reader must know; may be empty
};

inline constexpr const char* kPeerFigureColumns[] = {
    "mesh",     "figure",        "value",   "peer",   "peer_version",
    "measured", "geodex_commit", "machine", "source", "remark"};

// Every figure in the file at `path`, in file order; an error names the line that is wrong.
absl::StatusOr<std::vector<PeerFigure>> ReadPeerFigures(const std::string& path);

}  // namespace geodex::bench
