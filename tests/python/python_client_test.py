#!/usr/bin/python3
"""The Python client against a real geodexd (127.0.0.1, a port it picks): upload, distance field,
shortest path and Voronoi, each checked against the geodex CLI's local answer. Bounded: the server
is started and stopped here, every wait gives up.
Env: GEODEX, GEODEXD (binaries), DATA (tests/data); PYTHONPATH has build/python and client/python.
"""
import os
import re
import signal
import subprocess
import tempfile
import time
import unittest

import grpc

from geodex_client import GeodexClient, face_point, vertex

GEODEX, GEODEXD, DATA = os.environ["GEODEX"], os.environ["GEODEXD"], os.environ["DATA"]


class PythonClientTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        cls.log = open(os.path.join(cls.tmp.name, "server.log"), "w+")
        cls.server = subprocess.Popen(
            [GEODEXD, "--listen", "127.0.0.1:0", "--metrics_listen", "", "--pool-threads", "2",
             "--data-dir", os.path.join(cls.tmp.name, "data"), "--shutdown_grace_seconds", "5"],
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
        distances, labels, stats = self.client.distance_field(
            self.mesh.name, [vertex(0), face_point(10, 0.2, 0.3, 0.5)], want_stats=True)
        expected = [float(x) for x in
                    self.local("distances", os.path.join(DATA, "kitten.off"), "--sources",
                               "0,f:10:0.2:0.3:0.5").split()]
        self.assertEqual(distances, expected)  # bit for bit (%.17g round-trips)
        self.assertEqual(set(labels), {0, 1})
        self.assertGreater(stats.windows_created, 0)

    def test_shortest_path_equals_the_cli(self):
        length, points = self.client.shortest_path(self.mesh.name, vertex(0), vertex(1250))
        lines = self.local("path", os.path.join(DATA, "kitten.off"), "--from", "0", "--to",
                           "1250").splitlines()
        self.assertEqual(length, float(lines[0]))
        self.assertEqual(len(points), len(lines) - 1)
        self.assertEqual(points[-1], tuple(float(x) for x in lines[-1].split()[:3]))

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
        self.assertEqual(full, [[float(x) for x in line.split()] for line in lines])  # bit for bit
        nearest = self.client.distance_matrix(self.mesh.name, [vertex(v) for v in sources],
                                              [vertex(v) for v in targets], k_nearest=2)
        for row, kept in zip(full, nearest):
            finite = sorted(d for d in kept if d != float("inf"))
            self.assertEqual(finite, sorted(row)[:2])  # the two nearest, exact
        limit = sum(sorted(full[0])[1:3]) / 2  # between two entries: no ties at the limit
        capped = self.client.distance_matrix(self.mesh.name, [vertex(v) for v in sources],
                                             [vertex(v) for v in targets], max_distance=limit)
        for row, cut in zip(full, capped):
            self.assertEqual(cut, [d if d < limit else float("inf") for d in row])
        with self.assertRaises(grpc.RpcError) as error:
            self.client.distance_matrix(self.mesh.name, [vertex(0)], [vertex(7)], lambda_=2.0)
        self.assertEqual(error.exception.code(), grpc.StatusCode.INVALID_ARGUMENT)
        self.assertIn("options.lambda", error.exception.details())

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
        areas, boundaries = self.client.voronoi(self.mesh.name, sites)
        self.assertEqual(sorted(areas), [0, 1, 2, 3])
        self.assertTrue(all(a > 0 for a in areas.values()))
        self.assertTrue(boundaries)
        for a, b, points in boundaries:
            self.assertLess(a, b)
            self.assertGreaterEqual(len(points), 2)

    def test_errors_carry_the_status_code(self):
        import grpc
        with self.assertRaises(grpc.RpcError) as error:
            self.client.distance_field(self.mesh.name, [vertex(99999)])
        self.assertEqual(error.exception.code(), grpc.StatusCode.INVALID_ARGUMENT)
        self.assertIn("sources[0].vertex", error.exception.details())


if __name__ == "__main__":
    unittest.main(verbosity=2)
