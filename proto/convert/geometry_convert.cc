#include "geometry_convert.h"

#include <algorithm>
#include <utility>

#include "api_convert.h"

namespace geodex::api {
namespace {

// Cuts a result into messages of about `budget` bytes each.
template <typename Response>
class Chunker {
 public:
  explicit Chunker(size_t budget_bytes) : budget_(budget_bytes) { messages_.emplace_back(); }

  Response& current() { return messages_.back(); }
  Response& first() { return messages_.front(); }

  void Account(size_t bytes) { bytes_ += bytes; }
  bool Full() const { return bytes_ >= budget_; }
  // Starts the next message when the current one is full.
  void MakeRoom() {
    if (Full()) {
      messages_.emplace_back();
      bytes_ = 0;
    }
  }

  // Appends one item holding a point list. `new_item(message)` adds a new item with its header
  // fields set to the message and returns it.
  template <typename NewItem>
  void AppendPolyline(const std::vector<PathPoint>& points, NewItem new_item) {
    MakeRoom();
    auto* item = new_item(current());
    const size_t header = item->ByteSizeLong() + 4;
    Account(header);
    for (const PathPoint& p : points) {
      if (Full()) {
        item->set_continued(true);
        MakeRoom();
        item = new_item(current());
        Account(header);
      }
      v1::PathPoint* out = item->add_points();
      PathPointToProto(p, out);
      Account(out->ByteSizeLong() + 3);
    }
  }

  std::vector<Response> Take() { return std::move(messages_); }

