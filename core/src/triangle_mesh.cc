#include "geodex/triangle_mesh.h"

#include <sys/mman.h>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "absl/status/status.h"
#include "absl/strings/str_format.h"
#include "ich/solve_workspace.h"

namespace geodex {
namespace {

constexpr double kTwoPi = 6.283185307179586476925286766559;
// A vertex whose angle sum is within this of 2*pi counts as a saddle: an extra pseudo-source only
// costs time, a missed saddle costs exactness. Angle sums carry ~1e-15 of round-off.
constexpr double kSaddleAngleTolerance = 1e-9;
// A face whose smallest height is below this fraction of its longest edge is degenerate.
constexpr double kDegenerateRelativeHeight = 1e-12;

// Union-find with path halving; small and allocation-free after construction.
class DisjointSets {
 public:
  explicit DisjointSets(size_t n) : parent_(n) { std::iota(parent_.begin(), parent_.end(), 0u); }
  uint32_t Find(uint32_t x) {
    while (parent_[x] != x) x = parent_[x] = parent_[parent_[x]];
    return x;
  }
  void Union(uint32_t a, uint32_t b) {
    a = Find(a);
    b = Find(b);
    if (a != b) parent_[std::max(a, b)] = std::min(a, b);  // deterministic roots
  }

 private:
  std::vector<uint32_t> parent_;
};

double Dist3(const double* a, const double* b) {
  const double dx = a[0] - b[0], dy = a[1] - b[1], dz = a[2] - b[2];
  return std::sqrt(dx * dx + dy * dy + dz * dz);
}

// Angle at corner a of triangle (a, b, c), robust for tiny or degenerate triangles.
double CornerAngleAt(const double* a, const double* b, const double* c) {
  const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  const double w[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  const double cx = u[1] * w[2] - u[2] * w[1];
  const double cy = u[2] * w[0] - u[0] * w[2];
  const double cz = u[0] * w[1] - u[1] * w[0];
  const double cross = std::sqrt(cx * cx + cy * cy + cz * cz);
  const double dot = u[0] * w[0] + u[1] * w[1] + u[2] * w[2];
  if (cross == 0 && dot == 0) return 0;  // zero-length edge
  return std::atan2(cross, dot);
}

}  // namespace

// Builds a TriangleMesh in passes; each pass is one private method so the order reads as the plan.
class MeshBuilder {
 public:
  MeshBuilder(const MeshData& data, const MeshBuildOptions& options)
      : data_(data), options_(options) {}

  absl::StatusOr<TriangleMesh> Run() {
    if (absl::Status s = Validate(); !s.ok()) return s;
    Recentre();
    MarkDegenerateFaces();
    if (absl::Status s = PairEdges(); !s.ok()) return s;
    if (absl::Status s = Orient(); !s.ok()) return s;
    if (absl::Status s = SplitNonManifoldVertices(); !s.ok()) return s;
    ComputeGeometry();
    ComputeVertexRings();
    ComputeComponentsAndBoundary();
    PackHalfEdges();
    return std::move(m_);
  }

 private:
  // Half-edge topology while building (the mesh's own accessors read the packed records, which
  // exist only at the end).
  uint32_t From(uint32_t h) const { return m_.faces_[h]; }
  uint32_t To(uint32_t h) const { return m_.faces_[TriangleMesh::Next(h)]; }
  uint32_t Opposite(uint32_t h) const { return m_.faces_[TriangleMesh::Prev(h)]; }

