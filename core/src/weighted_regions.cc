// Travel costs by regions (weighted_regions.h): the union mesh, its links, and the point mapping.

#include "weighted_regions.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <optional>
#include <utility>

#include "absl/strings/str_format.h"
#include "geodex/mesh_data.h"
#include "ich/ich_solver.h"
#include "ich/region_links.h"
#include "mesh_lookup.h"
#include "path_trace.h"
#include "source_resolver.h"

namespace geodex {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

double Distance(const std::array<double, 3>& a, const std::array<double, 3>& b) {
  return std::hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);
}

}  // namespace

// The union of a surface's regions: one copy of a vertex per weight of the faces around it, each
// region's positions scaled by its weight (so its lengths are costs), faces in the surface's order
// (the impassable ones left out) and the surface's corner order.
struct RegionSurface::Impl {
 public:
  Impl(const TriangleMesh& mesh, const WeightedOptions& options) : mesh_(mesh), options_(options) {}

  bool empty() const { return union_ == nullptr; }      // every face impassable
  const TriangleMesh& mesh() const { return *union_; }  // the union (not empty())
  const TriangleMesh& surface() const { return mesh_; }
  double epsilon() const { return options_.epsilon; }
  uint64_t max_windows() const { return options_.max_windows; }
  const std::vector<double>& face_weight() const { return options_.face_weight; }
  const ich::RegionLinks& links() const { return links_; }
  uint64_t boundary_points() const { return links_.point_count(); }
  uint64_t bytes() const {
    auto of = [](const auto& v) { return uint64_t{v.capacity()} * sizeof(v[0]); };
    return sizeof(*this) + (union_ != nullptr ? union_->MemoryBytes() : 0) + links_.bytes() +
           of(options_.face_weight) + of(vertex_first_) + of(copy_weight_) + of(union_face_) +
           of(surface_face_) + of(surface_vertex_);
  }

  // The union's points standing for surface point p (a vertex: each copy; an edge point: one per
  // passable face on the edge; a face point: its face's), none when p is in impassable faces only.
  absl::Status Map(const SurfacePoint& p, std::vector<SurfacePoint>* out) const {
    out->clear();
    if (absl::Status s = ValidateSurfacePoint(mesh_, p); !s.ok()) return s;
    const SurfacePoint c = CanonicalPoint(mesh_, p);
    std::vector<uint32_t> list;
    switch (c.kind) {
      case SurfacePoint::Kind::kVertex:
        InternalCopies(mesh_, c.vertex, &list);
        for (const uint32_t v : list) {
          for (uint32_t i = vertex_first_[v]; i < vertex_first_[v + 1]; ++i) {
            out->push_back(SurfacePoint::AtVertex(i));
          }
        }
        break;
      case SurfacePoint::Kind::kEdge: {
        HalfEdgesOfFileEdge(mesh_, c.edge_from, c.edge_to, &list);
        if (list.empty()) {  // the resolvers' error, in the surface's ids
          return absl::InvalidArgumentError(
              absl::StrFormat("point %s: the mesh has no edge between vertices %d and %d",
                              SurfacePointToString(p), c.edge_from, c.edge_to));
        }
        bool degenerate_only = true;
        for (const uint32_t h : list) {
          const uint32_t f = TriangleMesh::FaceOf(h);
          if (Flat(f)) continue;
          degenerate_only = false;
          if (union_face_[f] == kNoIndex) continue;
          const double w = Weight(f);
          const bool forward = mesh_.FileVertex(mesh_.From(h)) == c.edge_from;
          out->push_back(SurfacePoint::OnEdge(Copy(mesh_.From(h), w), Copy(mesh_.To(h), w),
                                              forward ? c.t : 1 - c.t));
        }
        if (degenerate_only) {
          // On a zero-area face's edge: the same position on a neighbouring edge with area.
          if (const std::optional<SurfacePoint> on =
                  OnSegmentEdge(TriangleMesh::FaceOf(list[0]), Recentred(c))) {
            return Map(*on, out);
          }
          return absl::InvalidArgumentError(absl::StrFormat(
              "point %s: the edge %d-%d belongs only to degenerate (zero-area) faces",
              SurfacePointToString(p), c.edge_from, c.edge_to));
        }
        break;
      }
      case SurfacePoint::Kind::kFace:
        if (union_face_[c.face] == kNoIndex) break;
        // A zero-area face is a segment: its points are on its edges (the graph takes them too;
        // the exact engine places nothing inside such a face).
        if (Flat(c.face)) {
          const std::optional<SurfacePoint> on = OnSegmentEdge(c.face, Recentred(c));
          // None: every edge of it is of zero-area faces only (refused there, by name).
          const std::array<uint32_t, 3> k = mesh_.FileCorners(c.face);
          return Map(on.value_or(SurfacePoint::OnEdge(k[0], k[1], 0.5)), out);
        }
        out->push_back(SurfacePoint::InFace(union_face_[c.face], c.bary[0], c.bary[1], c.bary[2]));
        break;
      case SurfacePoint::Kind::kPosition:
        break;  // rejected by ValidateSurfacePoint
    }
    return absl::OkStatus();
  }

