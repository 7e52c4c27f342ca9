#!/usr/bin/python3
"""The geodex Python package against a real geodexd (127.0.0.1, a port it picks): every method,
each checked against the geodex CLI's local answer, and the typed exceptions. Bounded: the server
is started and stopped here, every wait gives up.
Env: GEODEX, GEODEXD (binaries), DATA (tests/data); `import geodex` works (PYTHONPATH with
build/python and client/python, or the package installed: tests/python/package_test.sh).
"""
import asyncio
import json
import os
import re
import signal
import subprocess
import tempfile
import threading
import time
import unittest
import warnings

import numpy

import geodex
from geodex import GeodexClient, face_point, position, vertex

GEODEX, GEODEXD, DATA = os.environ["GEODEX"], os.environ["GEODEXD"], os.environ["DATA"]


class PythonClientTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        cls.log = open(os.path.join(cls.tmp.name, "server.log"), "w+")
        cls.server = subprocess.Popen(
            [GEODEXD, "--listen", "127.0.0.1:0", "--metrics_listen", "", "--pool-threads", "2",
             "--data-dir", os.path.join(cls.tmp.name, "data"), "--shutdown_grace_seconds", "5",
             "--max_targets", "1000"],
            stdout=cls.log, stderr=subprocess.STDOUT)
        port = None
        for _ in range(300):
            cls.log.seek(0)
            match = re.search(r"listening on port (\d+)", cls.log.read())
            if match:
                port = match.group(1)
                break
            time.sleep(0.1)
        assert port, "geodexd did not start"
        cls.client = GeodexClient("127.0.0.1:" + port, timeout=60)
        cls.mesh = cls.client.upload(os.path.join(DATA, "kitten.off"), name="kitten")

    @classmethod
    def tearDownClass(cls):
        cls.server.send_signal(signal.SIGTERM)
        try:
            assert cls.server.wait(timeout=30) == 0
        finally:
            if cls.server.poll() is None:
                cls.server.kill()
            cls.log.close()
            cls.tmp.cleanup()

    def local(self, *args):
        return subprocess.run([GEODEX, *args], check=True, capture_output=True, text=True,
                              timeout=120).stdout

    def test_health_and_upload(self):
        self.assertTrue(self.client.health())
        self.assertEqual(self.mesh.vertex_count, 2500)
        self.assertEqual(self.mesh.display_name, "kitten")
        again = self.client.upload(os.path.join(DATA, "kitten.off"))
        self.assertEqual(again.name, self.mesh.name)  # idempotent by content hash
        self.assertEqual(self.client.get_mesh("meshes/kitten").name, self.mesh.name)

    def test_distance_field_equals_the_cli(self):
        distances, labels, stats, _ = self.client.distance_field(
            self.mesh.name, [vertex(0), face_point(10, 0.2, 0.3, 0.5)], want_stats=True)
        expected = [float(x) for x in
                    self.local("distances", os.path.join(DATA, "kitten.off"), "--sources",
                               "0,f:10:0.2:0.3:0.5").split()]
        self.assertEqual((distances.dtype, labels.dtype), (numpy.float64, numpy.uint32))
        self.assertEqual(distances.tolist(), expected)  # bit for bit (%.17g round-trips)
        self.assertEqual(set(labels.tolist()), {0, 1})
        self.assertGreater(stats.windows_created, 0)

    def test_direction_field_equals_the_cli(self):
        field = self.client.distance_field(self.mesh.name, [vertex(0), vertex(1250)],
                                           want_directions=True)
        lines = self.local("distances", os.path.join(DATA, "kitten.off"), "--sources", "0,1250",
                           "--directions").splitlines()
        self.assertEqual(len(field.directions), 2500)
        for (x, y, z), line in zip(field.directions, lines):
            self.assertEqual([x, y, z], [float(v) for v in line.split("\t")[1].split()])
        self.assertEqual(field.directions.shape, (2500, 3))
        self.assertEqual(field.directions[0].tolist(), [0.0, 0.0, 0.0])  # a source
        self.assertAlmostEqual(sum(c * c for c in field.directions[7]), 1.0, delta=1e-12)

    def test_directions_at_points_equal_the_cli(self):
        at = self.client.point_distances(self.mesh.name, [vertex(0), vertex(1250)],
                                         [face_point(4989, 0.2, 0.3, 0.5), vertex(5), vertex(0)],
                                         want_directions=True)
        lines = self.local("distances", os.path.join(DATA, "kitten.off"), "--sources", "0,1250",
                           "--at", "f:4989:0.2:0.3:0.5,5,0", "--directions").splitlines()
        self.assertEqual(len(at.directions), 3)
        for d, line in zip(at.directions, lines):  # bit for bit
            self.assertEqual(list(d), [float(v) for v in line.split("\t")[4].split()[1:]])
        self.assertEqual(at.directions[2].tolist(), [0.0, 0.0, 0.0])  # a source
        self.assertAlmostEqual(sum(c * c for c in at.directions[0]), 1.0, delta=1e-12)
        plain = self.client.point_distances(self.mesh.name, [vertex(0)], [vertex(5)])
        self.assertEqual(plain.directions.shape, (0, 3))

    def test_shortest_path_equals_the_cli(self):
        length, points = self.client.shortest_path(self.mesh.name, vertex(0), vertex(1250))
        lines = self.local("path", os.path.join(DATA, "kitten.off"), "--from", "0", "--to",
                           "1250").splitlines()
        self.assertEqual(length, float(lines[0]))
        self.assertEqual(len(points), len(lines) - 1)
        for point, line in zip(points, lines[1:]):  # positions bit for bit, and the simplices
            fields = line.split()
            self.assertEqual(point.position, tuple(float(x) for x in fields[:3]))
            self.assertEqual(point.simplex[0], fields[3])
        self.assertEqual(points[0].simplex, ("v", 0))
        self.assertEqual(points[-1].simplex, ("v", 1250))

    def test_matrix_equals_the_cli_with_k_nearest_and_max_distance(self):
        sources, targets = [0, 5, 1250], [7, 100, 2000, 2400]
        seen = []  # rows stream as they finish: progress per message, rows never go back
        full = self.client.distance_matrix(self.mesh.name, [vertex(v) for v in sources],
                                           [vertex(v) for v in targets],
                                           on_progress=lambda *p: seen.append(p))
        self.assertEqual(seen[-1], (3, 3, 1.0))
        self.assertEqual(seen, sorted(seen))
        lines = self.local("matrix", os.path.join(DATA, "kitten.off"), "--sources",
                           ",".join(map(str, sources)), "--targets",
                           ",".join(map(str, targets))).splitlines()
        self.assertEqual(full.shape, (3, 4))
        self.assertEqual(full.tolist(), [[float(x) for x in line.split()] for line in lines])
        nearest = self.client.distance_matrix(self.mesh.name, [vertex(v) for v in sources],
                                              [vertex(v) for v in targets], k_nearest=2)
        for row, kept in zip(full, nearest):
            finite = sorted(d for d in kept if d != float("inf"))
            self.assertEqual(finite, sorted(row)[:2])  # the two nearest, exact
        limit = sum(sorted(full[0])[1:3]) / 2  # between two entries: no ties at the limit
        capped = self.client.distance_matrix(self.mesh.name, [vertex(v) for v in sources],
                                             [vertex(v) for v in targets], max_distance=limit)
        for row, cut in zip(full, capped):
            self.assertEqual(cut.tolist(), [d if d < limit else float("inf") for d in row])
        with self.assertRaises(geodex.InvalidArgumentError) as error:
            self.client.distance_matrix(self.mesh.name, [vertex(0)], [vertex(7)], lambda_=2.0)
        self.assertEqual(error.exception.field, "options.lambda")

    def test_shortest_paths_equal_single_paths(self):
        pairs = [(vertex(0), vertex(1250)), (vertex(0), vertex(7)), (vertex(5), vertex(1250))]
        batch = self.client.shortest_paths(self.mesh.name, pairs)
        self.assertEqual(len(batch), 3)
        for (start, end), (length, points) in zip(pairs, batch):
            single_length, single_points = self.client.shortest_path(self.mesh.name, start, end)
            self.assertAlmostEqual(length, single_length, delta=1e-12 * max(1.0, single_length))
            self.assertEqual(len(points), len(single_points))

    def test_voronoi(self):
        sites = [vertex(0), vertex(800), vertex(1600), vertex(2400)]
        areas, boundaries, adjacency = self.client.voronoi(self.mesh.name, sites)
        self.assertEqual(sorted(areas), [0, 1, 2, 3])
        self.assertTrue(all(a > 0 for a in areas.values()))
        self.assertTrue(boundaries)
        for a, b, points in boundaries:
            self.assertLess(a, b)
            self.assertIn((a, b), adjacency)
            self.assertGreaterEqual(len(points), 2)
        cli = json.loads(self.local("voronoi", os.path.join(DATA, "kitten.off"), "--sites",
                                    "0,800,1600,2400"))
        self.assertEqual(len(boundaries), len(cli["boundaries"]))

    def test_isolines_and_delaunay_equal_the_cli(self):
        kitten = os.path.join(DATA, "kitten.off")
        iso = self.client.isolines(self.mesh.name, [vertex(0)], count=5)
        cli = json.loads(self.local("isolines", kitten, "--sources", "0", "--count", "5"))
        self.assertEqual(iso.levels, cli["levels"])
        self.assertEqual(len(iso.lines), len(cli["polylines"]))
        for (level, closed, points), line in zip(iso.lines, cli["polylines"]):
            self.assertEqual((level, closed, len(points)), (line["level"], line["closed"],
                                                            len(line["points"])))
            self.assertEqual(list(points[0].position), line["points"][0]["p"])
        sites = [vertex(0), vertex(800), vertex(1600), vertex(2400), vertex(1200)]
        dt = self.client.delaunay(self.mesh.name, sites)
        cli = json.loads(self.local("delaunay", kitten, "--sites", "0,800,1600,2400,1200"))
        self.assertEqual(sorted((a, b) for a, b, _, _ in dt.edges),
                         sorted(tuple(e["sites"]) for e in cli["edges"]))
        self.assertEqual(sorted(dt.triangles), sorted(tuple(t) for t in cli["triangles"]))

    def test_point_distances_and_locate_equal_the_cli(self):
        kitten = os.path.join(DATA, "kitten.off")
        at = self.client.point_distances(self.mesh.name, [vertex(1)],
                                         [vertex(7), face_point(30, 0.2, 0.2, 0.6)])
        cli = json.loads(self.local("distances", kitten, "--sources", "1", "--at",
                                    "7,f:30:0.2:0.2:0.6", "--format", "json"))["points"]
        self.assertEqual(at.exact.tolist(), [p["exact"] for p in cli])
        self.assertEqual(at.estimates.tolist(), [p["estimate"] for p in cli])
        self.assertEqual(at.exact_labels.tolist(), [0, 0])
        located = self.client.locate(self.mesh.name, [(0, 0, 0), (0, 100, 0)])
        cli = json.loads(self.local("locate", kitten, "--points", "p:0:0:0,p:0:100:0",
                                    "--format", "json"))["points"]
        self.assertEqual([l.distance for l in located], [p["snap_distance"] for p in cli])
        self.assertEqual([list(l.position) for l in located], [p["p"] for p in cli])
        self.assertEqual(located[0].point.vertex, int(cli[0]["point"]))
        with self.assertRaises(geodex.InvalidArgumentError) as error:
            self.client.locate(self.mesh.name, [(0, 0, 0), (0, 100, 0)], max_snap=5.0)
        self.assertEqual(error.exception.field, "positions[1]")
        # A position snapped by the server in a query: the same path as from the located vertex.
        self.assertEqual(self.client.shortest_path(self.mesh.name, position(0, 0, 0), vertex(9)),
                         self.client.shortest_path(self.mesh.name, vertex(2461), vertex(9)))

    def test_list_and_delete(self):
        extra = self.client.upload(os.path.join(DATA, "knight.off"), name="knight")
        self.assertIn(extra.name, [m.name for m in self.client.list_meshes()])
        self.client.delete_mesh("meshes/knight")
        self.assertNotIn(extra.name, [m.name for m in self.client.list_meshes()])
        with self.assertRaises(geodex.NotFoundError):
            self.client.get_mesh("meshes/knight")

    def test_geotiff_dem_with_map_points_equals_the_cli(self):
        import numpy
        from osgeo import gdal, osr  # Debian's python3-gdal (scripts/install-deps.sh)
        gdal.UseExceptions()
        tif = os.path.join(self.tmp.name, "slope.tif")
        ds = gdal.GetDriverByName("GTiff").Create(tif, 30, 20, 1, gdal.GDT_Float32)
        ds.SetGeoTransform((500000, 10, 0, 5000000, 0, -10))
        srs = osr.SpatialReference()
        srs.ImportFromEPSG(32633)
        ds.SetProjection(srs.ExportToWkt())
        band = ds.GetRasterBand(1)
        band.SetNoDataValue(-9999)
        # A slope with a nodata slot in column 12 from row 5 down.
        band.WriteArray(numpy.fromfunction(
            lambda j, i: numpy.where((i == 12) & (j > 4), -9999, 0.3 * i + 0.1 * j), (20, 30)))
        ds = None
        mesh = self.client.upload(tif, name="slope")
        self.assertEqual(mesh.terrain.crs_name, "WGS 84 / UTM zone 33N")
        self.assertEqual((mesh.terrain.grid_width, mesh.terrain.nodata_cells), (30, 15))
        wgs84 = osr.SpatialReference()
        wgs84.ImportFromEPSG(4326)
        wgs84.SetAxisMappingStrategy(osr.OAMS_TRADITIONAL_GIS_ORDER)
        to_ll = osr.CoordinateTransformation(srs, wgs84)
        lon, lat, _ = to_ll.TransformPoint(500232.5, 4999871.5)
        field = self.client.distance_field("meshes/slope", [geodex.map_point(500031.5, 4999903.5),
                                                            geodex.lon_lat(lon, lat)])
        expected = [float(x) for x in self.local(
            "distances", tif, "--sources",
            "g:500031.5:4999903.5,ll:%.17g:%.17g" % (lon, lat)).split()]
        self.assertEqual(field.distances.tolist(), expected)  # dropped where the CLI drops them
        self.assertEqual(set(field.labels.tolist()), {0, 1})
        with self.assertRaises(geodex.InvalidArgumentError) as error:  # in the nodata slot
            self.client.distance_field("meshes/slope", [geodex.map_point(500125, 4999850)])
        self.assertEqual(error.exception.field, "sources[0].map_point")
        with self.assertRaises(geodex.InvalidArgumentError) as error:  # not a DEM's mesh
            self.client.distance_field(self.mesh.name, [geodex.lon_lat(lon, lat)])
        self.assertEqual(error.exception.field, "sources[0].lon_lat")
        # A barrier: a wall across the DEM (WGS 84 polygon) derives a mesh the server stores; the
        # CLI makes the same one with --barrier (the same answers).
        ring = [to_ll.TransformPoint(x, y)[:2] for x, y in
                [(500052, 5000010), (500068, 5000010), (500068, 4999815), (500052, 4999815),
                 (500052, 5000010)]]
        wall = {"type": "Polygon", "coordinates": [ring]}
        walled = self.client.derive_mesh("meshes/slope", polygons_geojson=wall, name="walled")
        # cut exactly: block columns 4 and 6 in part, 5 whole, rows 0-17, two faces a block
        self.assertEqual(walled.terrain.barrier_faces, 3 * 2 * 18)
        wall_file = os.path.join(self.tmp.name, "wall.geojson")
        with open(wall_file, "w") as f:
            json.dump(wall, f)
        around = self.client.distance_field("meshes/walled", [geodex.map_point(500031.5, 4999903.5)])
        expected = [float(x) for x in self.local(
            "distances", tif, "--sources", "g:500031.5:4999903.5", "--barrier", wall_file).split()]
        self.assertEqual(around.distances.tolist(), expected)
        self.assertGreater(around.distances[7], field.distances[7])
        with self.assertRaises(geodex.InvalidArgumentError) as error:
            self.client.derive_mesh("meshes/slope")
        self.assertEqual(error.exception.field, "barrier")
        # Friction polygons: their outlines cut into a derived mesh (nothing removed) make the
        # CLI's --friction-boundaries exact mesh, and travel on it with the same polygons the
        # CLI's times.
        strip = {"type": "FeatureCollection",
                 "crs": {"type": "name", "properties": {"name": "EPSG:32633"}},
                 "features": [{"type": "Feature", "properties": {"friction": 3},
                               "geometry": {"type": "Polygon", "coordinates": [[
                                   [500080, 4999750], [500130, 4999750], [500230, 5000010],
                                   [500180, 5000010], [500080, 4999750]]]}}]}
        banded = self.client.derive_mesh("meshes/slope", friction_geojson=strip, name="banded")
        self.assertGreater(banded.face_count, self.client.get_mesh("meshes/slope").face_count)
        band_file = os.path.join(self.tmp.name, "band.geojson")
        with open(band_file, "w") as f:
            json.dump(strip, f)
        slow = self.client.distance_field(
            "meshes/banded", [geodex.map_point(500031.5, 4999903.5)],
            travel=geodex.Travel(3.6, epsilon=0.05, friction_geojson=strip))
        expected = [float(x) for x in self.local(
            "distances", tif, "--sources", "g:500031.5:4999903.5", "--speed", "constant:3.6",
            "--cost-epsilon", "0.05", "--friction", band_file, "--friction-boundaries",
            "exact").split("\n")[1:] if x]
        self.assertEqual(slow.distances.tolist(), expected)
        with self.assertRaises(geodex.InvalidArgumentError) as error:
            self.client.derive_mesh("meshes/slope", friction_geojson={"type": "Feature"})
        self.assertEqual(error.exception.field, "friction_geojson")
        # GIS files from the server are the CLI's files, byte for byte, but for what made them
        # (the "geodex" member: the CLI's command line, the server's request).
        def without_provenance(text):
            data = json.loads(text)
            made_by = data.pop("geodex")
            self.assertEqual(made_by["software"].split()[0], "geodex")
            return data
        source = geodex.map_point(500031.5, 4999903.5)
        for product, args, ext in [("isochrones", ["isolines", "--levels", "40,90"], "geojson"),
                                   ("voronoi", ["voronoi", "--sites", "g:500031.5:4999903.5,5"],
                                    "geojson")]:
            out = os.path.join(self.tmp.name, "cli." + ext)
            flag = "--sites" if product == "voronoi" else "--sources"
            cli_args = args if product == "voronoi" else args + [flag, "g:500031.5:4999903.5"]
            self.local(cli_args[0], tif, *cli_args[1:], "--output", out)
            sources = [source, vertex(5)] if product == "voronoi" else [source]
            got = self.client.export_gis("meshes/slope", product, sources, levels=[40, 90])
            with open(out, "rb") as f:
                self.assertEqual(without_provenance(got), without_provenance(f.read()), product)
        raster = self.client.export_gis("meshes/slope", "distance_raster", [source])
        gdal.FileFromMemBuffer("/vsimem/py-export.tif", raster)
        cells = gdal.Open("/vsimem/py-export.tif").ReadAsArray()
        gdal.Unlink("/vsimem/py-export.tif")
        self.assertEqual(cells.shape, (20, 30))
        self.assertEqual(cells[10, 12], -1)  # the slot
        alone = self.client.distance_field("meshes/slope", [source]).distances
        self.assertEqual(float(cells[0, 0]), float(numpy.float32(alone[0])))  # float32 cells
        self.assertEqual(raster.travel_epsilon, 0.0)
        # With a travel cost the raster holds seconds and says its bound.
        walk = geodex.Travel(speed_kmh=3.6, epsilon=0.1)
        timed = self.client.export_gis("meshes/slope", "distance_raster", [source], travel=walk)
        self.assertEqual(timed.travel_epsilon, 0.1)
        times = self.client.distance_field("meshes/slope", [source], travel=walk).distances
        gdal.FileFromMemBuffer("/vsimem/py-export-t.tif", timed)
        timed_cells = gdal.Open("/vsimem/py-export-t.tif").ReadAsArray()
        gdal.Unlink("/vsimem/py-export-t.tif")
        self.assertEqual(float(timed_cells[0, 0]), float(numpy.float32(times[0])))
        coarse = self.client.upload(tif, dem_step=2)
        self.assertEqual(coarse.terrain.grid_width, 15)
        self.assertNotEqual(coarse.name, mesh.name)
        # An adaptive TIN: the CLI's (the same field at its vertices), within its tolerance.
        tin = self.client.upload(tif, z_tolerance=0.05, name="slope-tin")
        self.assertEqual(tin.terrain.z_tolerance, 0.05)
        self.assertLessEqual(tin.terrain.max_vertical_deviation, 0.05)
        self.assertLess(tin.vertex_count, mesh.vertex_count / 4)
        expected = [float(x) for x in self.local(
            "distances", tif, "--z-tolerance", "0.05", "--sources", "g:500031.5:4999903.5").split()]
        self.assertEqual(self.client.distance_field("meshes/slope-tin", [source]).distances.tolist(),
                         expected)

    def test_errors_are_typed_and_carry_the_details(self):
        with self.assertRaises(geodex.InvalidArgumentError) as error:
            self.client.distance_field(self.mesh.name, [vertex(99999)])
        self.assertEqual(error.exception.code.name, "INVALID_ARGUMENT")
        self.assertEqual(error.exception.field, "sources[0].vertex")
        self.assertIsInstance(error.exception, geodex.GeodexError)
        with self.assertRaises(geodex.NotFoundError):
            self.client.distance_field("meshes/no-such-mesh", [vertex(0)])
        with self.assertRaises(geodex.UnreachableError) as error:
            self.client.shortest_path(self.mesh.name, vertex(0), vertex(1250), max_distance=1.0)
        self.assertEqual(error.exception.reason, "UNREACHABLE")
        with self.assertRaises(geodex.ResourceExhaustedError) as error:  # --max_targets 1000
            self.client.locate(self.mesh.name, [(0, 0, 0)] * 1001)
        self.assertEqual((error.exception.reason, error.exception.flag), ("LIMIT", "max_targets"))
        with self.assertRaises(geodex.UnavailableError):
            geodex.GeodexClient("127.0.0.1:1", timeout=5).health()