 private:
  const size_t budget_;
  size_t bytes_ = 0;
  std::vector<Response> messages_;
};

// Appends a streamed piece's points to the item being assembled: a piece continues the previous
// one when that one said `continued`.
template <typename Piece, typename Item, typename Start>
void AddPiece(const Piece& piece, bool* open, std::vector<Item>* items, Start start) {
  if (!*open) items->push_back(start(piece));
  for (const auto& p : piece.points()) items->back().points.push_back(PathPointFromProto(p));
  *open = piece.continued();
}

DelaunayEdge EdgeHeader(const v1::DelaunayEdge& first) {
  DelaunayEdge e;
  e.site_a = first.site_a();
  e.site_b = first.site_b();
  e.vertex_a = first.vertex_a();
  e.vertex_b = first.vertex_b();
  e.length = first.length();
  e.edge_start = first.edge_start();
  return e;
}

}  // namespace

void IsolineQueryToProto(const IsolineQuery& query, v1::ComputeIsolinesRequest* out) {
  for (const SurfacePoint& p : query.sources) SurfacePointToProto(p, out->add_sources());
  SolverOptionsToProto(query.options, out->mutable_options());
  for (double level : query.levels.levels) out->add_levels(level);
  out->set_count(query.levels.count);
}

void VoronoiQueryToProto(const VoronoiQuery& query, v1::ComputeVoronoiRequest* out) {
  for (const SurfacePoint& p : query.sites) SurfacePointToProto(p, out->add_sources());
  SolverOptionsToProto(query.options, out->mutable_options());
}

void DelaunayQueryToProto(const DelaunayQuery& query, v1::ComputeDelaunayRequest* out) {
  for (const SurfacePoint& p : query.sites) SurfacePointToProto(p, out->add_sources());
  SolverOptionsToProto(query.options, out->mutable_options());
}

IsolineOptions IsolineLevelsFromProto(const v1::ComputeIsolinesRequest& request) {
  return IsolineLevelsFromProto(request.levels(), request.count());
}

IsolineOptions IsolineLevelsFromProto(const google::protobuf::RepeatedField<double>& levels,
                                      int32_t count) {
  IsolineOptions out;
  out.levels.assign(levels.begin(), levels.end());
  out.count = count;
  return out;
}

std::vector<v1::ComputeIsolinesResponse> IsolinesToProto(const Isolines& isolines,
                                                         size_t budget_bytes) {
  Chunker<v1::ComputeIsolinesResponse> chunker(budget_bytes);
  for (double level : isolines.levels) chunker.first().add_levels(level);
  chunker.Account(isolines.levels.size() * 8);
  for (size_t i = 0; i < isolines.polylines.size(); ++i) {
    const IsolinePolyline& line = isolines.polylines[i];
    chunker.AppendPolyline(line.points, [&](v1::ComputeIsolinesResponse& message) {
      v1::Isoline* item = message.add_isolines();
      item->set_index(static_cast<uint32_t>(i));
      item->set_level(line.level);
      item->set_closed(line.closed);
      return item;
    });
  }
  return chunker.Take();
}

std::vector<v1::ComputeVoronoiResponse> VoronoiToProto(
    const VoronoiDiagram& diagram, const std::vector<SurfacePoint>& resolved_sources,
    bool omit_cell_faces, size_t budget_bytes) {
  Chunker<v1::ComputeVoronoiResponse> chunker(budget_bytes);
  v1::ComputeVoronoiResponse& first = chunker.first();
  for (const auto& [a, b] : diagram.adjacency) {
    v1::SitePair* pair = first.add_adjacency();
    pair->set_a(a);
    pair->set_b(b);
  }
  first.set_junction_faces(diagram.junction_faces);
  first.set_total_area(diagram.total_area);
  for (const SurfacePoint& p : resolved_sources)
    SurfacePointToProto(p, first.add_resolved_sources());
  chunker.Account(first.ByteSizeLong());

  for (const VoronoiCell& cell : diagram.cells) {
    chunker.MakeRoom();
    auto new_piece = [&]() {
      v1::VoronoiCell* piece = chunker.current().add_cells();
      piece->set_site(cell.site);
      piece->set_area(cell.area);
      chunker.Account(16);
      return piece;
    };
    v1::VoronoiCell* piece = new_piece();
    if (omit_cell_faces) continue;
    for (uint32_t face : cell.whole_faces) {
      if (chunker.Full()) {
        piece->set_continued(true);
        chunker.MakeRoom();
        piece = new_piece();
      }
      piece->add_whole_faces(face);
      chunker.Account(5);
    }
    for (const VoronoiFragment& fragment : cell.fragments) {
      if (chunker.Full()) {
        piece->set_continued(true);
        chunker.MakeRoom();
        piece = new_piece();
      }
      v1::VoronoiFragment* out = piece->add_fragments();
      out->set_face(fragment.face);
      out->set_area(fragment.area);
      for (const PathPoint& p : fragment.polygon) PathPointToProto(p, out->add_polygon());
      chunker.Account(out->ByteSizeLong() + 4);
    }
  }
  for (size_t i = 0; i < diagram.boundaries.size(); ++i) {
    const VoronoiBoundary& boundary = diagram.boundaries[i];
    chunker.AppendPolyline(boundary.points, [&](v1::ComputeVoronoiResponse& message) {
      v1::VoronoiBoundary* item = message.add_boundaries();
      item->set_index(static_cast<uint32_t>(i));
      item->set_site_a(boundary.site_a);
      item->set_site_b(boundary.site_b);
      item->set_closed(boundary.closed);
      return item;
    });
  }
  return chunker.Take();
}

std::vector<v1::ComputeDelaunayResponse> DelaunayToProto(
    const DelaunayTriangulation& delaunay, const std::vector<SurfacePoint>& resolved_sources,
    size_t budget_bytes) {
  Chunker<v1::ComputeDelaunayResponse> chunker(budget_bytes);
  for (const SurfacePoint& p : resolved_sources) {
    SurfacePointToProto(p, chunker.first().add_resolved_sources());
  }
  chunker.Account(chunker.first().ByteSizeLong());
  auto append_edges = [&](const std::vector<DelaunayEdge>& edges, bool removed) {
    for (size_t i = 0; i < edges.size(); ++i) {
      const DelaunayEdge& edge = edges[i];
      chunker.AppendPolyline(edge.points, [&](v1::ComputeDelaunayResponse& message) {
        v1::DelaunayEdge* item = removed ? message.add_removed_edges() : message.add_edges();
        item->set_index(static_cast<uint32_t>(i));
        item->set_site_a(edge.site_a);
        item->set_site_b(edge.site_b);
        item->set_vertex_a(edge.vertex_a);
        item->set_vertex_b(edge.vertex_b);
        item->set_length(edge.length);
        item->set_edge_start(edge.edge_start);
        return item;
      });
    }
  };
  append_edges(delaunay.edges, false);
  append_edges(delaunay.removed_edges, true);
  for (const auto& [a, b, c] : delaunay.triangles) {
    chunker.MakeRoom();
    v1::SiteTriple* t = chunker.current().add_triangles();
    t->set_a(a);
    t->set_b(b);
    t->set_c(c);
    chunker.Account(t->ByteSizeLong() + 2);
  }
  for (const XlEdge& xl : delaunay.xl_edges) {
    chunker.MakeRoom();
    v1::XlEdge* out = chunker.current().add_xl_edges();
    out->set_vertex_a(xl.vertex_a);
    out->set_vertex_b(xl.vertex_b);
    out->set_site_a(xl.site_a);
    out->set_site_b(xl.site_b);
    out->set_witness(xl.witness);
    PathPointToProto(xl.point, out->mutable_point());
    chunker.Account(out->ByteSizeLong() + 2);
  }
  return chunker.Take();
}

std::vector<v1::MeshGeometry> MeshGeometryToProto(const MeshData& mesh, size_t budget_bytes) {
  const size_t per_message = std::max<size_t>(1, budget_bytes / 8);  // doubles or ids per message
  std::vector<v1::MeshGeometry> out;
  auto next = [&]() -> v1::MeshGeometry& {
    out.emplace_back();
    out.back().set_vertex_count(mesh.vertex_count());
    out.back().set_face_count(mesh.face_count());
    return out.back();
  };
  for (size_t i = 0; i < mesh.positions.size(); i += per_message) {
    const size_t end = std::min(mesh.positions.size(), i + per_message);
    next().mutable_positions()->Add(mesh.positions.begin() + i, mesh.positions.begin() + end);
  }
  for (size_t i = 0; i < mesh.faces.size(); i += per_message) {
    const size_t end = std::min(mesh.faces.size(), i + per_message);
    next().mutable_faces()->Add(mesh.faces.begin() + i, mesh.faces.begin() + end);
  }
  if (out.empty()) next();
  return out;
}

void MeshGeometryAssembler::Add(const v1::MeshGeometry& message) {
  out_.positions.insert(out_.positions.end(), message.positions().begin(),
                        message.positions().end());
  out_.faces.insert(out_.faces.end(), message.faces().begin(), message.faces().end());
}

void IsolinesAssembler::Add(const v1::ComputeIsolinesResponse& message) {
  out_.levels.insert(out_.levels.end(), message.levels().begin(), message.levels().end());
  for (const v1::Isoline& piece : message.isolines()) {
    AddPiece(piece, &open_, &out_.polylines, [](const v1::Isoline& first) {
      IsolinePolyline line;
      line.level = first.level();
      line.closed = first.closed();
      return line;
    });
  }
}

void VoronoiAssembler::Add(const v1::ComputeVoronoiResponse& message) {
  if (first_) {
    out_.total_area = message.total_area();
    out_.junction_faces = message.junction_faces();
    for (const auto& pair : message.adjacency()) out_.adjacency.push_back({pair.a(), pair.b()});
    for (const auto& p : message.resolved_sources()) sources_.push_back(SurfacePointFromProto(p));
    first_ = false;
  }
  for (const v1::VoronoiCell& piece : message.cells()) {
    if (!cell_open_) {
      VoronoiCell cell;
      cell.site = piece.site();
      cell.area = piece.area();
      out_.cells.push_back(std::move(cell));
    }
    VoronoiCell& cell = out_.cells.back();
    cell.whole_faces.insert(cell.whole_faces.end(), piece.whole_faces().begin(),
                            piece.whole_faces().end());
    for (const v1::VoronoiFragment& f : piece.fragments()) {
      VoronoiFragment fragment;
      fragment.face = f.face();
      fragment.area = f.area();
      for (const auto& p : f.polygon()) fragment.polygon.push_back(PathPointFromProto(p));
      cell.fragments.push_back(std::move(fragment));
    }
    cell_open_ = piece.continued();
  }
  for (const v1::VoronoiBoundary& piece : message.boundaries()) {
    AddPiece(piece, &boundary_open_, &out_.boundaries, [](const v1::VoronoiBoundary& first) {
      VoronoiBoundary b;
      b.site_a = first.site_a();
      b.site_b = first.site_b();
      b.closed = first.closed();
      return b;
    });
  }
}

void DelaunayAssembler::Add(const v1::ComputeDelaunayResponse& message) {
  for (const auto& p : message.resolved_sources()) sources_.push_back(SurfacePointFromProto(p));
  for (const auto& piece : message.edges()) AddPiece(piece, &kept_open_, &out_.edges, EdgeHeader);
  for (const auto& piece : message.removed_edges()) {
    AddPiece(piece, &removed_open_, &out_.removed_edges, EdgeHeader);
  }
  for (const auto& t : message.triangles()) out_.triangles.push_back({t.a(), t.b(), t.c()});
  for (const auto& x : message.xl_edges()) {
    XlEdge xl;
    xl.vertex_a = x.vertex_a();
    xl.vertex_b = x.vertex_b();
    xl.site_a = x.site_a();
    xl.site_b = x.site_b();
    xl.witness = x.witness();
    xl.point = PathPointFromProto(x.point());
    out_.xl_edges.push_back(xl);
  }
}

}  // namespace geodex::api