  // Whether surface face f has zero area as the engine sees it (the union's flag where it has
  // the face: its positions are scaled).
  bool Flat(uint32_t f) const {
    return union_face_[f] != kNoIndex ? union_->FaceDegenerate(union_face_[f])
                                      : mesh_.FaceDegenerate(f);
  }

  // A position `at` on zero-area face f (a segment) as the nearest point of one of its edges that
  // has a face of some area (the position lies on two of the three edges); none if none has.
  std::optional<SurfacePoint> OnSegmentEdge(uint32_t f, const std::array<double, 3>& at) const {
    const std::array<uint32_t, 3> k = mesh_.FileCorners(f);
    std::vector<uint32_t> halves;
    std::optional<SurfacePoint> nearest;
    double nearest_gap = kInf;
    for (int i = 0; i < 3; ++i) {
      const uint32_t u = k[i], v = k[(i + 1) % 3];
      HalfEdgesOfFileEdge(mesh_, u, v, &halves);
      bool has_area = false;
      for (const uint32_t h : halves) has_area |= !Flat(TriangleMesh::FaceOf(h));
      const std::array<double, 3> a = mesh_.Position(u), b = mesh_.Position(v);
      const double len = Distance(a, b);
      if (!has_area || len == 0) continue;
      double t = 0;
      for (int j = 0; j < 3; ++j) t += (at[j] - a[j]) * (b[j] - a[j]);
      t = std::clamp(t / (len * len), 0.0, 1.0);
      std::array<double, 3> foot;
      for (int j = 0; j < 3; ++j) foot[j] = a[j] + t * (b[j] - a[j]);
      if (Distance(at, foot) < nearest_gap) {
        nearest = CanonicalPoint(mesh_, SurfacePoint::OnEdge(u, v, t));
        nearest_gap = Distance(at, foot);
      }
    }
    return nearest;
  }

  // A point of the union (file terms), named on the surface, and its position there (file
  // coordinates).
  SurfacePoint Back(const SurfacePoint& p) const {
    auto vertex = [&](uint32_t union_file) {
      return mesh_.FileVertex(surface_vertex_[union_file]);
    };
    switch (p.kind) {
      case SurfacePoint::Kind::kVertex:
        return SurfacePoint::AtVertex(vertex(p.vertex));
      case SurfacePoint::Kind::kEdge:
        return SurfacePoint::OnEdge(vertex(p.edge_from), vertex(p.edge_to), p.t);
      case SurfacePoint::Kind::kFace:
        return SurfacePoint::InFace(surface_face_[p.face], p.bary[0], p.bary[1], p.bary[2]);
      case SurfacePoint::Kind::kPosition:
        break;
    }
    return p;
  }
  std::array<double, 3> PositionOn(const SurfacePoint& p) const {
    std::array<double, 3> out = Recentred(p);
    for (int k = 0; k < 3; ++k) out[k] += mesh_.Center()[k];
    return out;
  }
  // Surface point p's position in the mesh's own (recentred) coordinates, as Position gives.
  std::array<double, 3> Recentred(const SurfacePoint& p) const {
    std::array<double, 3> out{0, 0, 0};
    auto add = [&](uint32_t file_vertex, double w) {
      const std::array<double, 3> q = mesh_.Position(file_vertex);
      for (int k = 0; k < 3; ++k) out[k] += w * q[k];
    };
    if (p.kind == SurfacePoint::Kind::kVertex) add(p.vertex, 1);
    if (p.kind == SurfacePoint::Kind::kEdge) {
      add(p.edge_from, 1 - p.t);
      add(p.edge_to, p.t);
    }
    if (p.kind == SurfacePoint::Kind::kFace) {
      const std::array<uint32_t, 3> c = mesh_.FileCorners(p.face);
      for (int k = 0; k < 3; ++k) add(c[k], p.bary[k]);
    }
    return out;
  }