def start_geodexd(tmp, listen="127.0.0.1:0", name="server"):
    """A geodexd child on 127.0.0.1 (the port it picks, or `listen`); returns (process, port, log)."""
    log = open(os.path.join(tmp, name + ".log"), "w+")
    server = subprocess.Popen(
        [GEODEXD, "--listen", listen, "--metrics_listen", "", "--pool-threads", "2",
         "--data-dir", os.path.join(tmp, "data"), "--shutdown_grace_seconds", "5"],
        stdout=log, stderr=subprocess.STDOUT)
    for _ in range(300):
        log.seek(0)
        match = re.search(r"listening on port (\d+)", log.read())
        if match:
            return server, match.group(1), log
        if server.poll() is not None:
            break
        time.sleep(0.1)
    server.kill()
    raise AssertionError("geodexd did not start")


def stop_geodexd(server, log):
    server.send_signal(signal.SIGTERM)
    try:
        server.wait(timeout=30)
    finally:
        if server.poll() is None:
            server.kill()
            server.wait(timeout=10)
        log.close()


def read_off(path):
    """Vertices (n x 3) and faces (m x 3) of a plain OFF file."""
    with open(path) as f:
        rows = [r.split() for r in f if r.strip() and not r.startswith("#")]
    nv, nf = int(rows[1][0]), int(rows[1][1])
    vertices = numpy.array([[float(x) for x in r[:3]] for r in rows[2:2 + nv]])
    faces = numpy.array([[int(x) for x in r[1:4]] for r in rows[2 + nv:2 + nv + nf]])
    return vertices, faces


