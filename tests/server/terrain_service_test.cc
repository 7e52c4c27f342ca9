// DEMs through geodexd: GeoTIFF bytes uploaded (MESH_FORMAT_GEOTIFF), the map kept with the stored
// mesh (Mesh.terrain, across restarts), and map points (SurfacePoint.map_point, lon_lat) dropped
// by the server exactly as the CLI drops them locally. Fixtures are made with GDAL at test time.

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "cpl_vsi.h"
#include "gdal_priv.h"
#include "geodex/distance_field.h"
#include "geodex/friction.h"
#include "geodex/geodesic_solver.h"
#include "geodex/geodex_client.h"
#include "geodex/mesh_id.h"
#include "geodex/mesh_io.h"
#include "geodex/terrain.h"
#include "geodex/triangle_mesh.h"
#include "gtest/gtest.h"
#include "ogr_spatialref.h"
#include "server_test_util.h"

namespace geodex::server {
namespace {

namespace fs = std::filesystem;

using testing::BadField;
using testing::Contains;

// A TCP listener on 127.0.0.1, on a port the kernel picks, that counts the connections made to it
// (each accepted and closed at once) until it is destroyed: what geodexd must never reach.
class ConnectionCounter {
 public:
  ConnectionCounter() {
    fd_ = socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    address.sin_port = 0;
    socklen_t size = sizeof(address);
    if (fd_ < 0 || bind(fd_, reinterpret_cast<sockaddr*>(&address), sizeof(address)) != 0 ||
        listen(fd_, 16) != 0 ||
        getsockname(fd_, reinterpret_cast<sockaddr*>(&address), &size) != 0) {
      ADD_FAILURE() << "cannot listen on 127.0.0.1";
      return;
    }
    port_ = ntohs(address.sin_port);
    thread_ = std::thread([this] {
      while (!stop_) {
        pollfd p{fd_, POLLIN, 0};
        if (poll(&p, 1, 50) == 1) {
          int client = accept(fd_, nullptr, nullptr);
          if (client >= 0) {
            ++connections_;
            close(client);
          }
        }
      }
    });
  }
  ~ConnectionCounter() {
    stop_ = true;
    if (thread_.joinable()) thread_.join();
    if (fd_ >= 0) close(fd_);
  }
  std::string Url(const std::string& path) const {
    return absl::StrCat("http://127.0.0.1:", port_, path);
  }
  int connections() const { return connections_; }