  void PackHalfEdges() {
    const uint32_t nh = 3 * m_.face_count();
    // The engine reads these records at random: ask for transparent huge pages before the first
    // touch (a large vector's buffer is a fresh mapping), so those reads rarely miss the TLB.
    m_.half_edges_.reserve(nh);
#ifdef MADV_HUGEPAGE
    {
      constexpr uintptr_t kHuge = uintptr_t{1} << 21;
      const uintptr_t begin = reinterpret_cast<uintptr_t>(m_.half_edges_.data());
      const uintptr_t end = begin + uintptr_t{nh} * sizeof(TriangleMesh::HalfEdge);
      const uintptr_t lo = (begin + kHuge - 1) & ~(kHuge - 1), hi = end & ~(kHuge - 1);
      if (hi > lo) madvise(reinterpret_cast<void*>(lo), hi - lo, MADV_HUGEPAGE);
    }
#endif
    m_.half_edges_.resize(nh);
    for (uint32_t h = 0; h < nh; ++h) {
      TriangleMesh::HalfEdge& r = m_.half_edges_[h];
      r.length = length_[h];
      r.opp_x = opp_x_[h];
      r.opp_y = opp_y_[h];
      r.twin = twin_[h];
      r.from = m_.faces_[h];
    }
  }
  absl::Status Validate() {
    const size_t nv = data_.vertex_count(), nf = data_.face_count();
    if (data_.positions.size() % 3 != 0 || data_.faces.size() % 3 != 0) {
      return absl::InvalidArgumentError("mesh arrays are not multiples of 3");
    }
    if (nv == 0 || nf == 0) {
      return absl::InvalidArgumentError(
          absl::StrFormat("empty mesh: %d vertices, %d faces", nv, nf));
    }
    if (nv >= kNoIndex / 2 || nf >= kNoIndex / 4) {
      return absl::ResourceExhaustedError(
          absl::StrFormat("mesh too large: %d vertices, %d faces", nv, nf));
    }
    for (size_t i = 0; i < data_.positions.size(); ++i) {
      if (!std::isfinite(data_.positions[i])) {
        return absl::InvalidArgumentError(absl::StrFormat(
            "vertex %d has a non-finite coordinate (%g)", i / 3, data_.positions[i]));
      }
    }
    for (size_t f = 0; f < nf; ++f) {
      const uint32_t* c = &data_.faces[3 * f];
      for (int k = 0; k < 3; ++k) {
        if (c[k] >= nv) {
          return absl::InvalidArgumentError(absl::StrFormat(
              "face %d references vertex %d, but the mesh has %d vertices", f, c[k], nv));
        }
      }
      if (c[0] == c[1] || c[1] == c[2] || c[0] == c[2]) {
        return absl::InvalidArgumentError(
            absl::StrFormat("face %d repeats a vertex (%d %d %d)", f, c[0], c[1], c[2]));
      }
    }
    m_.file_vertex_count_ = static_cast<uint32_t>(nv);
    m_.faces_ = data_.faces;
    m_.face_flags_.assign(nf, 0);
    m_.report_.file_vertices = nv;
    m_.report_.file_faces = nf;
    return absl::OkStatus();
  }

  void Recentre() {
    const size_t nv = data_.vertex_count();
    std::array<double, 3> lo, hi;
    for (int a = 0; a < 3; ++a) lo[a] = hi[a] = data_.positions[a];
    for (size_t v = 0; v < nv; ++v) {
      for (int a = 0; a < 3; ++a) {
        lo[a] = std::min(lo[a], data_.positions[3 * v + a]);
        hi[a] = std::max(hi[a], data_.positions[3 * v + a]);
      }
    }
    for (int a = 0; a < 3; ++a) m_.center_[a] = 0.5 * (lo[a] + hi[a]);
    m_.bounds_min_ = lo;
    m_.bounds_max_ = hi;
    m_.positions_.resize(data_.positions.size());
    for (size_t v = 0; v < nv; ++v) {
      for (int a = 0; a < 3; ++a) {
        m_.positions_[3 * v + a] = data_.positions[3 * v + a] - m_.center_[a];
      }
    }
  }

