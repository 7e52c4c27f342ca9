// The weighted engine's entry points (geodex/weighted_field.h): the options checked, the surface
// (graph and cost model, weighted/) built once per solve or shared, refined around points that need
// it, and the searches on it: a field, costs at points, paths.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <optional>
#include <type_traits>
#include <utility>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/str_format.h"
#include "geodex/geodesic_solver.h"
#include "geodex/triangle_mesh.h"
#include "geodex/weighted_field.h"
#include "weighted/cost_models.h"
#include "weighted/search.h"
#include "weighted/steiner_graph.h"
#include "weighted_regions.h"

namespace geodex {

using weighted_internal::BestLink;
using weighted_internal::DirectCost;
using weighted_internal::DirectionalCost;
using weighted_internal::GoalOf;
using weighted_internal::IsotropicCost;
using weighted_internal::kFromSourcePoint;
using weighted_internal::kInf;
using weighted_internal::Located;
using weighted_internal::LocatedPoint;
using weighted_internal::NodePoint;
using weighted_internal::Prepare;
using weighted_internal::Search;
using weighted_internal::SearchWhole;
using weighted_internal::SteinerGraph;
using weighted_internal::TargetWatch;
using weighted_internal::Vec;

namespace {

double Elapsed(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

}  // namespace

// The graph and its cost model, built once; the cost model refers to the graph and the graph to
// the options' weights, so all three live here, at fixed addresses.
struct WeightedSurface::Impl {
  Impl(const TriangleMesh& mesh, WeightedOptions opts)
      : options(std::move(opts)), graph(mesh, options) {}
  WeightedOptions options;
  SteinerGraph graph;
  std::optional<IsotropicCost> isotropic;
  std::optional<DirectionalCost> directional;
  // The bounded placement's anchors (sorted positions): a search from or to any other point
  // strictly inside a face or an edge needs a surface refined around it (Anchors).
  std::vector<Vec> anchored;
  // Set: one weight, the exact engine answers (OnRegions) and the graph stays unbuilt.
  std::shared_ptr<const RegionSurface> regions;

  // The weights it was built with: the options', or, OnRegions, the region surface's.
  const std::vector<double>& Weights() const {
    return regions != nullptr ? regions->face_weight() : options.face_weight;
  }

  // Whether every point of `points` is a vertex or one of the anchors (or the placement has none).
  bool Anchors(const std::vector<Located>& points) const {
    if (isotropic == std::nullopt) return true;
    for (const Located& l : points) {
      if (l.canonical.kind != SurfacePoint::Kind::kVertex &&
          !std::binary_search(anchored.begin(), anchored.end(), l.pos)) {
        return false;
      }
    }
    return true;
  }