  // The cost of surface vertex v (internal id) in a finished field over the union.
  double VertexCost(const std::vector<double>& dist, uint32_t v, uint32_t* label,
                    const std::vector<uint32_t>& labels) const {
    double best = kInf;
    for (uint32_t i = vertex_first_[v]; i < vertex_first_[v + 1]; ++i) {
      if (dist[i] < best) {
        best = dist[i];
        *label = labels[i];
      }
    }
    return best;
  }

  double Weight(uint32_t f) const {
    return options_.face_weight.empty() ? 1.0 : options_.face_weight[f];
  }
  // The union's (file) vertex copying surface vertex v in the region of weight w.
  uint32_t Copy(uint32_t v, double w) const {
    for (uint32_t i = vertex_first_[v]; i < vertex_first_[v + 1]; ++i) {
      if (copy_weight_[i] == w) return i;
    }
    return kNoIndex;  // not reached: every passable face's corners have their copy
  }

  absl::Status Make(const std::vector<SurfacePoint>& anchors) {
    const uint32_t nf = mesh_.face_count(), nv = mesh_.vertex_count();
    // Copies: per vertex, the distinct weights of its passable faces, in increasing order.
    std::vector<std::pair<uint32_t, double>> pairs;
    pairs.reserve(3 * size_t{nf});
    for (uint32_t f = 0; f < nf; ++f) {
      const double w = Weight(f);
      if (!std::isfinite(w)) continue;
      for (int k = 0; k < 3; ++k) pairs.push_back({mesh_.FaceVertex(f, k), w});
    }
    std::sort(pairs.begin(), pairs.end());
    pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
    vertex_first_.assign(nv + 1, 0);
    for (const auto& [v, w] : pairs) ++vertex_first_[v + 1];
    for (uint32_t v = 0; v < nv; ++v) vertex_first_[v + 1] += vertex_first_[v];
    MeshData data;
    data.positions.resize(3 * pairs.size());
    copy_weight_.resize(pairs.size());
    std::vector<uint32_t>& surface_vertex = surface_vertex_;
    surface_vertex.resize(pairs.size());
    for (uint32_t i = 0; i < pairs.size(); ++i) {
      const auto [v, w] = pairs[i];
      copy_weight_[i] = w;
      surface_vertex[i] = v;
      const double* p = mesh_.positions() + 3 * size_t{v};
      for (int k = 0; k < 3; ++k) data.positions[3 * size_t{i} + k] = w * p[k];
    }
    union_face_.assign(nf, kNoIndex);
    for (uint32_t f = 0; f < nf; ++f) {
      const double w = Weight(f);
      if (!std::isfinite(w)) continue;
      std::array<uint32_t, 3> corners{mesh_.FaceVertex(f, 0), mesh_.FaceVertex(f, 1),
                                      mesh_.FaceVertex(f, 2)};
      mesh_.SwapCornerOrder(f, &corners);  // the file's corner order, as face points give it
      union_face_[f] = static_cast<uint32_t>(data.faces.size() / 3);
      surface_face_.push_back(f);
      for (const uint32_t v : corners) data.faces.push_back(Copy(v, w));
    }
    if (data.faces.empty()) return absl::OkStatus();  // nothing passable: nothing is reached
    absl::StatusOr<TriangleMesh> built = TriangleMesh::Build(data);
    if (!built.ok()) return built.status();
    union_ = std::make_unique<TriangleMesh>(*std::move(built));
    const TriangleMesh& u = *union_;

    // The ring of copies of each surface vertex (the union's own non-manifold copies included).
    const uint32_t nu = u.vertex_count();
    std::vector<uint32_t> of(nu);
    for (uint32_t i = 0; i < nu; ++i) of[i] = surface_vertex[u.FileVertex(i)];
    links_.next_copy.resize(nu);
    std::vector<uint32_t> last(nv, kNoIndex), head(nv, kNoIndex);
    for (uint32_t i = 0; i < nu; ++i) {
      const uint32_t v = of[i];
      if (head[v] == kNoIndex) head[v] = i;
      if (last[v] != kNoIndex) links_.next_copy[last[v]] = i;
      last[v] = i;
    }
    for (uint32_t v = 0; v < nv; ++v) {
      if (last[v] != kNoIndex) links_.next_copy[last[v]] = head[v];
    }

    // The boundary points, and the union half-edges they lie on.
    absl::StatusOr<RegionBoundaryPoints> points =
        PlaceRegionBoundaryPoints(mesh_, options_, anchors);
    if (!points.ok()) return points.status();
    links_.chain_of_half.assign(3 * size_t{u.face_count()}, kNoIndex);
    links_.chain_reversed.assign(3 * size_t{u.face_count()}, 0);
    links_.chain_first.push_back(0);
    for (size_t k = 0; k + 1 < points->first.size(); ++k) {
      const uint32_t h0 = points->half_edge[k];
      const uint32_t a = mesh_.From(h0), b = mesh_.To(h0);
      std::array<uint32_t, 2> halves{kNoIndex, kNoIndex};
      const uint32_t c = static_cast<uint32_t>(links_.chain_cost.size());
      int side = 0;
      for (const uint32_t h : {h0, mesh_.Twin(h0)}) {
        const uint32_t uf = union_face_[TriangleMesh::FaceOf(h)];
        for (uint32_t e = 3 * uf; e < 3 * uf + 3; ++e) {
          const uint32_t from = of[u.From(e)], to = of[u.To(e)];
          if (u.Twin(e) != kNoIndex || !((from == a && to == b) || (from == b && to == a))) {
            continue;
          }
          halves[side] = e;
          links_.chain_of_half[e] = c;
          links_.chain_reversed[e] = from == b;
        }
        ++side;
      }
      links_.chain_halves.push_back(halves);
      const std::array<double, 2> side_cost{
          Weight(TriangleMesh::FaceOf(h0)) * mesh_.Length(h0),
          Weight(TriangleMesh::FaceOf(mesh_.Twin(h0))) * mesh_.Length(h0)};
      links_.side_cost.push_back(side_cost);
      links_.chain_cost.push_back(std::min(side_cost[0], side_cost[1]));
      for (uint32_t i = points->first[k]; i < points->first[k + 1]; ++i) {
        links_.point_param.push_back(points->param[i]);
        links_.point_chain.push_back(c);
      }
      links_.chain_first.push_back(links_.point_count());
    }
    return absl::OkStatus();
  }