 private:
  int fd_ = -1;
  int port_ = 0;
  std::atomic<bool> stop_{false};
  std::atomic<int> connections_{0};
  std::thread thread_;
};

class TerrainServiceTest : public testing::ServerFixture {
 protected:
  void SetUp() override {
    GDALAllRegister();
    dir_ = fs::path(::testing::TempDir()) /
           absl::StrCat("geodex-terrain-svc-", ::testing::UnitTest::GetInstance()->random_seed(),
                        "-", ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_ / "in");
    // A tilted plane in UTM 33N, 10 m cells, with a nodata slot (columns 14-15, rows 5 down).
    tif_ = (dir_ / "in" / "slot.tif").string();
    GDALDriver* driver = GetGDALDriverManager()->GetDriverByName("GTiff");
    GDALDataset* ds = driver->Create(tif_.c_str(), 30, 30, 1, GDT_Float32, nullptr);
    double gt[6] = {500000, 10, 0, 5000000, 0, -10};
    ds->SetGeoTransform(gt);
    OGRSpatialReference srs;
    srs.importFromEPSG(32633);
    ds->SetSpatialRef(&srs);
    GDALRasterBand* band = ds->GetRasterBand(1);
    band->SetNoDataValue(-9999);
    std::vector<float> row(30);
    for (int j = 0; j < 30; ++j) {
      for (int i = 0; i < 30; ++i) {
        row[i] = (i == 14 || i == 15) && j >= 5 ? -9999.0f : static_cast<float>(0.5 * i + 0.25 * j);
      }
      EXPECT_EQ(band->RasterIO(GF_Write, 0, j, 30, 1, row.data(), 30, 1, GDT_Float32, 0, 0),
                CE_None);
    }
    GDALClose(ds);
    std::ifstream in(tif_, std::ios::binary);
    bytes_.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  void TearDown() override {
    testing::ServerFixture::TearDown();
    server_.reset();
    fs::remove_all(dir_);
  }
  void Restart(ServerOptions options = {}) {
    if (server_) server_->Shutdown(absl::Now() + absl::Seconds(10));
    server_.reset();
    options.data_dir = (dir_ / "data").string();
    StartServer(options);
  }

  testing::UploadResult UploadDem(const std::string& bytes, const std::string& name,
                                  v1::MeshFormat format = v1::MESH_FORMAT_GEOTIFF,
                                  const std::string& file_name = "slot.tif", uint32_t step = 0,
                                  double z_tolerance = 0) {
    testing::UploadResult result;
    grpc::ClientContext context;
    context.set_deadline(testing::In(120));
    auto writer = stub_->CreateMesh(&context, &result.mesh);
    v1::CreateMeshRequest request;
    request.mutable_metadata()->set_format(format);
    request.mutable_metadata()->set_file_name(file_name);
    request.mutable_metadata()->set_display_name(name);
    if (step != 0) request.mutable_metadata()->mutable_dem()->set_step(step);
    if (z_tolerance != 0) request.mutable_metadata()->mutable_dem()->set_z_tolerance(z_tolerance);
    writer->Write(request);
    request.Clear();
    request.set_chunk(bytes);
    writer->Write(request);
    writer->WritesDone();
    result.status = writer->Finish();
    return result;
  }

  // The field of one source given as a v1 point.
  testing::FieldResult FieldFrom(const std::string& mesh, const v1::SurfacePoint& source) {
    v1::ComputeDistanceFieldRequest request;
    request.set_mesh(mesh);
    *request.add_sources() = source;
    return testing::ReadField(*stub_, request);
  }
  static v1::SurfacePoint FacePointOf(const SurfacePoint& p) {
    v1::SurfacePoint out;
    out.mutable_face()->set_face(p.face);
    out.mutable_face()->set_b0(p.bary[0]);
    out.mutable_face()->set_b1(p.bary[1]);
    out.mutable_face()->set_b2(p.bary[2]);
    return out;
  }

  fs::path dir_;
  std::string tif_, bytes_;
};

TEST_F(TerrainServiceTest, GeoTiffUploadKeepsItsMapAndTakesMapPoints) {
  StartServer();
  absl::StatusOr<terrain::Dem> local = terrain::Dem::Read(tif_);
  ASSERT_TRUE(local.ok()) << local.status();
  testing::UploadResult up = UploadDem(bytes_, "slot");
  ASSERT_TRUE(up.status.ok()) << up.status.error_message();
  // The same mesh (the same id) the CLI makes of the file, with its map.
  EXPECT_EQ(up.mesh.name(), absl::StrCat("meshes/", ComputeMeshId(local->mesh())));
  ASSERT_TRUE(up.mesh.has_terrain());
  const v1::Terrain& t = up.mesh.terrain();
  EXPECT_TRUE(Contains(t.crs_name(), "UTM zone 33N")) << t.crs_name();
  EXPECT_EQ(t.grid_width(), 30u);
  EXPECT_EQ(t.nodata_cells(), 50u);
  EXPECT_EQ(t.driver(), "GTiff");
  ASSERT_EQ(t.geotransform_size(), 6);
  EXPECT_EQ(t.geotransform(1), 10);
  // The C++ client gives the same map as plain values (ServerMesh::map: its header names no
  // generated or uninstalled type).
  client::ClientOptions client_options;
  client_options.target = absl::StrCat("127.0.0.1:", server_->port());
  client::GeodexClient client(client_options);
  absl::StatusOr<client::ServerMesh> got = client.GetMesh(up.mesh.name());
  ASSERT_TRUE(got.ok()) << got.status();
  ASSERT_TRUE(got->map.has_value());
  EXPECT_EQ(got->map->crs_name, t.crs_name());
  EXPECT_EQ(got->map->crs_wkt, t.crs_wkt());
  EXPECT_EQ(got->map->grid_width, 30u);
  EXPECT_EQ(got->map->nodata_cells, 50u);
  EXPECT_EQ(got->map->driver, "GTiff");
  for (int i = 0; i < 6; ++i) EXPECT_EQ(got->map->geotransform[i], t.geotransform(i)) << i;

  // A map point in the raster's CRS, and a longitude/latitude: the server drops them where the
  // CLI does, and the fields are the same to the bit.
  OGRSpatialReference utm, wgs84;
  utm.importFromEPSG(32633);
  wgs84.importFromEPSG(4326);
  utm.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  wgs84.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  OGRCoordinateTransformation* to_ll = OGRCreateCoordinateTransformation(&utm, &wgs84);
  ASSERT_NE(to_ll, nullptr);
  double lon = 500123.4, lat = 4999871.2;
  ASSERT_TRUE(to_ll->Transform(1, &lon, &lat));
  OGRCoordinateTransformation::DestroyCT(to_ll);
  v1::SurfacePoint map;
  map.mutable_map_point()->set_x(500061.7);
  map.mutable_map_point()->set_y(4999822.9);
  v1::SurfacePoint ll;
  ll.mutable_lon_lat()->set_lon(lon);
  ll.mutable_lon_lat()->set_lat(lat);
  absl::StatusOr<SurfacePoint> map_here = local->DropMapPoint(500061.7, 4999822.9);
  absl::StatusOr<SurfacePoint> ll_here = local->DropLonLat(lon, lat);
  ASSERT_TRUE(map_here.ok() && ll_here.ok());
  for (const auto& [remote, here] : {std::pair{map, *map_here}, std::pair{ll, *ll_here}}) {
    testing::FieldResult by_map = FieldFrom("meshes/slot", remote);
    ASSERT_TRUE(by_map.status.ok()) << by_map.status.error_message();
    testing::FieldResult by_face = FieldFrom("meshes/slot", FacePointOf(here));
    ASSERT_TRUE(by_face.status.ok()) << by_face.status.error_message();
    ASSERT_EQ(by_map.distances.size(), local->mesh().vertex_count());
    EXPECT_EQ(by_map.distances, by_face.distances);
    EXPECT_GT(*std::max_element(by_map.distances.begin(), by_map.distances.end()), 200);
  }

  // A point in the hole, or off the DEM, names itself and its field.
  v1::SurfacePoint hole;
  hole.mutable_map_point()->set_x(500150);
  hole.mutable_map_point()->set_y(4999800);
  testing::FieldResult in_hole = FieldFrom("meshes/slot", hole);
  EXPECT_EQ(in_hole.status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_EQ(BadField(in_hole.status), "sources[0].map_point");
  EXPECT_TRUE(Contains(in_hole.status.error_message(), "in a hole of the DEM"))
      << in_hole.status.error_message();
  v1::SurfacePoint far;
  far.mutable_lon_lat()->set_lon(-70);
  far.mutable_lon_lat()->set_lat(10);
  testing::FieldResult off = FieldFrom("meshes/slot", far);
  EXPECT_EQ(off.status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_EQ(BadField(off.status), "sources[0].lon_lat");

  // On a mesh that is not a DEM's, map points are refused, naming why.
  ASSERT_TRUE(testing::Upload(*stub_, testing::GridOff(4, 4, false), "grid").status.ok());
  testing::FieldResult not_dem = FieldFrom("meshes/grid", map);
  EXPECT_EQ(not_dem.status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_TRUE(Contains(not_dem.status.error_message(), "not a DEM's"))
      << not_dem.status.error_message();
}

TEST_F(TerrainServiceTest, UploadsAreCheckedAndLimited) {
  ServerOptions options;
  options.limits.max_dem_cells = 899;  // the raster has 900
  StartServer(options);
  testing::UploadResult big = UploadDem(bytes_, "big");
  EXPECT_EQ(big.status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_TRUE(Contains(big.status.error_message(), "(server flag --max_dem_cells)"))
      << big.status.error_message();
  // The mesh's limits hold before any row is read too.
  options.limits.max_dem_cells = 900;
  options.limits.max_vertices = 899;
  StartServer(options);
  testing::UploadResult many = UploadDem(bytes_, "many");
  EXPECT_EQ(many.status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_TRUE(Contains(many.status.error_message(), "(server flag --max_vertices)"))
      << many.status.error_message();
  options.limits.max_vertices = 900;
  options.limits.max_faces = 2 * 29 * 29 - 1;
  StartServer(options);
  testing::UploadResult faces = UploadDem(bytes_, "faces");
  EXPECT_TRUE(Contains(faces.status.error_message(), "(server flag --max_faces)"))
      << faces.status.error_message();

  StartServer();
  // Not a GeoTIFF, a cut one, DEM options on a mesh file: INVALID_ARGUMENT naming the field.
  testing::UploadResult junk = UploadDem("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", "junk");
  EXPECT_EQ(junk.status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_EQ(BadField(junk.status), "chunk");
  EXPECT_TRUE(Contains(junk.status.error_message(), "not a GeoTIFF"))
      << junk.status.error_message();
  testing::UploadResult cut = UploadDem(bytes_.substr(0, bytes_.size() / 2), "cut");
  EXPECT_EQ(cut.status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  testing::UploadResult options_on_off =
      UploadDem(testing::GridOff(3, 3, false), "off", v1::MESH_FORMAT_OFF, "grid.off", 2);
  EXPECT_EQ(options_on_off.status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_EQ(BadField(options_on_off.status), "metadata.dem");

  // The format is guessed from the name, or else from the bytes; the step is the CLI's --dem-step.
  testing::UploadResult named = UploadDem(bytes_, "", v1::MESH_FORMAT_UNSPECIFIED, "x.TIF", 2);
  ASSERT_TRUE(named.status.ok()) << named.status.error_message();
  EXPECT_EQ(named.mesh.terrain().grid_width(), 15u);
  // Used column 7 is file column 14: no data from used row 3 (file row 6) down.
  EXPECT_EQ(named.mesh.vertex_count(), 15u * 15u - 12u);
  testing::UploadResult sniffed = UploadDem(bytes_, "", v1::MESH_FORMAT_UNSPECIFIED, "upload");
  ASSERT_TRUE(sniffed.status.ok()) << sniffed.status.error_message();
  EXPECT_EQ(sniffed.mesh.terrain().grid_width(), 30u);
}

// The map survives a restart (the stored header, version 3), and the grid is rebuilt from the
// stored mesh: map points still drop. A DEM's mesh first stored as a mesh file gains its map.
TEST_F(TerrainServiceTest, TheMapIsStoredAndGained) {
  Restart();
  absl::StatusOr<terrain::Dem> local = terrain::Dem::Read(tif_);
  ASSERT_TRUE(local.ok());
  const std::string off = (dir_ / "in" / "slot.off").string();
  ASSERT_TRUE(WriteMeshOff(off, local->mesh()).ok());
  std::ifstream in(off, std::ios::binary);
  const std::string off_bytes((std::istreambuf_iterator<char>(in)),
                              std::istreambuf_iterator<char>());
  testing::UploadResult plain = testing::Upload(*stub_, off_bytes, "plain");
  ASSERT_TRUE(plain.status.ok()) << plain.status.error_message();
  EXPECT_FALSE(plain.mesh.has_terrain());
  v1::SurfacePoint map;
  map.mutable_map_point()->set_x(500230.5);
  map.mutable_map_point()->set_y(4999905.5);
  EXPECT_EQ(FieldFrom("meshes/plain", map).status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);

  testing::UploadResult dem = UploadDem(bytes_, "slot");
  ASSERT_TRUE(dem.status.ok()) << dem.status.error_message();
  EXPECT_EQ(dem.mesh.name(), plain.mesh.name());
  ASSERT_TRUE(dem.mesh.has_terrain());
  testing::FieldResult before = FieldFrom("meshes/plain", map);
  ASSERT_TRUE(before.status.ok()) << before.status.error_message();
  // The grid it gained is counted in the budget, once.
  EXPECT_GT(dem.mesh.memory_bytes(), plain.mesh.memory_bytes());
  EXPECT_EQ(server_->store().used_bytes(), dem.mesh.memory_bytes());

  Restart();
  v1::Mesh got;
  {
    grpc::ClientContext context;
    context.set_deadline(testing::In(30));
    v1::GetMeshRequest request;
    request.set_name("meshes/slot");
    ASSERT_TRUE(stub_->GetMesh(&context, request, &got).ok());
  }
  ASSERT_TRUE(got.has_terrain());
  EXPECT_EQ(got.terrain().crs_wkt(), dem.mesh.terrain().crs_wkt());
  EXPECT_EQ(got.terrain().nodata_cells(), 50u);
  testing::FieldResult after = FieldFrom("meshes/slot", map);
  ASSERT_TRUE(after.status.ok()) << after.status.error_message();
  EXPECT_EQ(after.distances, before.distances);
}

// Barriers as a request: DeriveMesh leaves out the faces a barrier covers and stores the result by
// its content. On a DEM's mesh a GeoJSON wall (in longitude/latitude) gives exactly the mesh the
// CLI makes with --barrier (the same id), map points still drop, and paths go around the wall.
TEST_F(TerrainServiceTest, DeriveMeshByABarrier) {
  StartServer();
  testing::UploadResult slot = UploadDem(bytes_, "slot");
  ASSERT_TRUE(slot.status.ok());
  auto derive = [&](const std::string& mesh, const v1::Barrier& barrier, const std::string& name,
                    v1::Mesh* out) {
    grpc::ClientContext context;
    context.set_deadline(testing::In(120));
    v1::DeriveMeshRequest request;
    request.set_mesh(mesh);
    *request.mutable_barrier() = barrier;
    request.set_display_name(name);
    return stub_->DeriveMesh(&context, request, out);
  };
  // A wall of columns 5-6 from the top edge down to row 20, as a WGS 84 polygon.
  OGRSpatialReference utm, wgs84;
  utm.importFromEPSG(32633);
  wgs84.importFromEPSG(4326);
  utm.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  wgs84.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  OGRCoordinateTransformation* to_ll = OGRCreateCoordinateTransformation(&utm, &wgs84);
  ASSERT_NE(to_ll, nullptr);
  std::string ring;
  for (auto [x, y] : std::vector<std::pair<double, double>>{{500052, 5000010},
                                                            {500052, 4999795},
                                                            {500068, 4999795},
                                                            {500068, 5000010},
                                                            {500052, 5000010}}) {
    ASSERT_TRUE(to_ll->Transform(1, &x, &y));
    absl::StrAppendFormat(&ring, "%s[%.15f, %.15f]", ring.empty() ? "" : ", ", x, y);
  }
  OGRCoordinateTransformation::DestroyCT(to_ll);
  const std::string geojson = absl::StrCat(
      R"({"type": "FeatureCollection", "features": [{"type": "Feature", "properties": {}, )",
      R"("geometry": {"type": "Polygon", "coordinates": [[)", ring, "]]}}]}");
  const std::string wall_file = (dir_ / "in" / "wall.geojson").string();
  std::ofstream(wall_file) << geojson;
  terrain::DemOptions with_wall;
  with_wall.barrier_files = {wall_file};
  absl::StatusOr<terrain::Dem> local = terrain::Dem::Read(tif_, with_wall);
  ASSERT_TRUE(local.ok()) << local.status();
  // x 500052-500068 cuts block columns 4 and 6 and covers column 5, rows 0-19: a wall
  ASSERT_EQ(local->info().barrier_faces, 120u);

  v1::Barrier wall;
  wall.set_polygons_geojson(geojson);
  v1::Mesh walled;
  grpc::Status status = derive("meshes/slot", wall, "walled", &walled);
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_EQ(walled.name(), absl::StrCat("meshes/", ComputeMeshId(local->mesh())));
  EXPECT_EQ(walled.vertex_count(), local->mesh().vertex_count());
  ASSERT_TRUE(walled.has_terrain());
  EXPECT_EQ(walled.terrain().barrier_faces(), local->info().barrier_faces);
  v1::Mesh again;
  ASSERT_TRUE(derive("meshes/slot", wall, "", &again).ok());
  EXPECT_EQ(again.name(), walled.name());  // by content: the same mesh

  // A map point west of the wall to one east of it: the path goes around the wall's foot.
  v1::SurfacePoint west;
  west.mutable_map_point()->set_x(500025);
  west.mutable_map_point()->set_y(4999945);
  testing::FieldResult open = FieldFrom("meshes/slot", west);
  testing::FieldResult around = FieldFrom("meshes/walled", west);
  ASSERT_TRUE(open.status.ok() && around.status.ok()) << around.status.error_message();
  const uint32_t east = local->VertexAt(10, 4);
  EXPECT_GT(around.distances[east], open.distances[east] + 100);
  // The CLI's local mesh gives the same field to the bit.
  absl::StatusOr<TriangleMesh> built = TriangleMesh::Build(local->mesh());
  ASSERT_TRUE(built.ok());
  absl::StatusOr<SurfacePoint> west_here = local->DropMapPoint(500025, 4999945);
  ASSERT_TRUE(west_here.ok());
  absl::StatusOr<DistanceField> here =
      ComputeDistanceField(*built, {*west_here}, GeodesicOptions{});
  ASSERT_TRUE(here.ok());
  EXPECT_EQ(around.distances, here->distance);

  // Below a height: faces with a corner lower than 2.6 m go (the top-left corner: 0.5 col +
  // 0.25 row), and vertex 0 (height 0) is unreachable from the far corner.
  v1::Barrier low;
  low.set_below(2.6);
  v1::Mesh dry;
  ASSERT_TRUE(derive("meshes/slot", low, "dry", &dry).ok());
  EXPECT_LT(dry.face_count(), slot.mesh.face_count());
  testing::FieldResult from_far =
      testing::ReadField(*stub_, testing::FieldRequest("meshes/dry", {849}));
  ASSERT_TRUE(from_far.status.ok()) << from_far.status.error_message();
  EXPECT_TRUE(std::isinf(from_far.distances[0]));
  EXPECT_TRUE(std::isfinite(from_far.distances[849 - 1]));

  // On a mesh without a map, polygons are in its own x y.
  ASSERT_TRUE(testing::Upload(*stub_, testing::GridOff(6, 6, false), "grid").status.ok());
  v1::Barrier square;
  square.set_polygons_geojson(
      R"({"type": "Polygon", "coordinates": [[[2, -1], [4, -1], [4, 7], [2, 7], [2, -1]]]})");
  v1::Mesh cut;
  ASSERT_TRUE(derive("meshes/grid", square, "", &cut).ok());
  EXPECT_EQ(cut.face_count(), 72u - 24u);  // columns 2 and 3: 2 cells x 6 rows x 2 triangles
  EXPECT_FALSE(cut.has_terrain());

  // Errors name the field.
  v1::Mesh none;
  grpc::Status empty = derive("meshes/slot", v1::Barrier(), "", &none);
  EXPECT_EQ(empty.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_EQ(BadField(empty), "barrier");
  v1::Barrier junk;
  junk.set_polygons_geojson("{not json");
  grpc::Status bad_json = derive("meshes/slot", junk, "", &none);
  EXPECT_EQ(BadField(bad_json), "barrier.polygons_geojson") << bad_json.error_message();
  v1::Barrier everything;
  everything.set_below(1e9);
  grpc::Status all = derive("meshes/slot", everything, "", &none);
  EXPECT_TRUE(Contains(all.error_message(), "covers every face")) << all.error_message();
  grpc::Status taken = derive("meshes/slot", low, "walled", &none);  // another mesh's alias
  EXPECT_EQ(BadField(taken), "display_name") << taken.error_message();
  EXPECT_EQ(taken.error_message().rfind("display_name: \"walled\" already names mesh", 0), 0u)
      << taken.error_message();
  // Text that is not a GeoJSON object is never taken for a path or a URL.
  for (const char* text :
       {"/etc/passwd", "https://127.0.0.1:1/x.geojson", "/vsimem/geodex-dem-0.tif"}) {
    v1::Barrier path;
    path.set_polygons_geojson(text);
    grpc::Status refused = derive("meshes/slot", path, "", &none);
    EXPECT_EQ(BadField(refused), "barrier.polygons_geojson") << text;
    EXPECT_TRUE(Contains(refused.error_message(), "not GeoJSON (a JSON object"))
        << refused.error_message();
  }
}

// Friction polygons as a request: DeriveMesh with friction_geojson cuts their outlines into the
// DEM's mesh (nothing removed): exactly the mesh the CLI makes for --friction F.geojson (the same
// id), map points still drop, and a travel field on it with the same polygons equals core's on the
// CLI's mesh. Bad polygons name the field.
TEST_F(TerrainServiceTest, DeriveMeshByFrictionOutlines) {
  StartServer();
  testing::UploadResult slot = UploadDem(bytes_, "slot");
  ASSERT_TRUE(slot.status.ok());
  // A band of friction 3, its edges 20 degrees off the grid, in the DEM's CRS by identifier.
  const double t = std::tan(20 * M_PI / 180);
  const std::string geojson = absl::StrFormat(
      R"({"type": "FeatureCollection", "crs": {"type": "name", "properties": {"name":
      "EPSG:32633"}}, "features": [{"type": "Feature", "properties": {"friction": 3},
      "geometry": {"type": "Polygon", "coordinates": [[[%.17g, 4999700], [%.17g, 4999700],
      [%.17g, 5000100], [%.17g, 5000100], [%.17g, 4999700]]]}}]})",
      500080.0, 500130.0, 500130 + 400 * t, 500080 + 400 * t, 500080.0);
  const std::string band_file = (dir_ / "in" / "band.geojson").string();
  std::ofstream(band_file) << geojson;
  terrain::DemOptions with_band;
  with_band.friction_file = band_file;
  absl::StatusOr<terrain::Dem> local = terrain::Dem::Read(tif_, with_band);
  ASSERT_TRUE(local.ok()) << local.status();

  auto derive = [&](const std::string& friction, v1::Mesh* out) {
    grpc::ClientContext context;
    context.set_deadline(testing::In(120));
    v1::DeriveMeshRequest request;
    request.set_mesh("meshes/slot");
    request.set_friction_geojson(friction);
    request.set_display_name("banded");
    return stub_->DeriveMesh(&context, request, out);
  };
  v1::Mesh banded;
  grpc::Status status = derive(geojson, &banded);
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_EQ(banded.name(), absl::StrCat("meshes/", ComputeMeshId(local->mesh())));
  EXPECT_EQ(banded.face_count(), local->mesh().face_count());
  EXPECT_GT(banded.face_count(), slot.mesh.face_count() + 20);  // the faces split along it
  ASSERT_TRUE(banded.has_terrain());

  // Travel from a map point west of the band: the field equals core's on the CLI's mesh.
  v1::ComputeDistanceFieldRequest request;
  request.set_mesh("meshes/banded");
  request.add_sources()->mutable_map_point()->set_x(500025);
  request.mutable_sources(0)->mutable_map_point()->set_y(4999945);
  v1::TravelCost* travel = request.mutable_options()->mutable_travel();
  travel->set_speed_kmh(3.6);
  travel->set_epsilon(0.05);
  travel->set_friction_geojson(geojson);
  testing::FieldResult got = testing::ReadField(*stub_, request);
  ASSERT_TRUE(got.status.ok()) << got.status.error_message();
  absl::StatusOr<std::vector<double>> friction =
      terrain::FrictionFromGeoJson(local->mesh(), geojson, &local->info(), "friction");
  ASSERT_TRUE(friction.ok()) << friction.status();
  absl::StatusOr<TriangleMesh> built = TriangleMesh::Build(local->mesh());
  ASSERT_TRUE(built.ok());
  absl::StatusOr<SurfacePoint> west = local->DropMapPoint(500025, 4999945);
  ASSERT_TRUE(west.ok());
  GeodesicOptions options;
  options.travel = TravelCost{};
  options.travel->speed_kmh = 3.6;
  options.travel->epsilon = 0.05;
  options.travel->face_weight = std::make_shared<const std::vector<double>>(*friction);
  absl::StatusOr<DistanceField> want = ComputeDistanceField(*built, {*west}, options);
  ASSERT_TRUE(want.ok()) << want.status();
  EXPECT_EQ(got.distances, want->distance);

  v1::Mesh none;
  grpc::Status bad = derive(R"({"type": "Feature", "properties": {}, "geometry":
      {"type": "Polygon", "coordinates": [[[0, 0], [1, 0], [1, 1], [0, 0]]]}})",
                            &none);
  EXPECT_EQ(bad.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_EQ(BadField(bad), "friction_geojson") << bad.error_message();
  EXPECT_TRUE(Contains(bad.error_message(), "no numeric \"friction\"")) << bad.error_message();
}

// geodexd never reaches out (issue 30): no URL, file or driver that a request names is followed.
// Each hostile input is refused as INVALID_ARGUMENT naming its field, quickly (a followed link
// waited 10 s on a silent peer), no connection reaches the listener, and the server goes on
// serving.
TEST_F(TerrainServiceTest, NoRequestMakesTheServerReachOut) {
  ConnectionCounter listener;
  StartServer();
  ASSERT_TRUE(UploadDem(bytes_, "slot").status.ok());
  const std::string polygon =
      R"("type": "Polygon", "coordinates": [[[500100, 4999900], [500200, 4999900], [500200, 4999800], [500100, 4999900]]])";
  auto collection = [&](const std::string& crs) {
    return absl::StrCat(R"({"type": "FeatureCollection", "crs": )", crs,
                        R"(, "features": [{"type": "Feature", "properties": {}, "geometry": {)",
                        polygon, "}}]}");
  };
  const std::vector<std::string> texts = {
      collection(absl::StrCat(R"({"type": "link", "properties": {"href": ")", listener.Url("/crs"),
                              R"(", "type": "proj4"}})")),
      collection(absl::StrCat(R"({"type": "url", "properties": {"url": ")", listener.Url("/crs"),
                              R"("}})")),
      collection(absl::StrCat(R"({"type": "name", "properties": {"name": ")", listener.Url("/crs"),
                              R"("}})")),
      collection(absl::StrCat(R"({"type": "LINK", "properties": {"href": ")", listener.Url("/crs"),
                              R"("}})")),
      collection(R"({"type": "name", "properties": {"name": "/etc/passwd"}})"),
      collection(R"({"type": "OGC", "properties": {"urn": "urn:ogc:def:crs:EPSG::32633"}})"),
      // GDAL reads the first "name" in any case, a check reading the last would pass a PROJ string
      // naming a local grid file: names differing only in case are refused.
      collection(
          R"({"type": "name", "properties": {"NAME": "+proj=longlat +datum=WGS84 +nadgrids=/etc/passwd +type=crs", "name": "EPSG:4326"}})"),
      collection(R"({"TYPE": "link", "type": "name", "properties": {"name": "EPSG:4326"}})"),
      // A crs on a geometry, and a member spelled in capitals: GDAL follows both.
      absl::StrCat(
          R"({"type": "Feature", "properties": {}, "geometry": {"CRS": {"type": "link", "properties": {"href": ")",
          listener.Url("/geometry-crs"), R"("}}, )", polygon, "}}"),
      absl::StrCat("/vsicurl/", listener.Url("/x.geojson")),
      "/vsimem/geodex-0.geojson",
      "file:///etc/passwd",
      "/etc/passwd",
      "barrier.geojson",
      listener.Url("/x.geojson"),
      absl::StrCat(R"(<OGRVRTDataSource><OGRVRTLayer name="x"><SrcDataSource>/vsicurl/)",
                   listener.Url("/v.geojson"), "</SrcDataSource></OGRVRTLayer></OGRVRTDataSource>"),
  };
  for (const std::string& text : texts) {
    v1::DeriveMeshRequest request;
    request.set_mesh("meshes/slot");
    request.mutable_barrier()->set_polygons_geojson(text);
    v1::Mesh derived;
    grpc::ClientContext context;
    context.set_deadline(testing::In(60));
    const auto start = std::chrono::steady_clock::now();
    grpc::Status status = stub_->DeriveMesh(&context, request, &derived);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << text;
    EXPECT_EQ(BadField(status), "barrier.polygons_geojson")
        << text << ": " << status.error_message();
    EXPECT_LT(seconds, 5) << text;  // generous; a followed link waits 10 s
  }
  // A crs named by an identifier is still read (and reprojected): the same wall as without it.
  v1::DeriveMeshRequest named;
  named.set_mesh("meshes/slot");
  named.mutable_barrier()->set_polygons_geojson(
      collection(R"({"type": "name", "properties": {"name": "urn:ogc:def:crs:EPSG::32633"}})"));
  v1::Mesh named_mesh;
  grpc::ClientContext named_context;
  named_context.set_deadline(testing::In(60));
  grpc::Status named_status = stub_->DeriveMesh(&named_context, named, &named_mesh);
  EXPECT_TRUE(named_status.ok()) << named_status.error_message();

  // GeoTIFFs: an overview file named in the file's own metadata (a URL, a local file), and a VRT
  // sent as a GeoTIFF, are refused; a URL in an ordinary metadata item is only text.
  auto tiff_with = [&](const std::string& key, const std::string& value, const char* domain) {
    const std::string path = (dir_ / "in" / absl::StrCat("meta-", key, ".tif")).string();
    GDALDataset* ds = GetGDALDriverManager()->GetDriverByName("GTiff")->CreateCopy(
        path.c_str(), GDALDataset::FromHandle(GDALOpen(tif_.c_str(), GA_ReadOnly)), FALSE, nullptr,
        nullptr, nullptr);
    EXPECT_NE(ds, nullptr);
    ds->SetMetadataItem(key.c_str(), value.c_str(), domain);
    GDALClose(ds);
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  };
  const std::string local_overview = (dir_ / "in" / "secret.tif").string();
  fs::copy_file(tif_, local_overview);
  for (const std::string& target :
       {absl::StrCat("/vsicurl/", listener.Url("/o.tif")), local_overview}) {
    const auto start = std::chrono::steady_clock::now();
    testing::UploadResult refused = UploadDem(tiff_with("OVERVIEW_FILE", target, "OVERVIEWS"), "");
    EXPECT_EQ(refused.status.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << target;
    EXPECT_EQ(BadField(refused.status), "chunk") << refused.status.error_message();
    EXPECT_TRUE(Contains(refused.status.error_message(), "external overview file"))
        << refused.status.error_message();
    EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 5);
  }
  testing::UploadResult harmless =
      UploadDem(tiff_with("SOURCE", listener.Url("/meta"), nullptr), "");
  EXPECT_TRUE(harmless.status.ok()) << harmless.status.error_message();
  const std::string vrt = absl::StrCat(
      R"(<VRTDataset rasterXSize="30" rasterYSize="30"><VRTRasterBand dataType="Float32" band="1"><SimpleSource>)",
      "<SourceFilename>/vsicurl/", listener.Url("/src.tif"),
      "</SourceFilename><SourceBand>1</SourceBand>",
      "</SimpleSource></VRTRasterBand></VRTDataset>");
  for (v1::MeshFormat format : {v1::MESH_FORMAT_GEOTIFF, v1::MESH_FORMAT_UNSPECIFIED}) {
    testing::UploadResult refused = UploadDem(vrt, "", format, "dem.vrt");
    EXPECT_EQ(refused.status.error_code(), grpc::StatusCode::INVALID_ARGUMENT)
        << refused.status.error_message();
  }

  // Nothing reached the listener, and geodexd still serves.
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  EXPECT_EQ(listener.connections(), 0);
  client::ClientOptions options;
  options.target = absl::StrCat("127.0.0.1:", server_->port());
  client::GeodexClient client(options);
  absl::StatusOr<bool> health = client.Health();
  ASSERT_TRUE(health.ok()) << health.status();
  EXPECT_TRUE(*health);
}