  void MarkDegenerateFaces() {
    const uint32_t nf = m_.face_count();
    for (uint32_t f = 0; f < nf; ++f) {
      const double* p[3];
      for (int k = 0; k < 3; ++k) p[k] = &m_.positions_[3 * m_.faces_[3 * f + k]];
      const double e0 = Dist3(p[0], p[1]), e1 = Dist3(p[1], p[2]), e2 = Dist3(p[2], p[0]);
      const double longest = std::max({e0, e1, e2});
      // Twice the area via the cross product, then the height over the longest edge.
      const double u[3] = {p[1][0] - p[0][0], p[1][1] - p[0][1], p[1][2] - p[0][2]};
      const double w[3] = {p[2][0] - p[0][0], p[2][1] - p[0][1], p[2][2] - p[0][2]};
      const double cx = u[1] * w[2] - u[2] * w[1], cy = u[2] * w[0] - u[0] * w[2],
                   cz = u[0] * w[1] - u[1] * w[0];
      const double twice_area = std::sqrt(cx * cx + cy * cy + cz * cz);
      if (longest == 0 || twice_area / longest <= kDegenerateRelativeHeight * longest) {
        m_.face_flags_[f] |= TriangleMesh::kFaceDegenerate;
        ++m_.report_.degenerate_faces;
      }
    }
  }

  // Groups half-edges by undirected edge (bucketed by the smaller vertex, O(F)). Edges with exactly
  // two faces become twin candidates; one face is boundary; more are non-manifold and stay cut.
  absl::Status PairEdges() {
    const uint32_t nh = 3 * m_.face_count();
    const uint32_t nv = m_.file_vertex_count_;
    std::vector<uint32_t> offsets(nv + 1, 0);
    auto lo_of = [&](uint32_t h) { return std::min(From(h), To(h)); };
    auto hi_of = [&](uint32_t h) { return std::max(From(h), To(h)); };
    for (uint32_t h = 0; h < nh; ++h) ++offsets[lo_of(h) + 1];
    for (uint32_t v = 0; v < nv; ++v) offsets[v + 1] += offsets[v];
    std::vector<uint32_t> bucket(nh), fill(offsets.begin(), offsets.end() - 1);
    for (uint32_t h = 0; h < nh; ++h) bucket[fill[lo_of(h)]++] = h;
    candidate_.assign(nh, kNoIndex);
    std::vector<uint32_t> group;
    for (uint32_t v = 0; v < nv; ++v) {
      uint32_t* b = bucket.data() + offsets[v];
      uint32_t* e = bucket.data() + offsets[v + 1];
      // Small buckets (vertex degree): sort by the other endpoint, then walk groups.
      std::sort(b, e, [&](uint32_t x, uint32_t y) {
        return hi_of(x) != hi_of(y) ? hi_of(x) < hi_of(y) : x < y;
      });
      for (uint32_t* g = b; g != e;) {
        uint32_t* g_end = g + 1;
        while (g_end != e && hi_of(*g_end) == hi_of(*g)) ++g_end;
        const size_t n = g_end - g;
        if (n == 1) {
          ++m_.report_.boundary_edges;
        } else if (n == 2) {
          candidate_[g[0]] = g[1];
          candidate_[g[1]] = g[0];
        } else {
          ++m_.report_.non_manifold_edges;
          if (options_.strict) {
            return absl::InvalidArgumentError(absl::StrFormat(
                "non-manifold edge %d-%d is shared by %d faces (strict mode)", v, hi_of(*g), n));
          }
        }
        g = g_end;
      }
    }
    return absl::OkStatus();
  }

