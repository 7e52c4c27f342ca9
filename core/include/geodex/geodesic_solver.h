#pragma once

#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "geodex/cancel.h"
#include "geodex/distance_field.h"
#include "geodex/surface_point.h"
#include "geodex/travel_cost.h"
#include "geodex/triangle_mesh.h"

namespace geodex {

enum class Method {
  // Exact, the default: ICH's rules (the filter theorem, one angle one split, pseudo-sources, the
  // A* key) without the paper's window tree. A window is freed as soon as it is processed, so
  // memory follows the wavefront; Lemma 1 then prunes forward only (docs/engine.md).
  kExact,
  // Exact: the paper's improved Chen-Han as published (Xin & Wang 2009/2010), with the window
  // tree and Lemma 1's retroactive subtree deletion. For the ablation and the paper's tables.
  kIch,
  kDijkstra,  // shortest paths along mesh edges (an upper bound; the baseline)
};

// True for the two exact engines.
inline bool IsExactMethod(Method m) { return m == Method::kExact || m == Method::kIch; }

enum class LambdaScale {
  kMaxEdge,   // epsilon = lambda * longest edge: lambda = 1 reproduces Dijkstra (Theorem 8)
  kMeanEdge,  // epsilon = lambda * mean edge length, the paper's practical suggestion
};

struct GeodesicOptions {
  Method method = Method::kExact;
  // Precision knob of section 7: 0 = exact ICH; larger values over-filter (faster, less exact).
  double lambda = 0;
  LambdaScale lambda_scale = LambdaScale::kMaxEdge;
  // Vertices farther than this stay +inf; propagation stops there.
  double max_distance = std::numeric_limits<double>::infinity();
  // 0 = unlimited. Stops the solve with ResourceExhausted once this many windows were created.
  uint64_t max_windows = 0;
  const CancelToken* cancel = nullptr;
  // Ablation switches for tests and benchmarks; both are exact either way.
  bool use_filter = true;               // Lemma 2, the filter theorem
  bool use_one_angle_one_split = true;  // Lemma 1, Chen & Han
  // Travel time instead of length (travel_cost.h): set, every answer is in seconds, within
  // (1 + travel->epsilon) of the least time at a constant speed.
  std::optional<TravelCost> travel;
};

// The one check of the options every solve shares (lambda in [0, 1], max_distance > 0, a travel
// cost's values and what it cannot combine with: lambda > 0, Dijkstra), made by
// every query; the CLI and geodexd call it too, before any work. An error is InvalidArgument
// "must be ..., got X" naming the option as data: InvalidOptionOf gives its name ("lambda",
// "max_distance"), which each front end spells its own way (--lambda, options.lambda).
absl::Status ValidateGeodesicOptions(const GeodesicOptions& options);
std::string InvalidOptionOf(const absl::Status& status);  // "" when the error is not an option's
// An error about `option` that InvalidOptionOf names: core's checks of query options make theirs
// with it (InvalidArgument for a bad value; ResourceExhausted for a value over a caller's limit).
absl::Status OptionError(absl::string_view option, const std::string& description,
                         absl::StatusCode code = absl::StatusCode::kInvalidArgument);

// Distances from every vertex to the nearest of `sources`, with the nearest source's index.
// Errors: InvalidArgument for an empty source list or a bad source (named), Cancelled,
// ResourceExhausted (window budget).
absl::StatusOr<DistanceField> ComputeDistanceField(const TriangleMesh& mesh,
                                                   const std::vector<SurfacePoint>& sources,
                                                   const GeodesicOptions& options = {});

}  // namespace geodex