// A GeoTIFF uploaded with dem.z_tolerance: the adaptive TIN the CLI makes (the same mesh id), its
// deviations in the Terrain, kept across a restart (mesh file version 4); map points drop onto it
// and its distance raster is the one made here. A bad tolerance names its field.
TEST_F(TerrainServiceTest, AdaptiveTinUploadIsTheClisTin) {
  Restart();
  terrain::DemOptions options;
  options.z_tolerance = 0.25;
  absl::StatusOr<terrain::Dem> local = terrain::Dem::Read(tif_, options);
  ASSERT_TRUE(local.ok()) << local.status();
  ASSERT_LT(local->mesh().vertex_count(), 100u);  // a plane with a slot: a few vertices
  testing::UploadResult up = UploadDem(bytes_, "tin", v1::MESH_FORMAT_GEOTIFF, "slot.tif", 0, 0.25);
  ASSERT_TRUE(up.status.ok()) << up.status.error_message();
  EXPECT_EQ(up.mesh.name(), absl::StrCat("meshes/", ComputeMeshId(local->mesh())));
  EXPECT_EQ(up.mesh.terrain().z_tolerance(), 0.25);
  EXPECT_EQ(up.mesh.terrain().max_vertical_deviation(), local->info().max_vertical_deviation);
  EXPECT_EQ(up.mesh.vertex_count(), local->mesh().vertex_count());

  Restart();  // loaded back from the data directory
  v1::ExportGisRequest request;
  request.set_mesh("meshes/tin");
  request.set_product(v1::GIS_PRODUCT_DISTANCE_RASTER);
  request.add_sources()->mutable_map_point()->set_x(500061.7);
  request.mutable_sources(0)->mutable_map_point()->set_y(4999822.9);
  grpc::ClientContext context;
  context.set_deadline(testing::In(120));
  auto reader = stub_->ExportGis(&context, request);
  v1::ExportGisResponse message;
  std::string tiff;
  while (reader->Read(&message)) tiff += message.data();
  grpc::Status status = reader->Finish();
  ASSERT_TRUE(status.ok()) << status.error_message();
  absl::StatusOr<TriangleMesh> built = TriangleMesh::Build(local->mesh());
  ASSERT_TRUE(built.ok());
  absl::StatusOr<SurfacePoint> source = local->DropMapPoint(500061.7, 4999822.9);
  ASSERT_TRUE(source.ok());
  absl::StatusOr<DistanceField> field = ComputeDistanceField(*built, {*source});
  ASSERT_TRUE(field.ok());
  GeodesicOptions exact;
  absl::StatusOr<terrain::CellValues> cells = terrain::SampleCells(*local, *field, &*built, &exact);
  ASSERT_TRUE(cells.ok());
  absl::StatusOr<std::string> want = local->DistanceRasterBytes(*cells);
  ASSERT_TRUE(want.ok());
  const std::string path = "/vsimem/tin-export.tif", want_path = "/vsimem/tin-want.tif";
  for (const auto& [p, bytes] : {std::pair{path, &tiff}, std::pair{want_path, &*want}}) {
    VSILFILE* f = VSIFileFromMemBuffer(p.c_str(), reinterpret_cast<GByte*>(bytes->data()),
                                       bytes->size(), FALSE);
    ASSERT_NE(f, nullptr);
    VSIFCloseL(f);
  }
  std::vector<float> got(30 * 30), expected(30 * 30);
  for (const auto& [p, out] : {std::pair{path, &got}, std::pair{want_path, &expected}}) {
    GDALDataset* ds = GDALDataset::Open(p.c_str(), GDAL_OF_RASTER);
    ASSERT_NE(ds, nullptr);
    ASSERT_EQ(ds->GetRasterBand(1)->RasterIO(GF_Read, 0, 0, 30, 30, out->data(), 30, 30,
                                             GDT_Float32, 0, 0),
              CE_None);
    GDALClose(ds);
    VSIUnlink(p.c_str());
  }
  EXPECT_EQ(got, expected);
  EXPECT_EQ(got[15 * 30 + 14], -1);  // the slot
  EXPECT_GT(got[20 * 30 + 3], 0);

  testing::UploadResult bad = UploadDem(bytes_, "bad", v1::MESH_FORMAT_GEOTIFF, "slot.tif", 0, -1);
  EXPECT_EQ(bad.status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_EQ(BadField(bad.status), "metadata.dem.z_tolerance") << bad.status.error_message();
}

// Travel time on a DEM's mesh with friction polygons in the DEM's map (named CRS): the field is
// core's with the weights terrain reads from the same text, and ExportGis's files say their bound.
TEST_F(TerrainServiceTest, TravelWithFrictionInTheDemsMap) {
  StartServer();
  ASSERT_TRUE(UploadDem(bytes_, "slot").status.ok());
  // Friction 3 on the western third (x < 500100), in UTM 33N metres.
  const std::string friction_text = R"({"type": "FeatureCollection",
      "crs": {"type": "name", "properties": {"name": "EPSG:32633"}},
      "features": [{"type": "Feature", "properties": {"friction": 3},
        "geometry": {"type": "Polygon", "coordinates": [[[499900, 4999600], [500100, 4999600],
          [500100, 5000100], [499900, 5000100], [499900, 4999600]]]}}]})";
  absl::StatusOr<terrain::Dem> local = terrain::Dem::Read(tif_);
  ASSERT_TRUE(local.ok()) << local.status();
  absl::StatusOr<std::vector<double>> weights =
      terrain::FrictionFromGeoJson(local->mesh(), friction_text, &local->info(), "friction");
  ASSERT_TRUE(weights.ok()) << weights.status();
  absl::StatusOr<TriangleMesh> built = TriangleMesh::Build(local->mesh());
  absl::StatusOr<SurfacePoint> source = local->DropMapPoint(500205, 4999845);
  ASSERT_TRUE(built.ok() && source.ok());
  GeodesicOptions options;
  options.travel = TravelCost{};
  options.travel->speed_kmh = 5;
  options.travel->epsilon = 0.1;
  options.travel->face_weight = std::make_shared<const std::vector<double>>(*weights);
  absl::StatusOr<DistanceField> want = ComputeDistanceField(*built, {*source}, options);
  ASSERT_TRUE(want.ok()) << want.status();

  v1::TravelCost travel;
  travel.set_speed_kmh(5);
  travel.set_epsilon(0.1);
  travel.set_friction_geojson(friction_text);
  v1::ComputeDistanceFieldRequest request;
  request.set_mesh("meshes/slot");
  request.add_sources()->mutable_map_point()->set_x(500205);
  request.mutable_sources(0)->mutable_map_point()->set_y(4999845);
  *request.mutable_options()->mutable_travel() = travel;
  std::vector<double> got;
  double travel_epsilon = -1;
  bool travel_exact = true;
  {
    grpc::ClientContext context;
    context.set_deadline(testing::In(120));
    auto reader = stub_->ComputeDistanceField(&context, request);
    v1::ComputeDistanceFieldResponse message;
    while (reader->Read(&message)) {
      if (message.offset() == 0) travel_epsilon = message.travel_epsilon();
      if (message.offset() == 0) travel_exact = message.travel_exact();
      got.insert(got.end(), message.distances_f64().begin(), message.distances_f64().end());
    }
    grpc::Status status = reader->Finish();
    ASSERT_TRUE(status.ok()) << status.error_message();
  }
  EXPECT_EQ(travel_epsilon, 0.1);
  EXPECT_FALSE(travel_exact);  // two weights: within the bound, not exact
  EXPECT_EQ(got, want->distance);

  // ExportGis: isochrones of the travel times carry the bound; Delaunay is refused.
  v1::ExportGisRequest gis;
  gis.set_mesh("meshes/slot");
  *gis.mutable_sources() = request.sources();
  *gis.mutable_options()->mutable_travel() = travel;
  gis.set_product(v1::GIS_PRODUCT_ISOCHRONES);
  gis.set_count(3);
  {
    grpc::ClientContext context;
    context.set_deadline(testing::In(120));
    auto reader = stub_->ExportGis(&context, gis);
    v1::ExportGisResponse message;
    std::vector<double> bounds;
    std::string file;
    while (reader->Read(&message)) {
      bounds.push_back(message.travel_epsilon());
      file += message.data();
    }
    grpc::Status status = reader->Finish();
    ASSERT_TRUE(status.ok()) << status.error_message();
    ASSERT_FALSE(bounds.empty());
    EXPECT_EQ(bounds.front(), 0.1);
    // Each feature says how its times were made, as the CLI's files do.
    EXPECT_NE(file.find(R"("units": "s", "epsilon": 0.1, "bound": true, "speed": "constant")"),
              std::string::npos)
        << file.substr(0, 400);
  }
  gis.set_product(v1::GIS_PRODUCT_DELAUNAY);
  {
    grpc::ClientContext context;
    context.set_deadline(testing::In(120));
    auto reader = stub_->ExportGis(&context, gis);
    v1::ExportGisResponse message;
    while (reader->Read(&message)) {
    }
    grpc::Status status = reader->Finish();
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
    EXPECT_EQ(BadField(status), "options.travel") << status.error_message();
  }
}