  // Breadth-first over faces: a neighbour whose shared edge runs the same way gets flipped; a
  // conflict (non-orientable, e.g. a Moebius strip) cuts that edge instead.
  absl::Status Orient() {
    const uint32_t nf = m_.face_count();
    std::vector<int8_t> flip(nf, -1);
    std::vector<uint32_t> queue;
    queue.reserve(nf);
    for (uint32_t seed = 0; seed < nf; ++seed) {
      if (flip[seed] >= 0) continue;
      flip[seed] = 0;
      queue.clear();
      queue.push_back(seed);
      for (size_t qi = 0; qi < queue.size(); ++qi) {
        const uint32_t f = queue[qi];
        for (int k = 0; k < 3; ++k) {
          const uint32_t h = 3 * f + k, t = candidate_[h];
          if (t == kNoIndex) continue;
          const uint32_t g = t / 3;
          const bool same_direction = From(h) == From(t);
          const int8_t want = static_cast<int8_t>(flip[f] ^ (same_direction ? 1 : 0));
          if (flip[g] < 0) {
            flip[g] = want;
            queue.push_back(g);
          } else if (flip[g] != want) {
            if (options_.strict) {
              return absl::InvalidArgumentError(absl::StrFormat(
                  "faces %d and %d cannot be oriented consistently (strict mode)", f, g));
            }
            candidate_[h] = candidate_[t] = kNoIndex;
            ++m_.report_.orientation_cuts;
          }
        }
      }
    }
    // Apply flips (swap corners 1 and 2: local edge k becomes 2-k) and set twins.
    twin_.assign(3 * nf, kNoIndex);
    auto remap = [&](uint32_t h) {
      const uint32_t f = h / 3, k = h % 3;
      return flip[f] ? 3 * f + (2 - k) : h;
    };
    for (uint32_t h = 0; h < 3 * nf; ++h) {
      if (candidate_[h] != kNoIndex) twin_[remap(h)] = remap(candidate_[h]);
    }
    for (uint32_t f = 0; f < nf; ++f) {
      if (flip[f]) {
        std::swap(m_.faces_[3 * f + 1], m_.faces_[3 * f + 2]);
        m_.face_flags_[f] |= TriangleMesh::kFaceFlipped;
        ++m_.report_.flipped_faces;
      }
    }
    if (m_.report_.flipped_faces > 0 && options_.strict) {
      return absl::InvalidArgumentError(absl::StrFormat(
          "inconsistent face orientation: %d faces would need flipping (strict mode)",
          m_.report_.flipped_faces));
    }
    candidate_.clear();
    candidate_.shrink_to_fit();
    return absl::OkStatus();
  }

  // Corners around a vertex joined through twins form fans; a vertex with several fans is cut into
  // one internal vertex per fan (the first keeps the file id).
  absl::Status SplitNonManifoldVertices() {
    const uint32_t nh = 3 * m_.face_count();
    DisjointSets fans(nh);  // one element per corner (corner c sits at vertex faces_[c])
    for (uint32_t h = 0; h < nh; ++h) {
      const uint32_t t = twin_[h];
      if (t == kNoIndex || t < h) continue;
      // h: a->b, t: b->a. Corner of h's start (a) pairs with corner of t's end (a).
      fans.Union(h, TriangleMesh::Next(t));
      fans.Union(TriangleMesh::Next(h), t);
    }
    const uint32_t nv = m_.file_vertex_count_;
    std::vector<uint32_t> first_root(nv, kNoIndex);
    std::vector<uint32_t> root_vertex(nh, kNoIndex);  // fan root -> internal vertex id
    std::vector<uint8_t> split_counted(nv, 0);
    uint32_t next_id = nv;
    for (uint32_t c = 0; c < nh; ++c) {
      const uint32_t v = m_.faces_[c];
      const uint32_t r = fans.Find(c);
      if (first_root[v] == kNoIndex) {
        first_root[v] = r;
        root_vertex[r] = v;
      } else if (root_vertex[r] == kNoIndex) {
        if (options_.strict) {
          return absl::InvalidArgumentError(absl::StrFormat(
              "non-manifold vertex %d (several fans of faces meet there; strict mode)", v));
        }
        if (!split_counted[v]) {
          split_counted[v] = 1;
          ++m_.report_.non_manifold_vertices;
        }
        root_vertex[r] = next_id++;
        m_.copy_of_.push_back(v);
        const double* p = &m_.positions_[3 * v];
        m_.positions_.insert(m_.positions_.end(), p, p + 3);
      }
      m_.faces_[c] = root_vertex[r];
    }
    return absl::OkStatus();
  }

