#include "harness/peer_figures.h"

#include <cstddef>
#include <fstream>
#include <map>
#include <utility>

#include "absl/strings/match.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "absl/strings/strip.h"

namespace geodex::bench {

absl::StatusOr<std::vector<PeerFigure>> ReadPeerFigures(const std::string& path) {
  std::ifstream in(path);
  if (!in) return absl::NotFoundError(absl::StrCat("cannot read ", path));
  std::vector<PeerFigure> figures;
  std::map<std::string, size_t> column;  // name -> index, from the header line
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (absl::StripAsciiWhitespace(line).empty() || absl::StartsWith(line, "#")) continue;
    const std::vector<std::string> fields = absl::StrSplit(line, '\t');
    auto error = [&](const std::string& what) {
      return absl::InvalidArgumentError(absl::StrCat(path, ":", number, ": ", what));
    };
    if (column.empty()) {
      for (size_t i = 0; i < fields.size(); ++i) column[fields[i]] = i;
      for (const char* name : kPeerFigureColumns) {
        if (!column.contains(name)) return error(absl::StrCat("no column '", name, "'"));
      }
      continue;
    }
    if (fields.size() != column.size()) {
      return error(absl::StrCat(fields.size(), " fields, the header has ", column.size()));
    }
    auto field = [&](const char* name) { return fields[column.at(name)]; };
    PeerFigure f;
    f.mesh = field("mesh");
    f.figure = field("figure");
    if (!absl::SimpleAtod(field("value"), &f.value)) {
      return error(absl::StrCat("value '", field("value"), "' is not a number"));
    }
    f.peer = field("peer");
    f.peer_version = field("peer_version");
    f.measured = field("measured");
    f.geodex_commit = field("geodex_commit");
    f.machine = field("machine");
    f.source = field("source");
    f.remark = field("remark");
    if (f.mesh.empty() || f.figure.empty() || f.peer.empty() || f.peer_version.empty() ||
        f.measured.empty() || f.source.empty()) {
      return error("mesh, figure, peer, peer_version, measured and source must not be empty");
    }
    figures.push_back(std::move(f));
  }
  if (column.empty()) return absl::InvalidArgumentError(absl::StrCat(path, ": no header line"));
  return figures;
}

}  // namespace geodex::bench