  const TriangleMesh& mesh_;
  const WeightedOptions options_;
  std::unique_ptr<TriangleMesh> union_;
  ich::RegionLinks links_;
  std::vector<uint32_t> vertex_first_;    // surface vertex v's copies: [first[v], first[v + 1])
  std::vector<double> copy_weight_;       // per copy
  std::vector<uint32_t> union_face_;      // per surface face (kNoIndex: impassable)
  std::vector<uint32_t> surface_face_;    // per union face
  std::vector<uint32_t> surface_vertex_;  // per union file vertex: the surface's internal vertex
};

namespace {

// The sources as the union's, and those it has no copy of: a vertex whose faces are all
// impassable is still where its source stands (cost 0 there, as on the graph), reaching nothing.
struct UnionSourceSet {
  std::vector<ich::ResolvedSource> resolved;
  std::vector<std::pair<uint32_t, uint32_t>> stranded;  // (file vertex, label)
};

absl::StatusOr<UnionSourceSet> UnionSources(const RegionSurface::Impl& regions,
                                            const std::vector<SurfacePoint>& sources) {
  if (sources.empty()) return absl::InvalidArgumentError("no sources given");
  UnionSourceSet out;
  std::vector<SurfacePoint> mapped;
  std::optional<SourceResolver> resolver;
  if (!regions.empty()) resolver.emplace(regions.mesh());
  for (uint32_t i = 0; i < sources.size(); ++i) {
    if (absl::Status s = regions.Map(sources[i], &mapped); !s.ok()) return s;
    if (mapped.empty()) {
      const SurfacePoint c = CanonicalPoint(regions.surface(), sources[i]);
      if (c.kind == SurfacePoint::Kind::kVertex) out.stranded.push_back({c.vertex, i});
      continue;
    }
    for (const SurfacePoint& p : mapped) {
      if (absl::Status s = resolver->Add(p, i); !s.ok()) return s;
    }
  }
  if (resolver.has_value()) out.resolved = resolver->sources();
  return out;
}

// Each target as one engine target over all the union's points standing for it; `first` (if
// given) receives the first of those points (kNoIndex vertex: none).
absl::Status UnionTargets(const RegionSurface::Impl& regions,
                          const std::vector<SurfacePoint>& targets,
                          std::vector<ich::ResolvedTarget>* resolved,
                          std::vector<SurfacePoint>* first) {
  resolved->assign(targets.size(), {});
  if (first != nullptr) first->assign(targets.size(), SurfacePoint::AtVertex(kNoIndex));
  std::vector<SurfacePoint> mapped;
  for (size_t t = 0; t < targets.size(); ++t) {
    if (absl::Status s = regions.Map(targets[t], &mapped); !s.ok()) return s;
    if (regions.empty() || mapped.empty()) continue;
    if (first != nullptr) (*first)[t] = mapped[0];
    SourceResolver resolver(regions.mesh());
    for (const SurfacePoint& p : mapped) {
      if (absl::Status s = resolver.Add(p, 0); !s.ok()) return s;
    }
    for (const ich::ResolvedSource& r : resolver.sources()) {
      if (r.is_vertex) {
        (*resolved)[t].vertices.push_back(r.vertex);
      } else {
        (*resolved)[t].placements.push_back({r.face, r.px, r.py});
      }
    }
  }
  return absl::OkStatus();
}

// The label of the stranded source at target point p, if any (cost 0 there).
std::optional<uint32_t> StrandedAt(const TriangleMesh& surface, const UnionSourceSet& sources,
                                   const SurfacePoint& p) {
  if (sources.stranded.empty()) return std::nullopt;
  const SurfacePoint c = CanonicalPoint(surface, p);
  if (c.kind != SurfacePoint::Kind::kVertex) return std::nullopt;
  for (const auto& [vertex, label] : sources.stranded) {
    if (vertex == c.vertex) return label;
  }
  return std::nullopt;
}

// The exact engine over the union, its copies linked, under the caller's limits. Not empty().
class UnionSolver {
 public:
  UnionSolver(const RegionSurface::Impl& regions, const WeightedSurface::Limits& limits)
      : options_(OptionsFor(regions, limits)), solver_(regions.mesh(), options_) {
    solver_.set_regions(&regions.links());
  }
  ich::IchSolver& operator*() { return solver_; }
  ich::IchSolver* operator->() { return &solver_; }