  void ComputeGeometry() {
    const uint32_t nf = m_.face_count(), nh = 3 * nf, nv = next_vertex_count();
    length_.resize(nh);
    opp_x_.resize(nh);
    opp_y_.resize(nh);
    m_.corner_angle_.resize(nh);
    m_.angle_sum_.assign(nv, 0.0);
    m_.vertex_flags_.assign(nv, TriangleMesh::kIsolated);
    double total = 0;
    for (uint32_t h = 0; h < nh; ++h) {
      const double* a = &m_.positions_[3 * From(h)];
      const double* b = &m_.positions_[3 * To(h)];
      const double* c = &m_.positions_[3 * Opposite(h)];
      const double len = Dist3(a, b);
      length_[h] = len;
      total += len;
      m_.max_edge_length_ = std::max(m_.max_edge_length_, len);
      // Opposite corner in this half-edge's frame, from the two other edge lengths (law of
      // cosines) so the frame is exact up to round-off whatever the 3D orientation.
      const double lac = Dist3(a, c), lbc = Dist3(b, c);
      double x = len > 0 ? (len * len + lac * lac - lbc * lbc) / (2 * len) : 0;
      double y2 = lac * lac - x * x;
      opp_x_[h] = x;
      opp_y_[h] = y2 > 0 ? std::sqrt(y2) : 0;
      m_.corner_angle_[h] = CornerAngleAt(a, b, c);  // corner h sits at From(h)
    }
    m_.mean_edge_length_ = nh ? total / nh : 0;
    for (uint32_t c = 0; c < nh; ++c) {
      const uint32_t v = m_.faces_[c];
      m_.angle_sum_[v] += m_.corner_angle_[c];
      m_.vertex_flags_[v] &= ~TriangleMesh::kIsolated;
      if (twin_[c] == kNoIndex || twin_[TriangleMesh::Prev(c)] == kNoIndex) {
        m_.vertex_flags_[v] |= TriangleMesh::kBoundary;
      }
      if (m_.face_flags_[c / 3] & TriangleMesh::kFaceDegenerate) {
        m_.vertex_flags_[v] |= TriangleMesh::kPseudoSource | TriangleMesh::kTouchesDegenerate;
      }
    }
    for (uint32_t v = 0; v < nv; ++v) {
      uint8_t& fl = m_.vertex_flags_[v];
      if (fl & TriangleMesh::kIsolated) {
        if (v < m_.file_vertex_count_) ++m_.report_.isolated_vertices;
        continue;
      }
      if (fl & TriangleMesh::kBoundary) {
        fl |= TriangleMesh::kPseudoSource;
        ++m_.report_.boundary_vertices;
      } else if (m_.angle_sum_[v] >= kTwoPi - kSaddleAngleTolerance) {
        fl |= TriangleMesh::kSaddle | TriangleMesh::kPseudoSource;
        ++m_.report_.saddle_vertices;
      }
    }
  }

