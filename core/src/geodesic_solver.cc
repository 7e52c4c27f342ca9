#include "geodex/geodesic_solver.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <new>

#include "absl/strings/cord.h"
#include "absl/strings/str_format.h"
#include "absl/strings/string_view.h"
#include "dijkstra.h"
#include "ich/ich_solver.h"
#include "mesh_lookup.h"
#include "source_resolver.h"
#include "travel_queries.h"

namespace geodex {
namespace {

// The option an InvalidArgument from ValidateGeodesicOptions is about (a type URL private to core).
constexpr absl::string_view kOptionPayload = "geodex/option";

}  // namespace

absl::Status OptionError(absl::string_view option, const std::string& description,
                         absl::StatusCode code) {
  absl::Status status(code, description);
  status.SetPayload(kOptionPayload, absl::Cord(option));
  return status;
}

absl::Status ValidateGeodesicOptions(const GeodesicOptions& options) {
  if (!(options.lambda >= 0 && options.lambda <= 1)) {  // also NaN
    return OptionError("lambda", absl::StrFormat("must be in [0, 1], got %g", options.lambda));
  }
  if (!(options.max_distance > 0)) {
    return OptionError("max_distance",
                       absl::StrFormat("must be > 0, got %g", options.max_distance));
  }
  if (options.travel.has_value()) {
    if (absl::Status s = ValidateTravelCost(*options.travel); !s.ok()) return s;
    if (options.lambda > 0 || options.method == Method::kDijkstra) {
      return OptionError(
          "travel",
          "a travel cost is solved by the weighted engine, which takes no lambda and "
          "no Dijkstra method (its precision is travel.epsilon)");
    }
  }
  return absl::OkStatus();
}

std::string InvalidOptionOf(const absl::Status& status) {
  auto option = status.GetPayload(kOptionPayload);
  return option ? std::string(*option) : std::string();
}

absl::StatusOr<DistanceField> ComputeDistanceField(const TriangleMesh& mesh,
                                                   const std::vector<SurfacePoint>& sources,
                                                   const GeodesicOptions& options) {
  if (sources.empty()) return absl::InvalidArgumentError("no sources given");
  if (absl::Status s = ValidateGeodesicOptions(options); !s.ok()) return s;
  if (options.travel.has_value()) return ComputeTravelField(mesh, sources, options);
  SourceResolver resolver(mesh);
  for (uint32_t i = 0; i < sources.size(); ++i) {
    if (absl::Status s = resolver.Add(sources[i], i); !s.ok()) return s;
  }
  DistanceField field;
  if (options.method == Method::kDijkstra) {
    if (absl::Status s =
            RunDijkstra(mesh, SeedsForDijkstra(mesh, resolver.sources()), options, &field);
        !s.ok()) {
      return s;
    }
  } else {
    double key_cap = std::numeric_limits<double>::infinity();
    if (!options.use_filter) {
      // Without the filter nothing stops windows wrapping around a closed surface until P3's depth
      // bound; Dijkstra's distances bound every geodesic distance from above, so cap there.
      DistanceField bound;
      GeodesicOptions dijkstra = options;
      dijkstra.method = Method::kDijkstra;
      if (absl::Status s =
              RunDijkstra(mesh, SeedsForDijkstra(mesh, resolver.sources()), dijkstra, &bound);
          !s.ok()) {
        return s;
      }
      double farthest = 0;
      for (double d : bound.internal_distance) {
        if (d < kUnreachable) farthest = std::max(farthest, d);
      }
      key_cap = farthest + mesh.MaxEdgeLength();
    }
    ich::IchSolver solver(mesh, options, key_cap);
    try {
      if (absl::Status s = solver.Solve(resolver.sources(), &field); !s.ok()) return s;
    } catch (const std::bad_alloc&) {
      // The window pool outgrew memory: report it like the window budget, never crash.
      return absl::ResourceExhaustedError(
          "out of memory for geodesic windows; set a window budget, a max_distance or lambda > 0");
    }
  }
  field.sources = sources;
  // File order: a split vertex takes the best of its copies.
  const uint32_t nf = mesh.file_vertex_count();
  field.distance.assign(field.internal_distance.begin(), field.internal_distance.begin() + nf);
  field.source.assign(field.internal_source.begin(), field.internal_source.begin() + nf);
  for (uint32_t v = nf; v < mesh.vertex_count(); ++v) {
    const uint32_t fv = mesh.FileVertex(v);
    if (field.internal_distance[v] < field.distance[fv]) {
      field.distance[fv] = field.internal_distance[v];
      field.source[fv] = field.internal_source[v];
    }
  }
  return field;
}

}  // namespace geodex