// Friction read on a mesh is cached with the map it was read in: a mesh uploaded as a file has
// none (the GeoJSON's coordinates are its own x and y), and when the same mesh's GeoTIFF is
// uploaded (the same id) it gains one, and the same request must read the polygons in it (issue
// 55: it used to answer from the weights read without the map).
TEST_F(TerrainServiceTest, FrictionReadBeforeTheMeshGainedItsMapIsNotReused) {
  StartServer();
  absl::StatusOr<terrain::Dem> local = terrain::Dem::Read(tif_);
  ASSERT_TRUE(local.ok()) << local.status();
  const std::string off = (dir_ / "in" / "gain.off").string();
  ASSERT_TRUE(WriteMeshOff(off, local->mesh()).ok());
  std::ifstream in(off, std::ios::binary);
  const std::string off_bytes((std::istreambuf_iterator<char>(in)),
                              std::istreambuf_iterator<char>());
  ASSERT_TRUE(testing::Upload(*stub_, off_bytes, "gain").status.ok());
  // Friction 3 west of about x = 500100 in longitude/latitude (RFC 7946): in the DEM's map the
  // western third; as the file mesh's own x and y (metres from 500000), far off the mesh.
  const std::string friction_text = R"({"type": "FeatureCollection", "features": [
      {"type": "Feature", "properties": {"friction": 3}, "geometry": {"type": "Polygon",
       "coordinates": [[[14.99, 45.0], [15.0012, 45.0], [15.0012, 45.3], [14.99, 45.3],
                        [14.99, 45.0]]]}}]})";
  v1::ComputeDistanceFieldRequest request;
  request.set_mesh("meshes/gain");
  request.add_sources()->set_vertex(0);
  request.mutable_options()->mutable_travel()->set_speed_kmh(5);
  request.mutable_options()->mutable_travel()->set_epsilon(0.1);
  request.mutable_options()->mutable_travel()->set_friction_geojson(friction_text);
  testing::FieldResult without_map = testing::ReadField(*stub_, request);
  ASSERT_TRUE(without_map.status.ok()) << without_map.status.error_message();

  ASSERT_TRUE(UploadDem(bytes_, "").status.ok());  // the same mesh gains its map
  testing::FieldResult with_map = testing::ReadField(*stub_, request);
  ASSERT_TRUE(with_map.status.ok()) << with_map.status.error_message();

  // What a server that only ever had the GeoTIFF answers: the friction read in the map.
  absl::StatusOr<std::vector<double>> weights =
      terrain::FrictionFromGeoJson(local->mesh(), friction_text, &local->info(), "friction");
  ASSERT_TRUE(weights.ok()) << weights.status();
  ASSERT_GT(*std::max_element(weights->begin(), weights->end()), 1);  // the polygon is on the DEM
  absl::StatusOr<TriangleMesh> built = TriangleMesh::Build(local->mesh());
  ASSERT_TRUE(built.ok());
  GeodesicOptions options;
  options.travel = TravelCost{};
  options.travel->speed_kmh = 5;
  options.travel->epsilon = 0.1;
  options.travel->face_weight = std::make_shared<const std::vector<double>>(*weights);
  absl::StatusOr<DistanceField> want =
      ComputeDistanceField(*built, {SurfacePoint::AtVertex(0)}, options);
  ASSERT_TRUE(want.ok()) << want.status();
  EXPECT_EQ(with_map.distances, want->distance);
  EXPECT_NE(without_map.distances, want->distance);  // the two readings differ: the test can fail
}