  void ComputeVertexRings() {
    const uint32_t nh = 3 * m_.face_count(), nv = next_vertex_count();
    m_.corner_offsets_.assign(nv + 1, 0);
    for (uint32_t c = 0; c < nh; ++c) ++m_.corner_offsets_[m_.faces_[c] + 1];
    for (uint32_t v = 0; v < nv; ++v) m_.corner_offsets_[v + 1] += m_.corner_offsets_[v];
    m_.vertex_corners_.resize(nh);
    std::vector<uint32_t> fill(m_.corner_offsets_.begin(), m_.corner_offsets_.end() - 1);
    for (uint32_t c = 0; c < nh; ++c) m_.vertex_corners_[fill[m_.faces_[c]]++] = c;

    // Neighbours: both endpoints of every half-edge, then sort + unique per vertex.
    std::vector<uint32_t> offsets(nv + 1, 0);
    for (uint32_t h = 0; h < nh; ++h) {
      ++offsets[From(h) + 1];
      ++offsets[To(h) + 1];
    }
    for (uint32_t v = 0; v < nv; ++v) offsets[v + 1] += offsets[v];
    std::vector<uint32_t> raw(offsets[nv]);
    fill.assign(offsets.begin(), offsets.end() - 1);
    for (uint32_t h = 0; h < nh; ++h) {
      raw[fill[From(h)]++] = To(h);
      raw[fill[To(h)]++] = From(h);
    }
    m_.neighbor_offsets_.assign(nv + 1, 0);
    m_.neighbors_.clear();
    m_.neighbors_.reserve(raw.size() / 2 + nv);
    for (uint32_t v = 0; v < nv; ++v) {
      std::sort(raw.begin() + offsets[v], raw.begin() + offsets[v + 1]);
      const auto end = std::unique(raw.begin() + offsets[v], raw.begin() + offsets[v + 1]);
      m_.neighbors_.insert(m_.neighbors_.end(), raw.begin() + offsets[v], end);
      m_.neighbor_offsets_[v + 1] = static_cast<uint32_t>(m_.neighbors_.size());
    }
    m_.neighbors_.shrink_to_fit();
    ComputeFanAngles();
    m_.neighbor_length_.resize(m_.neighbors_.size());
    for (uint32_t v = 0; v < nv; ++v) {
      for (uint32_t i = m_.neighbor_offsets_[v]; i < m_.neighbor_offsets_[v + 1]; ++i) {
        m_.neighbor_length_[i] = Dist3(&m_.positions_[3 * v], &m_.positions_[3 * m_.neighbors_[i]]);
      }
    }
  }

  // Angular coordinates around each closed fan, walking corners counter-clockwise
  // (c -> Twin(Prev(c))). Used to restrict a saddle's new windows to its shadow sector.
  void ComputeFanAngles() {
    const uint32_t nv = next_vertex_count();
    m_.corner_start_angle_.assign(m_.corner_angle_.size(), 0.0);
    for (uint32_t v = 0; v < nv; ++v) {
      const uint8_t fl = m_.vertex_flags_[v];
      if (fl &
          (TriangleMesh::kBoundary | TriangleMesh::kIsolated | TriangleMesh::kTouchesDegenerate)) {
        continue;
      }
      const uint32_t degree = m_.corner_offsets_[v + 1] - m_.corner_offsets_[v];
      const uint32_t c0 = m_.vertex_corners_[m_.corner_offsets_[v]];
      uint32_t c = c0, steps = 0;
      double angle = 0;
      do {
        m_.corner_start_angle_[c] = angle;
        angle += m_.corner_angle_[c];
        const uint32_t t = twin_[TriangleMesh::Prev(c)];
        if (t == kNoIndex) break;
        c = t;
        ++steps;
      } while (c != c0 && steps <= degree);
      if (c == c0 && steps == degree) m_.vertex_flags_[v] |= TriangleMesh::kClosedFan;
    }
  }

  void ComputeComponentsAndBoundary() {
    const uint32_t nv = next_vertex_count(), nf = m_.face_count();
    // Components of the internal (cut) mesh drive reachability; the report counts the file's.
    DisjointSets internal(nv), file(m_.file_vertex_count_);
    for (uint32_t f = 0; f < nf; ++f) {
      const uint32_t* c = &m_.faces_[3 * f];
      internal.Union(c[0], c[1]);
      internal.Union(c[1], c[2]);
      file.Union(m_.FileVertex(c[0]), m_.FileVertex(c[1]));
      file.Union(m_.FileVertex(c[1]), m_.FileVertex(c[2]));
    }
    m_.component_.resize(nv);
    for (uint32_t v = 0; v < nv; ++v) m_.component_[v] = internal.Find(v);
    // `components` counts pieces after cutting at non-manifold vertices (what paths can cross);
    // `vertex_connected_components` counts pieces joined through any shared vertex.
    std::vector<uint8_t> seen(nv, 0);
    for (uint32_t v = 0; v < nv; ++v) {
      if (m_.vertex_flags_[v] & TriangleMesh::kIsolated) continue;
      if (!seen[m_.component_[v]]) {
        seen[m_.component_[v]] = 1;
        ++m_.report_.components;
      }
    }
    std::fill(seen.begin(), seen.end(), 0);
    for (uint32_t v = 0; v < m_.file_vertex_count_; ++v) {
      if (m_.vertex_flags_[v] & TriangleMesh::kIsolated) continue;
      const uint32_t r = file.Find(v);
      if (!seen[r]) {
        seen[r] = 1;
        ++m_.report_.vertex_connected_components;
      }
    }
    // Boundary loops: connected pieces of the graph of boundary half-edges (cut edges included).
    DisjointSets loops(nv);
    std::vector<uint8_t> on_boundary(nv, 0);
    for (uint32_t h = 0; h < 3 * nf; ++h) {
      if (twin_[h] != kNoIndex) continue;
      loops.Union(From(h), To(h));
      on_boundary[From(h)] = on_boundary[To(h)] = 1;
    }
    std::vector<uint8_t> root_seen(nv, 0);
    for (uint32_t v = 0; v < nv; ++v) {
      if (!on_boundary[v]) continue;
      const uint32_t r = loops.Find(v);
      if (!root_seen[r]) {
        root_seen[r] = 1;
        ++m_.report_.boundary_loops;
      }
    }
  }

