// The local backend: every query runs in this process on core. The mesh is read and built once
// per command; the field of the last sources is kept so that a command needing the field and the
// geometry derived from it (render, isolines) solves once.

#include <chrono>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "cli_backend.h"
#include "geodex/locate.h"
#include "geodex/point_distance.h"
#include "geodex/solve_key.h"
#include "geodex/triangle_mesh.h"

namespace geodex::cli {
namespace {

// The answer a field cache may reuse: core's SolveKey, the rule geodexd's result cache keeps.
std::string Key(const std::vector<SurfacePoint>& sources, const GeodesicOptions& o) {
  return SolveKey(sources, o);
}

// Core says NOT_FOUND for a target no source reaches; as geodexd does, the CLI treats that as a
// failed computation (FAILED_PRECONDITION, exit 1), keeping NOT_FOUND for an unknown mesh.
template <typename T>
absl::StatusOr<T> Reachable(absl::StatusOr<T> result) {
  if (result.status().code() == absl::StatusCode::kNotFound) {
    return absl::FailedPreconditionError(result.status().message());
  }
  return result;
}

class LocalBackend final : public Backend {
 public:
  absl::Status Open(const std::string& mesh, const MeshBuildOptions& build,
                    const terrain::DemOptions& dem) override {
    absl::StatusOr<LoadedMesh> loaded = LoadMesh(mesh, build, dem);
    if (!loaded.ok()) return loaded.status();
    loaded_ = std::make_unique<LoadedMesh>(*std::move(loaded));
    return absl::OkStatus();
  }

  bool Supports(const Args&, std::string*) const override { return true; }
  const terrain::Dem* Terrain() const override { return loaded_->dem.get(); }

  absl::StatusOr<std::vector<LocatedPoint>> Locate(
      const std::vector<std::array<double, 3>>& xyz) override {
    if (locator_ == nullptr) locator_ = std::make_unique<SurfaceLocator>(loaded_->mesh);
    std::vector<LocatedPoint> out;
    for (const auto& q : xyz) {
      absl::StatusOr<LocatedPoint> located = locator_->Locate(q);
      if (!located.ok()) return located.status();
      out.push_back(*located);
    }
    return out;
  }

  absl::Status Check(const std::string& option, const std::vector<SurfacePoint>& points) override {
    for (const SurfacePoint& p : points) {
      if (absl::Status s = ValidateSurfacePoint(loaded_->mesh, p); !s.ok()) {
        return absl::InvalidArgumentError(absl::StrFormat("--%s: %s", option, s.message()));
      }
    }
    return absl::OkStatus();
  }

  absl::StatusOr<const MeshData*> Geometry() override { return &loaded_->data; }

  absl::StatusOr<InfoValues> Info() override {
    InfoValues v;
    static_cast<MeshSummary&>(v) = Summarize(loaded_->mesh);
    v.load_ms = loaded_->load_ms;
    v.dem = loaded_->dem ? &loaded_->dem->info() : nullptr;
    v.build_ms = loaded_->build_ms;
    return v;
  }

  absl::StatusOr<const DistanceField*> Field(const FieldQuery& query) override {
    absl::StatusOr<const DistanceField*> f = CachedField(query.sources, query.options);
    if (!f.ok()) return f.status();
    if (absl::Status s = ComputeFieldProducts(loaded_->mesh, *field_, query, field_.get());
        !s.ok()) {
      return s;
    }
    return field_.get();
  }

  absl::StatusOr<AtValues> DistancesAt(const PointQuery& query) override {
    if (query.options.travel.has_value()) {  // times only: the unfolding estimate is geometry
      absl::StatusOr<PointValues> times = Reachable(ComputePointValues(loaded_->mesh, query));
      if (!times.ok()) return times.status();
      AtValues out;
      out.exact = *std::move(times);
      out.estimate.assign(query.points.size(), std::numeric_limits<double>::quiet_NaN());
      return out;
    }
    absl::StatusOr<const DistanceField*> field = CachedField(query.sources, query.options);
    if (!field.ok()) return field.status();
    AtValues out;
    absl::StatusOr<PointValues> exact = Reachable(ComputePointValues(loaded_->mesh, query));
    if (!exact.ok()) return exact.status();
    out.exact = *std::move(exact);
    for (const SurfacePoint& p : query.points) {
      absl::StatusOr<PointEstimate> est = EstimateDistanceAt(loaded_->mesh, **field, p);
      if (!est.ok()) {
        return absl::InvalidArgumentError(absl::StrCat("--at: ", est.status().message()));
      }
      out.estimate.push_back(est->distance);
    }
    return out;
  }