 private:
  static GeodesicOptions OptionsFor(const RegionSurface::Impl& regions,
                                    const WeightedSurface::Limits& limits) {
    GeodesicOptions g;
    g.method = Method::kExact;
    g.max_distance = limits.max_distance;
    g.cancel = limits.cancel;
    g.max_windows = regions.max_windows();
    return g;
  }
  const GeodesicOptions options_;  // before solver_, which keeps a reference to it
  ich::IchSolver solver_;
};

double Since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

void CopyStats(const SolveStats& s, WeightedStats* out) {
  out->nodes_settled = s.windows_processed + s.pseudo_sources;
  out->edge_relaxations = s.windows_created;
  out->peak_bytes = s.peak_bytes;
}

}  // namespace

bool OneFiniteWeight(const std::vector<double>& weights) {
  double weight = kInf;
  for (const double w : weights) {
    if (!std::isfinite(w)) continue;
    if (std::isfinite(weight) && w != weight) return false;
    weight = w;
  }
  return true;
}

bool RegionsServe(const WeightedOptions& options) {
  return options.slope_cost == nullptr && OneFiniteWeight(options.face_weight);
}

bool RegionsServeFields(const WeightedOptions& options) { return options.slope_cost == nullptr; }

bool RegionsServeSeveralWeights(const WeightedOptions& options) {
  return RegionsServeFields(options) && !RegionsServe(options);
}