  uint32_t next_vertex_count() const { return static_cast<uint32_t>(m_.positions_.size() / 3); }

  const MeshData& data_;
  const MeshBuildOptions& options_;
  TriangleMesh m_;
  std::vector<uint32_t> candidate_;  // twin candidates in file half-edge numbering
  std::vector<uint32_t> twin_;       // packed into the mesh's half-edge records at the end
  std::vector<double> length_, opp_x_, opp_y_;
};

absl::StatusOr<TriangleMesh> TriangleMesh::Build(const MeshData& data,
                                                 const MeshBuildOptions& options) {
  absl::StatusOr<TriangleMesh> mesh = MeshBuilder(data, options).Run();
  if (mesh.ok()) mesh->workspaces_ = std::make_shared<ich::WorkspaceCache>();
  return mesh;
}

uint64_t TriangleMesh::MemoryBytes() const {
  auto bytes = [](const auto& v) { return uint64_t{v.capacity()} * sizeof(v[0]); };
  return sizeof(*this) + bytes(positions_) + bytes(faces_) + bytes(face_flags_) + bytes(copy_of_) +
         bytes(half_edges_) + bytes(corner_angle_) + bytes(corner_start_angle_) +
         bytes(angle_sum_) + bytes(vertex_flags_) + bytes(component_) + bytes(corner_offsets_) +
         bytes(vertex_corners_) + bytes(neighbor_offsets_) + bytes(neighbors_) +
         bytes(neighbor_length_);
}

MeshData TriangleMesh::ToMeshData() const {
  MeshData out;
  out.positions.resize(3 * size_t{file_vertex_count_});
  for (uint32_t v = 0; v < file_vertex_count_; ++v) {
    for (int k = 0; k < 3; ++k) out.positions[3 * v + k] = positions_[3 * v + k] + center_[k];
  }
  out.faces.resize(faces_.size());
  for (uint32_t f = 0; f < face_count(); ++f) {
    const bool flipped = FaceFlipped(f);  // Build swapped the 2nd and 3rd corners
    out.faces[3 * f] = FileVertex(faces_[3 * f]);
    out.faces[3 * f + 1] = FileVertex(faces_[3 * f + (flipped ? 2 : 1)]);
    out.faces[3 * f + 2] = FileVertex(faces_[3 * f + (flipped ? 1 : 2)]);
  }
  return out;
}

MeshSummary Summarize(const TriangleMesh& mesh) {
  MeshSummary s;
  s.report = mesh.report();
  s.internal_vertices = mesh.vertex_count();
  s.mean_edge_length = mesh.MeanEdgeLength();
  s.max_edge_length = mesh.MaxEdgeLength();
  s.bbox_min = mesh.BoundsMin();
  s.bbox_max = mesh.BoundsMax();
  s.bytes = mesh.MemoryBytes();
  return s;
}

}  // namespace geodex