def bumpy_grid(n):
    """An n x n vertex grid of bumps: 2 (n - 1)^2 faces."""
    x, y = numpy.meshgrid(numpy.linspace(0, 1, n), numpy.linspace(0, 1, n))
    z = 0.05 * numpy.sin(9 * x) * numpy.cos(7 * y)
    vertices = numpy.stack([x.ravel(), y.ravel(), z.ravel()], axis=1)
    i = numpy.arange(n - 1)
    a = (i[None, :] + n * i[:, None]).ravel()
    faces = numpy.concatenate([numpy.stack([a, a + 1, a + n + 1], 1),
                               numpy.stack([a, a + n + 1, a + n], 1)])
    return vertices, faces


class ControlLoopTest(unittest.TestCase):
    """What a planner's control loop needs: a deadline per call, retries across a restart, the
    mesh uploaded again after the server lost it, meshes from bytes and arrays."""

    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.server, self.port, self.log = start_geodexd(self.tmp.name)

    def tearDown(self):
        if self.server is not None:
            stop_geodexd(self.server, self.log)
        self.tmp.cleanup()

    def client(self, **kwargs):
        return GeodexClient("127.0.0.1:" + self.port, **kwargs)

    def test_a_timeout_per_call(self):
        client = self.client(timeout=120)
        mesh = client.upload(bumpy_grid(211))  # 88,200 faces, sent as arrays
        self.assertEqual(mesh.face_count, 88200)
        with self.assertRaises(geodex.DeadlineExceededError):
            client.distance_field(mesh.name, [vertex(0)], timeout=0.005)
        field = client.distance_field(mesh.name, [vertex(0)], timeout=60)  # the same client
        self.assertEqual(field.distances.shape, (211 * 211,))
        self.assertTrue(numpy.isfinite(field.distances).all())
        path = client.shortest_path(mesh.name, vertex(0), vertex(5), timeout=1)  # not an option
        self.assertGreater(path.length, 0)

    def test_bytes_and_arrays_upload_as_the_file(self):
        client = self.client(timeout=60)
        kitten = os.path.join(DATA, "kitten.off")
        from_file = client.upload(kitten)
        with open(kitten, "rb") as f:
            from_bytes = client.upload(f.read(), file_name="kitten.off")
        from_arrays = client.upload(read_off(kitten), name="kitten-arrays")
        self.assertEqual(from_bytes.name, from_file.name)
        self.assertEqual(from_arrays.name, from_file.name)  # float64 round-trips: the same id
        self.assertIn("kitten-arrays", from_arrays.aliases)
        self.assertEqual(client.get_mesh("meshes/kitten-arrays").name, from_file.name)
        self.assertTrue(from_file.name.startswith("meshes/") and len(from_file.id) == 64)
        with self.assertRaises(geodex.InvalidArgumentError) as error:
            client.upload(b"OFF\n")
        self.assertEqual(error.exception.field, "file_name")
        # Array shapes are checked here, naming the argument (not numpy's reshape error).
        vertices, faces = read_off(kitten)
        out_of_range = faces.copy()
        out_of_range[7, 1] = len(vertices)
        for bad, field in (((vertices, faces[:, :2]), "faces"), ((vertices[:, :2], faces), "vertices"),
                           ((vertices, faces.astype(float)), "faces"), ((vertices, out_of_range), "faces"),
                           ((vertices * numpy.nan, faces), "vertices")):
            with self.assertRaises(geodex.InvalidArgumentError) as error:
                client.upload(bad)
            self.assertEqual(error.exception.field, field)
            self.assertIn("upload((vertices, faces))", str(error.exception))
        # A mesh named bare, as the CLI takes it ("kitten-arrays"), is "meshes/kitten-arrays".
        bare = client.shortest_path("kitten-arrays", vertex(0), vertex(5))
        self.assertEqual(bare, client.shortest_path(from_file.name, vertex(0), vertex(5)))
        self.assertEqual(client.get_mesh("kitten-arrays").name, from_file.name)
        # help() and type checkers see what a call returns, not a generator.
        import typing
        self.assertIs(typing.get_type_hints(GeodexClient.shortest_path)["return"], geodex.Path)
        self.assertIs(typing.get_type_hints(GeodexClient.get_mesh)["return"], geodex.Mesh)

    def test_the_mesh_is_uploaded_again_after_the_server_lost_it(self):
        client = self.client(timeout=60)
        mesh = client.upload(os.path.join(DATA, "kitten.off"))
        before = client.shortest_path(mesh.name, vertex(0), vertex(1250))
        self.client(timeout=60).delete_mesh(mesh.name)  # another client: the server loses it
        again = client.shortest_path(mesh.name, vertex(0), vertex(1250))
        self.assertEqual(again, before)
        self.assertEqual(client.reuploads, 1)

    def _restart_during(self, call):
        """Stops geodexd, starts it again on the same port 2 s later, and makes `call` while it
        is down: returns its answer."""
        thread = self._stop_for_restart()
        try:
            return call()
        finally:
            thread.join(timeout=60)

    def test_retries_survive_a_restart(self):
        # The default policy: a call made while geodexd restarts on the same port succeeds (the
        # channel is waited for, not given up on after 4 quick attempts).
        client = self.client(timeout=60)
        mesh = client.upload(os.path.join(DATA, "kitten.off"))
        before = client.shortest_path(mesh.name, vertex(0), vertex(1250))
        again = self._restart_during(
            lambda: client.shortest_path(mesh.name, vertex(0), vertex(1250)))
        self.assertEqual(again, before)
        self.assertGreater(client.retries, 0)

    def test_async_retries_survive_a_restart(self):
        from geodex.aio import AsyncGeodexClient
        mesh = self.client(timeout=60).upload(os.path.join(DATA, "kitten.off"))

        async def run():
            async with AsyncGeodexClient("127.0.0.1:" + self.port, timeout=60) as client:
                before = await client.shortest_path(mesh.name, vertex(0), vertex(1250))
                loop = asyncio.get_running_loop()
                # The restart runs in a thread; the call is made on this loop while it is down.
                stopped = await loop.run_in_executor(None, self._stop_for_restart)
                try:
                    again = await client.shortest_path(mesh.name, vertex(0), vertex(1250))
                finally:
                    await loop.run_in_executor(None, stopped.join, 60)
                return before, again, client.retries
        before, again, retries = asyncio.run(run())
        self.assertEqual(again, before)
        self.assertGreater(retries, 0)

    def _stop_for_restart(self):
        """Stops geodexd and returns a started thread that brings it back 2 s later (longer than
        the 1.4 s the old policy's 4 attempts spanned)."""
        stop_geodexd(self.server, self.log)
        self.server = None

        def restart():
            time.sleep(2)
            self.server, _, self.log = start_geodexd(self.tmp.name, "127.0.0.1:" + self.port,
                                                     "again")
        thread = threading.Thread(target=restart)
        thread.start()
        return thread

    def test_a_server_that_stays_down_fails_within_the_reconnect_wait(self):
        policy = geodex.RetryPolicy(reconnect_wait=1.0)
        client = geodex.GeodexClient("127.0.0.1:1", timeout=30, retry=policy)
        start = time.monotonic()
        with self.assertRaises(geodex.UnavailableError):
            client.health()
        self.assertLess(time.monotonic() - start, 20)  # generous: the wait is 1 s, not 30

    def test_max_snap_refuses_far_points_and_answers_say_how_far(self):
        client = self.client(timeout=60)
        mesh = client.upload(os.path.join(DATA, "kitten.off"))
        box = mesh.resource.info
        far = (box.bbox_max.x + 0.2 * mesh.diagonal, box.bbox_max.y, box.bbox_max.z)
        d = client.locate(mesh.name, [far])[0].distance
        self.assertGreater(d, 0.1 * mesh.diagonal)
        # Refused by the server on path, paths and matrix, naming the point.
        for call, field in [
                (lambda **k: client.shortest_path(mesh.name, vertex(0), position(*far), **k),
                 "to.position"),
                (lambda **k: client.shortest_paths(mesh.name, [(vertex(0), position(*far))], **k),
                 "pairs[0].to.position"),
                (lambda **k: client.distance_matrix(mesh.name, [vertex(0)], [position(*far)], **k),
                 "targets[0].position")]:
            with self.assertRaises(geodex.InvalidArgumentError) as error:
                call(max_snap=d / 2)
            self.assertEqual(error.exception.field, field)
            self.assertIn("maximum snap distance", str(error.exception))
        with self.assertRaises(geodex.InvalidArgumentError) as error:  # the client's default
            self.client(timeout=60, max_snap=d / 2).shortest_path(mesh.name, vertex(0),
                                                                  position(*far))
        self.assertEqual(error.exception.field, "to.position")
        # Without max_snap it is snapped: the answer says how far (LocatePoints' distance, to the
        # bit) and, beyond 1% of the diagonal, a SnapWarning names it.
        with self.assertWarns(geodex.SnapWarning) as warned:
            path = client.shortest_path(mesh.name, vertex(0), position(*far))
        self.assertIn("end is", str(warned.warning))
        self.assertEqual(warned.filename, __file__)  # the caller's line, not the client's
        self.assertEqual(path.snap_distances.tolist(), [0.0, d])
        with self.assertWarns(geodex.SnapWarning):
            matrix = client.distance_matrix(mesh.name, [vertex(0), position(*far)], [vertex(9)])
        self.assertEqual(matrix.snap_distances.tolist(), [0.0, d, 0.0])
        self.assertEqual(matrix.shape, (2, 1))
        # A point a little off the surface passes without max_snap, silently.
        on = path.points[len(path.points) // 2].position
        near = (on[0], on[1], on[2] + 1e-3 * mesh.diagonal)
        with warnings.catch_warnings():
            warnings.simplefilter("error", geodex.SnapWarning)
            near_path = client.shortest_path(mesh.name, vertex(0), position(*near))
            field = client.distance_field(mesh.name, [position(*near), vertex(3)])
        self.assertGreater(near_path.snap_distances[1], 0)
        self.assertLessEqual(near_path.snap_distances[1], 1e-3 * mesh.diagonal * (1 + 1e-9))
        self.assertEqual(field.snap_distances.tolist(), [near_path.snap_distances[1], 0.0])
        self.assertEqual(client.shortest_path(mesh.name, vertex(0), position(*near),
                                              max_snap=2e-3 * mesh.diagonal).length,
                         near_path.length)

    def test_the_asyncio_client_gives_the_same_answers(self):
        from geodex.aio import AsyncGeodexClient
        quiet = warnings.catch_warnings()  # position(1, 2, 3) is far, on purpose
        quiet.__enter__()
        self.addCleanup(quiet.__exit__, None, None, None)
        warnings.simplefilter("ignore", geodex.SnapWarning)
        sync = self.client(timeout=120)
        kitten = os.path.join(DATA, "kitten.off")
        mesh = sync.upload(kitten)
        sites = [vertex(0), vertex(800), vertex(1600), position(1, 2, 3)]
        want = {
            "field": sync.distance_field(mesh.name, sites, want_directions=True),
            "path": sync.shortest_path(mesh.name, vertex(0), vertex(1250)),
            "paths": sync.shortest_paths(mesh.name, [(vertex(0), vertex(5)), (vertex(7), vertex(9))]),
            "matrix": sync.distance_matrix(mesh.name, sites, sites),
            "points": sync.point_distances(mesh.name, sites[:2], [vertex(5), position(0, 0, 0)]),
            "isolines": sync.isolines(mesh.name, sites, count=5),
            "voronoi": sync.voronoi(mesh.name, sites),
            "delaunay": sync.delaunay(mesh.name, sites),
            "locate": sync.locate(mesh.name, [(0, 0, 0), (1, 2, 3)]),
        }

        async def run():
            async with AsyncGeodexClient("127.0.0.1:" + self.port, timeout=120) as client:
                uploaded = await client.upload(read_off(kitten))
                self.assertEqual(uploaded.name, mesh.name)
                got = {
                    "field": await client.distance_field(mesh.name, sites, want_directions=True),
                    "path": await client.shortest_path(mesh.name, vertex(0), vertex(1250)),
                    "paths": await client.shortest_paths(
                        mesh.name, [(vertex(0), vertex(5)), (vertex(7), vertex(9))]),
                    "matrix": await client.distance_matrix(mesh.name, sites, sites),
                    "points": await client.point_distances(mesh.name, sites[:2],
                                                           [vertex(5), position(0, 0, 0)]),
                    "isolines": await client.isolines(mesh.name, sites, count=5),
                    "voronoi": await client.voronoi(mesh.name, sites),
                    "delaunay": await client.delaunay(mesh.name, sites),
                    "locate": await client.locate(mesh.name, [(0, 0, 0), (1, 2, 3)]),
                }
                # The same errors, deadline and snapping rule.
                big = await client.upload(bumpy_grid(211))
                with self.assertRaises(geodex.DeadlineExceededError):
                    await client.distance_field(big.name, [vertex(0)], timeout=0.005)
                with self.assertRaises(geodex.InvalidArgumentError) as error:
                    await client.shortest_path(mesh.name, vertex(0), position(1, 2, 3),
                                               max_snap=1e-9)
                self.assertEqual(error.exception.field, "to.position")
                with self.assertRaises(geodex.InvalidArgumentError) as error:
                    await client.export_gis(mesh.name, "isochrone", [vertex(0)])
                self.assertEqual(error.exception.field, "product")
                self.assertTrue(await client.health())
                return got
        got = asyncio.run(run())
        for name in ("field", "points"):
            for a, b in zip(want[name], got[name]):
                if isinstance(a, numpy.ndarray):
                    self.assertEqual(a.tobytes(), b.tobytes(), name)
            self.assertEqual(want[name].snap_distances.tobytes(), got[name].snap_distances.tobytes())
        self.assertEqual(want["matrix"].tobytes(), got["matrix"].tobytes())
        self.assertEqual(want["matrix"].snap_distances.tolist(),
                         got["matrix"].snap_distances.tolist())
        for name in ("path", "paths", "isolines", "voronoi", "delaunay", "locate"):
            self.assertEqual(want[name], got[name], name)

    def test_travel_answers_in_seconds_from_both_clients(self):
        from geodex.aio import AsyncGeodexClient
        sync = self.client(timeout=120)
        mesh = sync.upload(bumpy_grid(21))  # 800 faces
        # 3.6 km/h is 1 m/s: on weights 1 a time is the length in metres, within the bound.
        walk = geodex.Travel(speed_kmh=3.6, epsilon=0.05)
        weights = [1.0 + (f % 2) for f in range(mesh.face_count)]
        heavy = geodex.Travel(speed_kmh=3.6, epsilon=0.05, face_weights=weights)
        sources, targets = [vertex(0), vertex(220)], [vertex(440), vertex(17), vertex(300)]
        plain = sync.distance_field(mesh.name, sources)
        self.assertEqual(plain.travel_epsilon, 0.0)
        field = sync.distance_field(mesh.name, sources, travel=walk)
        self.assertEqual(field.travel_epsilon, 0.05)
        for metres, seconds in zip(plain.distances.tolist(), field.distances.tolist()):
            self.assertGreaterEqual(seconds, metres * (1 - 1e-9))
            self.assertLessEqual(seconds, metres * 1.05 + 1e-12)
        faster = sync.distance_field(mesh.name, sources, travel=geodex.Travel(7.2, epsilon=0.05))
        numpy.testing.assert_allclose(faster.distances, field.distances / 2, rtol=1e-12)
        weighted = sync.distance_field(mesh.name, sources, travel=heavy)
        self.assertGreater(weighted.distances.sum(), field.distances.sum())
        # One weight at a constant speed is the exact engine's answer, and says so; two weights
        # are within the bound; metres are not travel times.
        self.assertEqual((field.travel_exact, weighted.travel_exact, plain.travel_exact),
                         (True, False, False))
        # A path, a matrix and exact point values in seconds, consistent with the field.
        path = sync.shortest_path(mesh.name, vertex(0), vertex(440), travel=walk)
        self.assertEqual(path.travel_epsilon, 0.05)
        self.assertGreater(len(path.points), 1)
        exact = sync.shortest_path(mesh.name, vertex(0), vertex(440))
        self.assertEqual(exact.travel_epsilon, 0.0)
        self.assertGreaterEqual(path.length, exact.length * (1 - 1e-9))
        self.assertLessEqual(path.length, exact.length * 1.05)
        # Metres and seconds, both: length_m is the route's length, time_s its time (length is
        # the cost asked for); at 7.2 km/h (2 m/s) the time is length_m / 2 within the bound.
        self.assertIsNone(exact.time_s)
        self.assertAlmostEqual(exact.length_m, exact.length, delta=1e-12 * exact.length)
        self.assertEqual(path.time_s, path.length)
        self.assertGreaterEqual(path.length_m, exact.length * (1 - 1e-9))
        fast = sync.shortest_path(mesh.name, vertex(0), vertex(440),
                                  travel=geodex.Travel(7.2, epsilon=0.05))
        self.assertGreaterEqual(fast.time_s, fast.length_m / 2 * (1 - 1e-9))
        self.assertLessEqual(fast.time_s, exact.length_m / 2 * 1.05)
        self.assertAlmostEqual(fast.length_m, path.length_m, delta=1e-9 * path.length_m)
        matrix = sync.distance_matrix(mesh.name, sources, targets, travel=walk)
        self.assertEqual(matrix.travel_epsilon, 0.05)
        self.assertEqual(sync.distance_matrix(mesh.name, sources, targets).travel_epsilon, 0.0)
        metres = sync.distance_matrix(mesh.name, sources, targets)
        self.assertTrue(numpy.all(matrix >= metres * (1 - 1e-9)))
        self.assertTrue(numpy.all(matrix <= metres * 1.05))
        points = sync.point_distances(mesh.name, sources, targets, travel=walk)
        self.assertEqual(points.travel_epsilon, 0.05)
        self.assertEqual(len(points.estimates), 0)  # the unfolding estimate is of metres
        numpy.testing.assert_allclose(points.exact, matrix.min(axis=0), rtol=1e-12)
        self.assertTrue(path.travel_exact and matrix.travel_exact and points.travel_exact)
        paths = sync.shortest_paths(mesh.name, [(vertex(0), vertex(440))], travel=walk)
        self.assertTrue(paths[0].travel_exact)
        self.assertEqual((paths[0].length, paths[0].travel_epsilon), (path.length, 0.05))
        self.assertEqual((paths[0].length_m, paths[0].time_s), (path.length_m, path.time_s))
        isolines = sync.isolines(mesh.name, sources, count=4, travel=walk)
        self.assertEqual(isolines.travel_epsilon, 0.05)
        self.assertTrue(isolines.travel_exact)
        voronoi = sync.voronoi(mesh.name, sources, travel=walk)
        self.assertEqual((voronoi.travel_epsilon, voronoi.travel_exact), (0.05, True))
        self.assertFalse(sync.voronoi(mesh.name, sources, travel=heavy).travel_exact)
        gis_free = sync.shortest_path(mesh.name, vertex(0), vertex(440), travel=heavy)
        self.assertFalse(gis_free.travel_exact)
        # What a travel cost cannot do, and a bad value, name the field.
        with self.assertRaises(geodex.InvalidArgumentError) as error:
            sync.delaunay(mesh.name, sources, travel=walk)
        self.assertEqual(error.exception.field, "options.travel")
        with self.assertRaises(geodex.InvalidArgumentError) as error:
            sync.distance_field(mesh.name, sources, travel=geodex.Travel(speed_kmh=0))
        self.assertEqual(error.exception.field, "options.travel.speed_kmh")
        with self.assertRaises(geodex.InvalidArgumentError) as error:
            sync.distance_field(mesh.name, sources,
                                travel=geodex.Travel(3.6, face_weights=weights[:-1]))
        self.assertEqual(error.exception.field, "options.travel.face_weights")
        # Friction polygons in the mesh's x y: the left half at friction 2.
        half = {"type": "FeatureCollection", "features": [{
            "type": "Feature", "properties": {"friction": 2},
            "geometry": {"type": "Polygon",
                         "coordinates": [[[-1, -1], [0.5, -1], [0.5, 2], [-1, 2], [-1, -1]]]}}]}
        rough = sync.distance_field(mesh.name, sources,
                                    travel=geodex.Travel(3.6, epsilon=0.05, friction_geojson=half))
        self.assertEqual(rough.travel_epsilon, 0.05)
        self.assertGreater(rough.distances.sum(), field.distances.sum())
        # A friction polygon that cannot be used is refused naming the field, never dropped in
        # silence (a coordinate beyond any map, a ring of two distinct points).
        for ring in ([[-1, -1], [1e308, -1], [0.5, 2], [-1, -1]], [[-1, -1], [0.5, -1], [-1, -1]]):
            bad = {"type": "FeatureCollection", "features": [{
                "type": "Feature", "properties": {"friction": 2},
                "geometry": {"type": "Polygon", "coordinates": [ring]}}]}
            with self.assertRaises(geodex.InvalidArgumentError) as error:
                sync.distance_field(mesh.name, sources,
                                    travel=geodex.Travel(3.6, friction_geojson=bad))
            self.assertEqual(error.exception.field, "options.travel.friction_geojson")

        async def run():
            async with AsyncGeodexClient("127.0.0.1:" + self.port, timeout=120) as client:
                return (await client.distance_field(mesh.name, sources, travel=walk),
                        await client.shortest_path(mesh.name, vertex(0), vertex(440),
                                                   travel=walk),
                        await client.distance_matrix(mesh.name, sources, targets, travel=walk))
        a_field, a_path, a_matrix = asyncio.run(run())
        self.assertEqual(a_field.distances.tobytes(), field.distances.tobytes())
        self.assertEqual(a_field.travel_epsilon, 0.05)
        self.assertEqual(a_path, path)
        self.assertEqual(a_path.travel_epsilon, 0.05)
        self.assertEqual(a_matrix.tobytes(), matrix.tobytes())
        self.assertEqual(a_matrix.travel_epsilon, 0.05)

    def test_slope_dependent_speed_from_both_clients(self):
        from geodex.aio import AsyncGeodexClient
        sync = self.client(timeout=120)
        mesh = sync.upload(bumpy_grid(21))  # slopes up to about 24 degrees
        sources = [vertex(0), vertex(220)]
        plain = sync.distance_field(mesh.name, sources)
        # Tobler's speed: in seconds, never faster than its 6 km/h (0.6 s per metre of the
        # shortest path), and a dict of Travel's fields is the same request.
        tobler = geodex.Travel(speed="tobler", epsilon=0.05)
        field = sync.distance_field(mesh.name, sources, travel=tobler)
        self.assertEqual(field.travel_epsilon, 0.05)
        self.assertTrue(numpy.all(numpy.isfinite(field.distances)))
        self.assertTrue(numpy.all(field.distances >= plain.distances * 0.6 * (1 - 1e-9)))
        self.assertGreater(field.distances.max(), 0)
        same = sync.distance_field(mesh.name, sources, travel={"speed": "tobler", "epsilon": 0.05})
        self.assertEqual(same.distances.tobytes(), field.distances.tobytes())
        # Epsilon unset: the speed model's default, 0.125 for a slope speed (0.01 for a constant
        # one).
        coarse = sync.distance_field(mesh.name, sources, travel=geodex.Travel(speed="tobler"))
        self.assertEqual(coarse.travel_epsilon, 0.125)
        numpy.testing.assert_allclose(coarse.distances, field.distances, rtol=0.02)
        self.assertEqual(
            sync.distance_field(mesh.name, sources, travel=geodex.Travel(3.6)).travel_epsilon, 0.01)
        # Towards the sources is not from them on the bumps (its own field, not the cached one).
        inbound = geodex.Travel(speed="tobler", epsilon=0.05, inbound=True)
        towards = sync.distance_field(mesh.name, sources, travel=inbound, want_stats=True)
        self.assertFalse(towards.stats.cached)
        self.assertEqual(towards.travel_epsilon, 0.05)
        differ = numpy.abs(towards.distances - field.distances) > 1e-6 * field.distances
        self.assertGreater(differ.sum(), len(field.distances) // 2)
        # A matrix is row to column (not symmetric); inbound, column to row.
        points = [vertex(0), vertex(220), vertex(440)]
        matrix = sync.distance_matrix(mesh.name, points, points, travel=tobler)
        self.assertFalse(numpy.allclose(matrix, matrix.T, rtol=1e-6))
        back = sync.distance_matrix(mesh.name, points, points, travel=inbound)
        # Equal within the discretisation: a slope cost's search crosses between Steiner points,
        # which a search from the other end approximates differently (the asymmetry is ~15%).
        numpy.testing.assert_allclose(back, matrix.T, rtol=0.01)
        # A path is walked from its start (the way back takes another time) and refuses inbound.
        there = sync.shortest_path(mesh.name, vertex(0), vertex(440), travel=tobler)
        back_path = sync.shortest_path(mesh.name, vertex(440), vertex(0), travel=tobler)
        self.assertEqual(there.travel_epsilon, 0.05)
        self.assertGreater(len(there.points), 1)
        self.assertNotEqual(there.length, back_path.length)
        with self.assertRaises(geodex.InvalidArgumentError) as error:
            sync.shortest_path(mesh.name, vertex(0), vertex(440), travel=inbound)
        self.assertEqual(error.exception.field, "options.travel.inbound")
        # A speed table (the model follows from the rows); speed_kmh=5 still means constant.
        table = geodex.Travel(speed_table=[(-30, 2), (-5, 5.5), (0, 5), (30, 1.5)], epsilon=0.05)
        tabled = sync.distance_field(mesh.name, sources, travel=table)
        self.assertEqual(tabled.travel_epsilon, 0.05)
        self.assertNotEqual(tabled.distances.tobytes(), field.distances.tobytes())
        constant = sync.distance_field(mesh.name, sources,
                                       travel=geodex.Travel(speed_kmh=5, epsilon=0.05))
        self.assertNotEqual(constant.distances.tobytes(), field.distances.tobytes())
        # Bad values name their field: the server's checks, and the client's own.
        cases = [
            (geodex.Travel(speed_table=[(-30, 2), (0, -5), (30, 2)]),
             "options.travel.speed_table[1]"),
            (geodex.Travel(speed_table=[(0, 5)]), "options.travel.speed_table"),
            (geodex.Travel(speed="tobler", speed_table=[(-30, 2), (30, 2)]),
             "options.travel.speed_table"),
            (geodex.Travel(5, speed="tobler"), "options.travel.speed_kmh"),
            (geodex.Travel(speed="table"), "options.travel.speed_table"),
            (geodex.Travel(speed="walk"), "options.travel.speed_model"),
            (geodex.Travel(speed_table=[(0, 5, 1), (10, 2, 1)]), "options.travel.speed_table"),
        ]
        for travel, field_name in cases:
            with self.assertRaises(geodex.InvalidArgumentError, msg=str(travel)) as error:
                sync.distance_field(mesh.name, sources, travel=travel)
            self.assertEqual(error.exception.field, field_name, str(error.exception))
        with self.assertRaises(geodex.InvalidArgumentError) as error:
            sync.distance_field(mesh.name, sources, travel=geodex.Travel(speed="walk"))
        self.assertIn("tobler", str(error.exception))  # lists the valid ones

        async def run():
            async with AsyncGeodexClient("127.0.0.1:" + self.port, timeout=120) as client:
                return (await client.distance_field(mesh.name, sources, travel=inbound),
                        await client.distance_matrix(mesh.name, points, points, travel=tobler))
        a_field, a_matrix = asyncio.run(run())
        self.assertEqual(a_field.distances.tobytes(), towards.distances.tobytes())
        self.assertEqual(a_matrix.tobytes(), matrix.tobytes())

    def test_bad_names_are_typed_errors(self):
        client = self.client(timeout=60)
        mesh = client.upload(os.path.join(DATA, "knight.off"))
        with self.assertRaises(geodex.InvalidArgumentError) as error:
            client.export_gis(mesh.name, "isochrone", [vertex(0)])
        self.assertIn("isochrones", str(error.exception))  # lists the valid ones
        self.assertEqual(error.exception.field, "product")
        with self.assertRaises(geodex.InvalidArgumentError) as error:
            client.shortest_path(mesh.name, vertex(0), vertex(5), lamda=0.5)
        self.assertEqual(error.exception.field, "options.lamda")
        path = client.shortest_path(mesh.name, vertex(0), vertex(5), lambda_scale="mean_edge",
                                    lambda_=0.5)
        self.assertGreater(path.length, 0)


if __name__ == "__main__":
    unittest.main(verbosity=2)