  // Calls fn(cost model).
  template <typename Fn>
  auto WithCost(Fn&& fn) const {
    return isotropic.has_value() ? fn(*isotropic) : fn(*directional);
  }
};

namespace {

// The graph and the cost model of `options` (already validated): the one place the model is
// chosen. Every solve builds its surface here; `seeds` are the sources when known, `anchors` every
// point the surface will be searched from or to (the bounded placement is refined around them).
absl::StatusOr<std::unique_ptr<WeightedSurface::Impl>> BuildSurface(
    const TriangleMesh& mesh, const WeightedOptions& options, const std::vector<Located>& seeds,
    const std::vector<Located>& anchors) {
  auto impl = std::make_unique<WeightedSurface::Impl>(mesh, options);
  // The placement goes with the cost model: a model that crosses between points (no bound to
  // keep, kInterpolates) takes them evenly spaced.
  auto placement_of = [](auto interpolates) {
    return interpolates ? SteinerGraph::Placement::kUniform : SteinerGraph::Placement::kBounded;
  };
  const SteinerGraph::Placement placement = options.slope_cost == nullptr
                                                ? placement_of(IsotropicCost::kInterpolates)
                                                : placement_of(DirectionalCost::kInterpolates);
  std::vector<Vec> seed_positions;
  for (const Located& l : seeds) seed_positions.push_back(l.pos);
  if (absl::Status s = impl->graph.Build(options.epsilon, options.max_steiner_points, placement,
                                         seed_positions, anchors);
      !s.ok()) {
    return s;
  }
  if (placement == SteinerGraph::Placement::kBounded) {
    for (const Located& l : anchors) impl->anchored.push_back(l.pos);
    std::sort(impl->anchored.begin(), impl->anchored.end());
  }
  if (options.slope_cost == nullptr) {
    impl->isotropic.emplace(impl->graph);
  } else {
    impl->directional.emplace(impl->graph, *impl->options.slope_cost, options.inbound);
  }
  return impl;
}

// The surface to search from `from` to `to` on: `surface` itself when every point of both (of
// `from` only, without `anchor_targets`) is a vertex or one of its anchors; else one refined
// around them, built for this call and kept in *refined.
absl::StatusOr<const WeightedSurface::Impl*> SurfaceFor(
    const WeightedSurface::Impl& surface, const std::vector<Located>& from,
    const std::vector<Located>& to, bool anchor_targets,
    std::unique_ptr<WeightedSurface::Impl>* refined) {
  if (surface.Anchors(from) && (!anchor_targets || surface.Anchors(to))) return &surface;
  std::vector<Located> anchors = from;
  if (anchor_targets) anchors.insert(anchors.end(), to.begin(), to.end());
  absl::StatusOr<std::unique_ptr<WeightedSurface::Impl>> built =
      BuildSurface(surface.graph.mesh(), surface.options, from, anchors);
  if (!built.ok()) return built.status();
  *refined = std::move(*built);
  return refined->get();
}

}  // namespace

absl::Status ValidateWeightedOptions(const TriangleMesh& mesh, const WeightedOptions& options) {
  if (!(options.epsilon > 0 && options.epsilon < 1)) {
    return OptionError("epsilon", absl::StrFormat("must be in (0, 1), got %g", options.epsilon));
  }
  if (!(options.max_distance > 0)) {
    return OptionError("max_distance",
                       absl::StrFormat("must be > 0, got %g", options.max_distance));
  }
  if (options.slope_cost != nullptr) {
    const std::vector<double>& c = options.slope_cost->per_metre;
    bool ok = c.size() >= 2;
    for (size_t i = 0; ok && i < c.size(); ++i) ok = c[i] > 0;  // also NaN
    // The level direction (sine 0) must be walkable: a face always has one.
    if (ok && c.size() % 2 == 1) ok = std::isfinite(c[c.size() / 2]);
    if (ok && c.size() % 2 == 0) ok = std::isfinite(c[c.size() / 2 - 1] + c[c.size() / 2]);
    if (!ok) {
      return OptionError("slope_cost", "needs >= 2 samples, each > 0 (or +inf), finite at slope 0");
    }
  }
  const std::vector<double>& w = options.face_weight;
  if (!w.empty() && w.size() != mesh.face_count()) {
    return OptionError("face_weight", absl::StrFormat("must have one weight per face (%d), got %d",
                                                      mesh.face_count(), w.size()));
  }
  for (size_t f = 0; f < w.size(); ++f) {
    if (!(w[f] > 0)) {  // also NaN
      return OptionError(absl::StrFormat("face_weight[%d]", f),
                         absl::StrFormat("must be > 0 (or +inf: impassable), got %g", w[f]));
    }
  }
  return absl::OkStatus();
}

absl::StatusOr<WeightedField> ComputeWeightedField(const TriangleMesh& mesh,
                                                   const std::vector<SurfacePoint>& sources,
                                                   const WeightedOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  if (absl::Status s = ValidateWeightedOptions(mesh, options); !s.ok()) return s;
  if (sources.empty()) return absl::InvalidArgumentError("no sources given");
  std::vector<Located> located;
  if (absl::Status s = Prepare(mesh, sources, &located); !s.ok()) return s;
  absl::StatusOr<std::unique_ptr<WeightedSurface::Impl>> surface =
      BuildSurface(mesh, options, located, located);
  if (!surface.ok()) return surface.status();
  const SteinerGraph& g = (*surface)->graph;
  return (*surface)->WithCost([&](const auto& cost) -> absl::StatusOr<WeightedField> {
    Search search(g, cost);
    if (absl::Status s = SearchWhole(located, options, &search); !s.ok()) return s;
    WeightedField field;
    field.cost.assign(mesh.file_vertex_count(), kInf);
    field.source.assign(mesh.file_vertex_count(), kNoIndex);
    for (uint32_t v = 0; v < mesh.vertex_count(); ++v) {
      const uint32_t fv = mesh.FileVertex(v);
      if (search.cost(v) < field.cost[fv]) {
        field.cost[fv] = search.cost(v);
        field.source[fv] = search.label(v);
      }
    }
    field.steiner_points = g.steiner_points();
    field.graph_edges = g.graph_edges();
    field.epsilon = options.epsilon;
    field.stats = search.Stats(Elapsed(start));
    return field;
  });
}

WeightedSurface::WeightedSurface(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
WeightedSurface::WeightedSurface(WeightedSurface&&) noexcept = default;
WeightedSurface& WeightedSurface::operator=(WeightedSurface&&) noexcept = default;
WeightedSurface::~WeightedSurface() = default;

absl::StatusOr<WeightedSurface> WeightedSurface::Build(const TriangleMesh& mesh,
                                                       const WeightedOptions& options,
                                                       const std::vector<SurfacePoint>& seeds,
                                                       const std::vector<SurfacePoint>& anchors) {
  if (absl::Status s = ValidateWeightedOptions(mesh, options); !s.ok()) return s;
  std::vector<Located> located, anchored;
  if (absl::Status s = Prepare(mesh, seeds, &located); !s.ok()) return s;
  if (absl::Status s = Prepare(mesh, anchors, &anchored); !s.ok()) return s;
  anchored.insert(anchored.end(), located.begin(), located.end());
  absl::StatusOr<std::unique_ptr<Impl>> impl = BuildSurface(mesh, options, located, anchored);
  if (!impl.ok()) return impl.status();
  return WeightedSurface(*std::move(impl));
}

WeightedSurface WeightedSurface::OnRegions(const TriangleMesh& mesh, WeightedOptions options,
                                           std::shared_ptr<const RegionSurface> regions) {
  // The weights stay in `regions` only (Impl::Weights): the unbuilt graph never reads them.
  std::vector<double>().swap(options.face_weight);
  auto impl = std::make_unique<Impl>(mesh, std::move(options));
  impl->regions = std::move(regions);
  return WeightedSurface(std::move(impl));
}

uint64_t WeightedSurface::steiner_points() const {
  return impl_->regions != nullptr ? 0 : impl_->graph.steiner_points();
}

uint64_t WeightedSurface::bytes() const {
  // (the graph reads the options' weights; a surface OnRegions keeps them in `regions`)
  return sizeof(Impl) + impl_->graph.bytes() +
         impl_->options.face_weight.capacity() * sizeof(double) +
         (impl_->regions != nullptr ? impl_->regions->bytes() : 0);
}

const TriangleMesh& WeightedSurface::mesh() const { return impl_->graph.mesh(); }

bool WeightedSurface::Serves(const TriangleMesh& mesh, const WeightedOptions& options) const {
  const WeightedOptions& built = impl_->options;
  return &impl_->graph.mesh() == &mesh && options.slope_cost == nullptr &&
         built.slope_cost == nullptr && options.epsilon == built.epsilon &&
         options.face_weight == impl_->Weights() &&
         (options.max_steiner_points == 0 || steiner_points() <= options.max_steiner_points) &&
         (impl_->regions == nullptr || options.max_windows == built.max_windows);
}

namespace {

// What a search on a shared surface reads of its options: the query's limits (the surface holds
// the rest), without copying the surface's weights.
WeightedOptions SearchOptions(const WeightedOptions& built, const WeightedSurface::Limits& limits) {
  WeightedOptions out;
  out.epsilon = built.epsilon;
  out.max_distance = limits.max_distance;
  out.cancel = limits.cancel;
  out.max_windows = built.max_windows;  // the work budget the surface was built under
  out.check_optimality = built.check_optimality;
  return out;
}

}  // namespace

namespace {
absl::StatusOr<WeightedCosts> CostsOn(const WeightedSurface::Impl& surface,
                                      const std::vector<Located>& from,
                                      const std::vector<Located>& to, bool whole,
                                      const WeightedOptions& options,
                                      std::chrono::steady_clock::time_point start);
}  // namespace

absl::StatusOr<WeightedCosts> WeightedSurface::CostsAt(const std::vector<SurfacePoint>& sources,
                                                       const std::vector<SurfacePoint>& targets,
                                                       bool whole) const {
  return CostsAt(sources, targets, whole, {impl_->options.max_distance, impl_->options.cancel});
}

absl::StatusOr<WeightedCosts> WeightedSurface::CostsAt(const std::vector<SurfacePoint>& sources,
                                                       const std::vector<SurfacePoint>& targets,
                                                       bool whole, const Limits& limits) const {
  if (impl_->regions != nullptr) return impl_->regions->CostsAt(sources, targets, whole, limits);
  const auto start = std::chrono::steady_clock::now();
  if (sources.empty()) return absl::InvalidArgumentError("no sources given");
  if (!(limits.max_distance > 0)) {
    return OptionError("max_distance", absl::StrFormat("must be > 0, got %g", limits.max_distance));
  }
  const WeightedOptions options = SearchOptions(impl_->options, limits);
  std::vector<Located> from, to;
  if (absl::Status s = Prepare(impl_->graph.mesh(), sources, &from); !s.ok()) return s;
  if (absl::Status s = Prepare(impl_->graph.mesh(), targets, &to); !s.ok()) return s;
  std::unique_ptr<Impl> refined;
  absl::StatusOr<const Impl*> surface =
      SurfaceFor(*impl_, from, to, limits.anchor_targets, &refined);
  if (!surface.ok()) return surface.status();
  return CostsOn(**surface, from, to, whole, options, start);
}

namespace {

// CostsAt's search on `surface` (refined around every point of `from` and `to`).
absl::StatusOr<WeightedCosts> CostsOn(const WeightedSurface::Impl& surface,
                                      const std::vector<Located>& from,
                                      const std::vector<Located>& to, bool whole,
                                      const WeightedOptions& options,
                                      std::chrono::steady_clock::time_point start) {
  const SteinerGraph& g = surface.graph;
  return surface.WithCost([&](const auto& cost) -> absl::StatusOr<WeightedCosts> {
    // The answers off a finished search.
    auto answer = [&](const auto& search) {
      WeightedCosts out;
      out.cost.assign(to.size(), kInf);
      out.source.assign(to.size(), kNoIndex);
      for (size_t t = 0; t < to.size(); ++t) {
        const auto [c, n] = BestLink(g, cost, search, to[t]);
        if (n != kNoIndex) {
          out.cost[t] = c;
          out.source[t] = search.label(n);
        }
        for (uint32_t s = 0; s < from.size(); ++s) {
          const double direct = DirectCost(g, cost, from[s], to[t]);
          if (direct < out.cost[t]) {
            out.cost[t] = direct;
            out.source[t] = s;
          }
        }
        if (out.cost[t] > options.max_distance) {
          out.cost[t] = kInf;
          out.source[t] = kNoIndex;
        }
      }
      out.steiner_points = g.steiner_points();
      out.stats = search.Stats(Elapsed(start));
      return out;
    };
    using CostModel = std::decay_t<decltype(cost)>;
    if (whole || options.check_optimality) {
      Search<CostModel> search(g, cost);
      if (absl::Status s = SearchWhole(from, options, &search); !s.ok()) return s;
      return answer(search);
    }
    // Headed for the targets (A*), stopping once each is final.
    Search<CostModel, true> search(g, cost);
    search.HeadFor(GoalOf(g, cost, to));
    TargetWatch watch(g, cost, from, to);
    for (uint32_t i = 0; i < from.size(); ++i) search.Seed(from[i], i);
    absl::Status s = search.Run(
        options, [&](double key) { return watch.Done(key); },
        [&](uint32_t u) { watch.Settled(u, search.cost(u)); });
    if (!s.ok()) return s;
    return answer(search);
  });
}

}  // namespace

absl::StatusOr<WeightedCosts> ComputeWeightedCostsAt(const TriangleMesh& mesh,
                                                     const std::vector<SurfacePoint>& sources,
                                                     const std::vector<SurfacePoint>& targets,
                                                     const WeightedOptions& options) {
  absl::StatusOr<WeightedSurface> surface = WeightedSurface::Build(mesh, options, sources, targets);
  if (!surface.ok()) return surface.status();
  return surface->CostsAt(sources, targets);
}

namespace {

// The paths from src to every dst on a surface built outward; `options`: the query's limits.
absl::StatusOr<std::vector<WeightedPath>> PathsOn(const WeightedSurface::Impl& surface,
                                                  const Located& src,
                                                  const std::vector<Located>& dsts,
                                                  const WeightedOptions& options,
                                                  std::chrono::steady_clock::time_point start) {
  const SteinerGraph& g = surface.graph;
  const TriangleMesh& mesh = g.mesh();
  const std::vector<Located> src_list = {src};
  return surface.WithCost([&](const auto& cost) -> absl::StatusOr<std::vector<WeightedPath>> {
    Search<std::decay_t<decltype(cost)>, true> search(g, cost);
    search.HeadFor(GoalOf(g, cost, dsts));
    search.Seed(src, 0);
    TargetWatch watch(g, cost, src_list, dsts);
    if (absl::Status s = search.Run(
            options, [&](double key) { return watch.Done(key); },
            [&](uint32_t u) { watch.Settled(u, search.cost(u)); });
        !s.ok()) {
      return s;
    }
    std::vector<WeightedPath> paths(dsts.size());
    for (size_t t = 0; t < dsts.size(); ++t) {
      const Located& dst = dsts[t];
      WeightedPath& path = paths[t];
      path.steiner_points = g.steiner_points();
      auto [total, node] = BestLink(g, cost, search, dst);
      const double direct = DirectCost(g, cost, src, dst);
      if (direct <= total) {
        total = direct;
        node = kNoIndex;
      }
      if (!std::isfinite(total) || total > options.max_distance) {
        path.cost = kInf;  // unreachable: no points
        continue;
      }
      path.cost = total;
      // Backwards from the target, then reversed.
      path.points.push_back(LocatedPoint(mesh, dst));
      uint32_t parent = kFromSourcePoint;
      while (node != kNoIndex) {
        if (!(dst.canonical.kind == SurfacePoint::Kind::kVertex && search.cost(node) == total &&
              path.points.size() == 1 && node < g.nv() &&
              mesh.FileVertex(node) == dst.canonical.vertex)) {
          path.points.push_back(NodePoint(g, node));
        }
        parent = search.parent(node);
        node = parent >= kFromSourcePoint ? kNoIndex : parent;
      }
      if (parent == kFromSourcePoint) path.points.push_back(LocatedPoint(mesh, src));
      std::reverse(path.points.begin(), path.points.end());
    }
    const WeightedStats stats = search.Stats(Elapsed(start));
    for (WeightedPath& path : paths) path.stats = stats;
    return paths;
  });
}

}  // namespace

absl::StatusOr<std::vector<WeightedPath>> ComputeWeightedPaths(const TriangleMesh& mesh,
                                                               const SurfacePoint& from,
                                                               const std::vector<SurfacePoint>& tos,
                                                               const WeightedOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  if (absl::Status s = ValidateWeightedOptions(mesh, options); !s.ok()) return s;
  std::vector<Located> src_list, dsts;
  if (absl::Status s = Prepare(mesh, {from}, &src_list); !s.ok()) return s;
  if (absl::Status s = Prepare(mesh, tos, &dsts); !s.ok()) return s;
  // A path is walked from `from`: the search runs outward whatever options.inbound says. One graph
  // and one search serve every target; it stops once every target's best is final.
  WeightedOptions outward = options;
  outward.inbound = false;
  std::vector<Located> anchors = src_list;
  anchors.insert(anchors.end(), dsts.begin(), dsts.end());
  absl::StatusOr<std::unique_ptr<WeightedSurface::Impl>> surface =
      BuildSurface(mesh, outward, src_list, anchors);
  if (!surface.ok()) return surface.status();
  return PathsOn(**surface, src_list[0], dsts, options, start);
}

absl::StatusOr<std::vector<WeightedPath>> WeightedSurface::Paths(
    const SurfacePoint& from, const std::vector<SurfacePoint>& tos, const Limits& limits) const {
  if (impl_->regions != nullptr) return impl_->regions->Paths(from, tos, limits);
  const auto start = std::chrono::steady_clock::now();
  if (impl_->options.inbound && impl_->options.slope_cost != nullptr) {
    return OptionError("inbound", "a path is walked from its start: build the surface outward");
  }
  if (!(limits.max_distance > 0)) {
    return OptionError("max_distance", absl::StrFormat("must be > 0, got %g", limits.max_distance));
  }
  std::vector<Located> src_list, dsts;
  if (absl::Status s = Prepare(impl_->graph.mesh(), {from}, &src_list); !s.ok()) return s;
  if (absl::Status s = Prepare(impl_->graph.mesh(), tos, &dsts); !s.ok()) return s;
  const WeightedOptions options = SearchOptions(impl_->options, limits);
  std::unique_ptr<Impl> refined;
  absl::StatusOr<const Impl*> surface =
      SurfaceFor(*impl_, src_list, dsts, /*anchor_targets=*/true, &refined);
  if (!surface.ok()) return surface.status();
  return PathsOn(**surface, src_list[0], dsts, options, start);
}

absl::StatusOr<WeightedPath> ComputeWeightedPath(const TriangleMesh& mesh, const SurfacePoint& from,
                                                 const SurfacePoint& to,
                                                 const WeightedOptions& options) {
  absl::StatusOr<std::vector<WeightedPath>> paths = ComputeWeightedPaths(mesh, from, {to}, options);
  if (!paths.ok()) return paths.status();
  WeightedPath& path = (*paths)[0];
  if (!std::isfinite(path.cost)) {
    return absl::NotFoundError(
        absl::StrFormat("point %s cannot be reached from %s%s", SurfacePointToString(to),
                        SurfacePointToString(from),
                        std::isfinite(options.max_distance) ? " within max_distance" : ""));
  }
  return std::move(path);
}

}  // namespace geodex