// ExportGis: the files the CLI writes, made by geodexd from a stored DEM's mesh.
TEST_F(TerrainServiceTest, ExportGisMakesTheCliFiles) {
  ServerOptions options;
  options.limits.stream_chunk_bytes = 1000;  // several messages per file
  StartServer(options);
  ASSERT_TRUE(UploadDem(bytes_, "slot").status.ok());
  std::vector<double> snaps;  // of the last run
  auto run = [&](const v1::ExportGisRequest& request, std::string* media) {
    grpc::ClientContext context;
    context.set_deadline(testing::In(120));
    auto reader = stub_->ExportGis(&context, request);
    v1::ExportGisResponse message;
    std::string bytes;
    int messages = 0;
    while (reader->Read(&message)) {
      if (messages++ == 0) {
        *media = message.media_type();
        snaps.assign(message.snap_distances().begin(), message.snap_distances().end());
      } else {
        EXPECT_EQ(message.snap_distances_size(), 0);
      }
      EXPECT_LE(message.data().size(), 1000u);
      bytes += message.data();
    }
    grpc::Status status = reader->Finish();
    EXPECT_TRUE(status.ok()) << status.error_message();
    return bytes;
  };
  v1::ExportGisRequest request;
  request.set_mesh("meshes/slot");
  request.add_sources()->mutable_map_point()->set_x(500105);
  request.mutable_sources(0)->mutable_map_point()->set_y(4999845);
  std::string media;

  // The distance raster: aligned with the grid, the field's values, nodata in the slot.
  request.set_product(v1::GIS_PRODUCT_DISTANCE_RASTER);
  const std::string tiff = run(request, &media);
  EXPECT_EQ(media, "image/tiff");
  absl::StatusOr<terrain::Dem> local = terrain::Dem::Read(tif_);
  ASSERT_TRUE(local.ok());
  absl::StatusOr<SurfacePoint> source = local->DropMapPoint(500105, 4999845);
  absl::StatusOr<TriangleMesh> built = TriangleMesh::Build(local->mesh());
  ASSERT_TRUE(source.ok() && built.ok());
  absl::StatusOr<DistanceField> field = ComputeDistanceField(*built, {*source}, GeodesicOptions{});
  ASSERT_TRUE(field.ok());
  const std::string path = "/vsimem/export-test.tif";
  VSILFILE* file = VSIFileFromMemBuffer(
      path.c_str(), reinterpret_cast<GByte*>(const_cast<char*>(tiff.data())), tiff.size(), FALSE);
  ASSERT_NE(file, nullptr);
  VSIFCloseL(file);
  GDALDataset* ds = GDALDataset::Open(path.c_str(), GDAL_OF_RASTER);
  ASSERT_NE(ds, nullptr);
  std::vector<float> cells(30 * 30);
  ASSERT_EQ(ds->GetRasterBand(1)->RasterIO(GF_Read, 0, 0, 30, 30, cells.data(), 30, 30, GDT_Float32,
                                           0, 0),
            CE_None);
  double gt[6];
  ds->GetGeoTransform(gt);
  EXPECT_EQ(gt[0], 500000);
  // What made it: geodexd's request and what the values are (terrain::Provenance).
  const char* made_by = ds->GetMetadataItem("GEODEX_MADE_BY");
  ASSERT_NE(made_by, nullptr);
  EXPECT_EQ(std::string(made_by), "geodexd ExportGis GIS_PRODUCT_DISTANCE_RASTER meshes/slot");
  ASSERT_NE(ds->GetMetadataItem("GEODEX_VALUES"), nullptr);
  EXPECT_EQ(std::string(ds->GetMetadataItem("GEODEX_VALUES")), "geodesic distance");
  GDALClose(ds);
  VSIUnlink(path.c_str());
  EXPECT_EQ(cells[15 * 30 + 14], -1);  // the slot
  EXPECT_EQ(cells[20 * 30 + 3], static_cast<float>(field->distance[local->VertexAt(3, 20)]));

  // Isochrones: one Feature per level, in WGS 84.
  request.set_product(v1::GIS_PRODUCT_ISOCHRONES);
  request.add_levels(50);
  request.add_levels(120);
  const std::string geojson = run(request, &media);
  EXPECT_EQ(media, "application/geo+json");
  EXPECT_TRUE(Contains(geojson, "\"level\": 120")) << geojson.substr(0, 300);
  EXPECT_TRUE(Contains(geojson, "MultiPolygon") || Contains(geojson, "\"Polygon\""));
  EXPECT_TRUE(Contains(geojson, "[ 15.")) << geojson.substr(0, 400);  // longitudes near 15 E
  EXPECT_TRUE(
      Contains(geojson, R"("made_by": "geodexd ExportGis GIS_PRODUCT_ISOCHRONES meshes\/slot")"))
      << geojson.substr(0, 400);

  // Points name themselves as written and where they landed.
  request.set_product(v1::GIS_PRODUCT_POINTS);
  request.add_points()->mutable_map_point()->set_x(500205);
  request.mutable_points(0)->mutable_map_point()->set_y(4999845);
  request.add_points()->set_vertex(0);
  const std::string points = run(request, &media);
  EXPECT_TRUE(Contains(points, "\"point\": \"g:500205:4999845\"")) << points.substr(0, 600);
  EXPECT_TRUE(Contains(points, "\"point\": \"0\""));
  EXPECT_EQ(snaps, std::vector<double>(3, 0.0));  // map points drop, vertices are on the surface
  // A position 5 m above a vertex: its snap distance reported, max_snap below it refuses it.
  const std::array<double, 3> above = built->Position(built->vertex_count() / 2);  // recentred
  v1::Position* p = request.add_points()->mutable_position();
  p->set_x(above[0] + built->Center()[0]);
  p->set_y(above[1] + built->Center()[1]);
  p->set_z(above[2] + built->Center()[2] + 5);
  run(request, &media);
  ASSERT_EQ(snaps.size(), 4u);
  EXPECT_GT(snaps[3], 0.1);
  EXPECT_LE(snaps[3], 5.0 + 1e-9);
  request.set_max_snap(snaps[3] / 2);
  {
    grpc::ClientContext context;
    context.set_deadline(testing::In(60));
    auto reader = stub_->ExportGis(&context, request);
    v1::ExportGisResponse message;
    while (reader->Read(&message)) {
    }
    grpc::Status status = reader->Finish();
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
    EXPECT_EQ(BadField(status), "points[2].position") << status.error_message();
  }
  request.clear_max_snap();
  request.mutable_points()->RemoveLast();
  // Beyond max_distance: distance and source are null, not left out.
  request.mutable_options()->set_max_distance(20);
  const std::string near_only = run(request, &media);
  EXPECT_TRUE(Contains(near_only, "\"distance\": null, \"source\": null"))
      << near_only.substr(0, 800);
  request.clear_options();

  // Not a DEM's mesh, no product: INVALID_ARGUMENT naming the field.
  ASSERT_TRUE(testing::Upload(*stub_, testing::GridOff(3, 3, false), "grid").status.ok());
  for (auto [mesh, product, field_name] :
       std::vector<std::tuple<std::string, v1::GisProduct, std::string>>{
           {"meshes/grid", v1::GIS_PRODUCT_VORONOI, "mesh"},
           {"meshes/slot", v1::GIS_PRODUCT_UNSPECIFIED, "product"}}) {
    v1::ExportGisRequest bad;
    bad.set_mesh(mesh);
    bad.set_product(product);
    bad.add_sources()->set_vertex(0);
    grpc::ClientContext context;
    context.set_deadline(testing::In(60));
    auto reader = stub_->ExportGis(&context, bad);
    v1::ExportGisResponse message;
    while (reader->Read(&message)) {
    }
    grpc::Status status = reader->Finish();
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << mesh;
    EXPECT_EQ(BadField(status), field_name) << status.error_message();
  }
}

}  // namespace
}  // namespace geodex::server