  absl::StatusOr<PathQueryResult> Path(const PathQuery& query) override {
    return Reachable(ComputeShortestPath(loaded_->mesh, query));
  }

  absl::StatusOr<DistanceMatrix> Matrix(const MatrixQuery& query) override {
    return Reachable(ComputeDistanceMatrix(loaded_->mesh, query));
  }

  absl::StatusOr<Isolines> ComputeIsolines(const IsolineQuery& query) override {
    if (absl::Status s = ValidateIsolineQuery(query); !s.ok()) return s;
    absl::StatusOr<const DistanceField*> field = CachedFieldWithin(
        query.sources, IsolineFieldOptions(loaded_->mesh, query.options, query.levels));
    if (!field.ok()) return field.status();
    return ExtractIsolines(loaded_->mesh, **field, query.levels);
  }

  absl::StatusOr<VoronoiDiagram> ComputeVoronoi(const VoronoiQuery& query) override {
    absl::StatusOr<const DistanceField*> field = CachedField(query.sites, query.options);
    if (!field.ok()) return field.status();
    return BuildVoronoi(loaded_->mesh, **field,
                        query.options.travel.has_value() ? &*query.options.travel : nullptr);
  }

  absl::StatusOr<DelaunayTriangulation> ComputeDelaunay(const DelaunayQuery& query) override {
    absl::StatusOr<const DistanceField*> field = CachedField(query.sites, query.options);
    if (!field.ok()) return field.status();
    return BuildDelaunay(loaded_->mesh, **field);
  }

  std::string StatsContext() const override {
    return absl::StrFormat(
        "\"vertices\": %u, \"faces\": %u, \"mesh_bytes\": %llu, \"load_ms\": %.3f, "
        "\"build_ms\": %.3f, ",
        loaded_->mesh.file_vertex_count(), loaded_->mesh.face_count(),
        static_cast<unsigned long long>(loaded_->mesh.MemoryBytes()), loaded_->load_ms,
        loaded_->build_ms);
  }

 private:
  absl::StatusOr<const DistanceField*> CachedField(const std::vector<SurfacePoint>& sources,
                                                   const GeodesicOptions& options) {
    const std::string key = Key(sources, options);
    if (field_ != nullptr && key == field_key_) return field_.get();
    absl::StatusOr<DistanceField> field = ComputeDistanceField(loaded_->mesh, sources, options);
    if (!field.ok()) return field.status();
    field_ = std::make_unique<DistanceField>(*std::move(field));
    field_key_ = key;
    field_unlimited_key_ = Key(sources, Unlimited(options));
    field_max_distance_ = options.max_distance;
    return field_.get();
  }

  // As CachedField, but a field solved further (a larger max_distance, all else the same) serves:
  // its values up to the smaller limit are the same. Isolines drawn on render's whole field reuse
  // it (and the pointer render holds stays valid).
  absl::StatusOr<const DistanceField*> CachedFieldWithin(const std::vector<SurfacePoint>& sources,
                                                         const GeodesicOptions& options) {
    if (field_ != nullptr && field_max_distance_ >= options.max_distance &&
        Key(sources, Unlimited(options)) == field_unlimited_key_) {
      return field_.get();
    }
    return CachedField(sources, options);
  }
  static GeodesicOptions Unlimited(GeodesicOptions options) {
    options.max_distance = std::numeric_limits<double>::infinity();
    return options;
  }

  std::unique_ptr<LoadedMesh> loaded_;
  std::unique_ptr<SurfaceLocator> locator_;  // built on the first p:X:Y:Z point
  std::unique_ptr<DistanceField> field_;     // the last sources' field
  std::string field_key_;
  std::string field_unlimited_key_;  // field_key_ with no max_distance
  double field_max_distance_ = 0;
};

}  // namespace

std::unique_ptr<Backend> MakeLocalBackend() { return std::make_unique<LocalBackend>(); }

}  // namespace geodex::cli