RegionSurface::RegionSurface(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
RegionSurface::~RegionSurface() = default;

absl::StatusOr<std::shared_ptr<const RegionSurface>> RegionSurface::Build(
    const TriangleMesh& mesh, const WeightedOptions& options,
    const std::vector<SurfacePoint>& anchors) {
  if (absl::Status s = ValidateWeightedOptions(mesh, options); !s.ok()) return s;
  auto impl = std::make_unique<Impl>(mesh, options);
  if (absl::Status s = impl->Make(anchors); !s.ok()) return s;
  return std::shared_ptr<const RegionSurface>(new RegionSurface(std::move(impl)));
}

uint64_t RegionSurface::boundary_points() const { return impl_->boundary_points(); }

uint64_t RegionSurface::bytes() const { return impl_->bytes(); }

const std::vector<double>& RegionSurface::face_weight() const { return impl_->face_weight(); }

absl::StatusOr<WeightedField> RegionSurface::Field(const std::vector<SurfacePoint>& sources,
                                                   const WeightedSurface::Limits& limits) const {
  const auto start = std::chrono::steady_clock::now();
  absl::StatusOr<UnionSourceSet> src = UnionSources(*impl_, sources);
  if (!src.ok()) return src.status();
  DistanceField field;
  if (!impl_->empty()) {
    UnionSolver solver(*impl_, limits);
    if (absl::Status s = solver->Solve(src->resolved, &field); !s.ok()) return s;
  }
  const TriangleMesh& mesh = impl_->surface();
  WeightedField out;
  out.epsilon = impl_->epsilon();
  out.steiner_points = impl_->boundary_points();
  const uint32_t nfile = mesh.file_vertex_count();
  out.cost.assign(nfile, kInf);
  out.source.assign(nfile, kNoIndex);
  for (uint32_t v = 0; v < mesh.vertex_count(); ++v) {
    uint32_t label = kNoIndex;
    const double c = impl_->empty() ? kInf
                                    : impl_->VertexCost(field.internal_distance, v, &label,
                                                        field.internal_source);
    const uint32_t fv = mesh.FileVertex(v);
    if (c < out.cost[fv]) {
      out.cost[fv] = c;
      out.source[fv] = label;
    }
  }
  for (const auto& [vertex, label] : src->stranded) {
    if (out.cost[vertex] > 0) {  // the first such source, as the engine labels ties
      out.cost[vertex] = 0;
      out.source[vertex] = label;
    }
  }
  CopyStats(field.stats, &out.stats);
  out.stats.solve_ms = Since(start);
  return out;
}

absl::StatusOr<WeightedCosts> RegionSurface::CostsAt(const std::vector<SurfacePoint>& sources,
                                                     const std::vector<SurfacePoint>& targets,
                                                     bool whole,
                                                     const WeightedSurface::Limits& limits) const {
  const auto start = std::chrono::steady_clock::now();
  absl::StatusOr<UnionSourceSet> src = UnionSources(*impl_, sources);
  if (!src.ok()) return src.status();
  std::vector<ich::ResolvedTarget> resolved;
  if (absl::Status s = UnionTargets(*impl_, targets, &resolved, nullptr); !s.ok()) return s;
  std::vector<ich::TargetResult> results(targets.size());
  SolveStats stats;
  if (!impl_->empty()) {
    UnionSolver solver(*impl_, limits);
    if (absl::Status s = solver->SolveForTargets(src->resolved, resolved, /*use_heuristic=*/false,
                                                 /*stop_early=*/!whole, &results, &stats);
        !s.ok()) {
      return s;
    }
  }
  WeightedCosts out;
  out.steiner_points = impl_->boundary_points();
  out.cost.assign(targets.size(), kInf);
  out.source.assign(targets.size(), kNoIndex);
  for (size_t t = 0; t < targets.size(); ++t) {
    if (const std::optional<uint32_t> label = StrandedAt(impl_->surface(), *src, targets[t])) {
      out.cost[t] = 0;
      out.source[t] = *label;
      continue;
    }
    out.cost[t] = results[t].distance;
    out.source[t] = std::isfinite(results[t].distance) ? results[t].label : kNoIndex;
  }
  CopyStats(stats, &out.stats);
  out.stats.solve_ms = Since(start);
  return out;
}

absl::StatusOr<std::vector<WeightedPath>> RegionSurface::Paths(
    const SurfacePoint& from, const std::vector<SurfacePoint>& tos,
    const WeightedSurface::Limits& limits) const {
  const auto start = std::chrono::steady_clock::now();
  absl::StatusOr<UnionSourceSet> src = UnionSources(*impl_, {from});
  if (!src.ok()) return src.status();
  std::vector<ich::ResolvedTarget> resolved;
  std::vector<SurfacePoint> first;
  if (absl::Status s = UnionTargets(*impl_, tos, &resolved, &first); !s.ok()) return s;
  std::vector<WeightedPath> out(tos.size());
  for (size_t i = 0; i < tos.size(); ++i) {
    out[i].cost = kInf;
    if (StrandedAt(impl_->surface(), *src, tos[i]).has_value()) {  // from itself, going nowhere
      out[i].cost = 0;
      PathPoint p;
      p.where = tos[i];
      p.position = impl_->PositionOn(CanonicalPoint(impl_->surface(), tos[i]));
      out[i].points = {p, p};
    }
  }
  if (impl_->empty()) return out;
  std::vector<ich::TargetResult> results;
  SolveStats stats;
  UnionSolver solver(*impl_, limits);
  if (absl::Status s = solver->SolveForTargets(src->resolved, resolved, /*use_heuristic=*/false,
                                               /*stop_early=*/true, &results, &stats);
      !s.ok()) {
    return s;
  }
  // Traced back through the boundary points where they cross regions: the path's cost is the
  // solve's, the field's at its end.
  const VertexPaths paths{solver->distances().data(), solver->origins().data(),
                          solver->point_origins().data(), &impl_->links()};
  for (size_t i = 0; i < tos.size(); ++i) {
    if (!std::isfinite(results[i].distance) || out[i].cost == 0) continue;
    absl::StatusOr<GeodesicPath> traced =
        TraceFromTarget(impl_->mesh(), paths, results[i], first[i]);
    if (absl::IsNotFound(traced.status())) continue;
    if (!traced.ok()) return traced.status();
    WeightedPath& path = out[i];
    path.cost = results[i].distance;
    // The trace runs from the target back: walk it from `from`, named on the surface, without
    // the repeats where it passes from one copy of a vertex to another.
    for (auto it = traced->points.rbegin(); it != traced->points.rend(); ++it) {
      PathPoint p;
      p.where = impl_->Back(it->where);
      p.position = impl_->PositionOn(p.where);
      if (!path.points.empty() && path.points.back().position == p.position) continue;
      path.points.push_back(p);
    }
    if (path.points.empty()) continue;
    path.points.front().where = from;
    path.points.back().where = tos[i];
    CopyStats(stats, &path.stats);
    path.stats.solve_ms = Since(start);
  }
  return out;
}

}  // namespace geodex
