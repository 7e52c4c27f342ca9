"""A small Python client for geodexd (geodex.v1), on Debian's python3-grpcio.

The stubs (geodex/v1/geodex_pb2.py, geodex_pb2_grpc.py) are generated at build time into
build/python; put that directory on PYTHONPATH (see client/python/README.md).

    client = GeodexClient("127.0.0.1:50051")
    mesh = client.upload("tests/data/kitten.off", name="kitten")
    field = client.distance_field(mesh.name, [vertex(0)])
    path = client.shortest_path(mesh.name, vertex(0), vertex(1250))
    rows = client.distance_matrix(mesh.name, [vertex(0), vertex(5)], [vertex(7), vertex(99)],
                                  k_nearest=1, max_distance=40.0)
    cells, boundaries = client.voronoi(mesh.name, [vertex(0), vertex(1250)])
"""
import os

import grpc

from geodex.v1 import geodex_pb2 as pb
from geodex.v1 import geodex_pb2_grpc as pb_grpc

CHUNK_BYTES = 1 << 20


def vertex(v):
    """A vertex as a SurfacePoint."""
    return pb.SurfacePoint(vertex=v)


def face_point(face, b0, b1, b2):
    """A point inside a face, by barycentric coordinates in the file's corner order."""
    return pb.SurfacePoint(face=pb.FacePoint(face=face, b0=b0, b1=b1, b2=b2))


def position(x, y, z):
    """A 3D position, snapped to the surface by the server."""
    return pb.SurfacePoint(position=pb.Position(x=x, y=y, z=z))


class GeodexClient:
    """Blocking calls with a deadline; mesh-scoped calls carry the mesh id as x-mesh-id."""

    def __init__(self, target, timeout=600.0):
        self.channel = grpc.insecure_channel(target)
        self.stub = pb_grpc.GeodexStub(self.channel)
        self.timeout = timeout
        # grpc.health.v1 without its generated module: HealthCheckRequest{} is empty bytes and
        # HealthCheckResponse{status: SERVING} is 08 01.
        self._health = self.channel.unary_unary(
            "/grpc.health.v1.Health/Check",
            request_serializer=lambda b: b, response_deserializer=lambda b: b)

    @staticmethod
    def _metadata(mesh_name):
        key = mesh_name[len("meshes/"):] if mesh_name.startswith("meshes/") else mesh_name
        if len(key) == 64 and all(c in "0123456789abcdef" for c in key):
            return (("x-mesh-id", key),)
        return ()

    def health(self):
        """True when the server says SERVING."""
        return self._health(b"", timeout=self.timeout) == b"\x08\x01"

    def upload(self, path, name="", pin=False):
        """Uploads a mesh file in 1 MiB chunks (idempotent); returns the Mesh resource."""
        def requests():
            yield pb.CreateMeshRequest(metadata=pb.CreateMeshMetadata(
                file_name=os.path.basename(path), display_name=name, pin=pin,
                total_bytes=os.path.getsize(path)))
            with open(path, "rb") as f:
                while True:
                    chunk = f.read(CHUNK_BYTES)
                    if not chunk:
                        return
                    yield pb.CreateMeshRequest(chunk=chunk)
        return self.stub.CreateMesh(requests(), timeout=self.timeout)

    def get_mesh(self, mesh):
        return self.stub.GetMesh(pb.GetMeshRequest(name=mesh), timeout=self.timeout,
                                 metadata=self._metadata(mesh))

    def distance_field(self, mesh, sources, want_stats=False, **options):
        """(distances, labels, stats) for every vertex, reassembled from the streamed chunks."""
        request = pb.ComputeDistanceFieldRequest(
            mesh=mesh, sources=sources, options=pb.SolverOptions(**options), want_stats=want_stats)
        distances, labels, stats = [], [], None
        for chunk in self.stub.ComputeDistanceField(request, timeout=self.timeout,
                                                    metadata=self._metadata(mesh)):
            assert chunk.offset == len(distances)
            distances.extend(chunk.distances_f64)
            labels.extend(chunk.labels)
            if chunk.HasField("stats"):
                stats = chunk.stats
        return distances, labels, stats

    def shortest_path(self, mesh, start, end):
        """The exact shortest path: (length, [(x, y, z), ...])."""
        response = self.stub.FindShortestPath(
            pb.FindShortestPathRequest(mesh=mesh, to=end, **{"from": start}),
            timeout=self.timeout, metadata=self._metadata(mesh))
        points = [(p.position.x, p.position.y, p.position.z) for p in response.points]
        return response.distance, points

    def shortest_paths(self, mesh, pairs, **options):
        """Many exact shortest paths in one call, [(start, end), ...] -> [(length, points), ...];
        pairs from the same start share one solve. An unreachable end gives (inf, [])."""
        request = pb.FindShortestPathsRequest(
            mesh=mesh, pairs=[pb.ShortestPathPair(to=end, **{"from": start}) for start, end in pairs],
            options=pb.SolverOptions(**options))
        response = self.stub.FindShortestPaths(request, timeout=self.timeout,
                                               metadata=self._metadata(mesh))
        return [(p.distance, [(q.position.x, q.position.y, q.position.z) for q in p.points])
                for p in response.paths]

    def distance_matrix(self, mesh, sources, targets, k_nearest=0, on_progress=None, **options):
        """Exact distances, one row per source: [[d(source, target), ...], ...]. `k_nearest`
        keeps only each source's k nearest targets (the rest are inf); `options` are
        SolverOptions fields (lambda_, max_distance, ...; lambda is spelled `lambda_` here or
        passed as options={"lambda": x}). The server streams rows as they finish:
        `on_progress(rows_received, rows, fraction_solved)`, when given, is called per message."""
        solver = dict(options.pop("options", {}))
        if "lambda_" in options:
            solver["lambda"] = options.pop("lambda_")
        solver.update(options)
        request = pb.ComputeDistanceMatrixRequest(
            mesh=mesh, sources=sources, targets=targets, k_nearest=k_nearest,
            options=pb.SolverOptions(**solver))
        values, rows, cols = [], 0, 0
        for chunk in self.stub.ComputeDistanceMatrix(request, timeout=self.timeout,
                                                     metadata=self._metadata(mesh)):
            assert chunk.offset == len(values)
            rows, cols = chunk.rows, chunk.cols
            values.extend(chunk.values_f64)
            if on_progress is not None and cols:
                on_progress(len(values) // cols, rows, chunk.progress)
        return [values[r * cols:(r + 1) * cols] for r in range(rows)]

    def voronoi(self, mesh, sites):
        """The approximate Voronoi diagram: ({site: area}, [(site_a, site_b, [(x, y, z), ...])]),
        with cells and boundaries reassembled from their streamed pieces."""
        request = pb.ComputeVoronoiRequest(mesh=mesh, sources=sites, omit_cell_faces=True)
        areas, boundaries, open_boundary = {}, [], False
        for message in self.stub.ComputeVoronoi(request, timeout=self.timeout,
                                                metadata=self._metadata(mesh)):
            for cell in message.cells:
                areas[cell.site] = cell.area
            for piece in message.boundaries:
                points = [(p.position.x, p.position.y, p.position.z) for p in piece.points]
                if open_boundary:
                    boundaries[-1][2].extend(points)
                else:
                    boundaries.append((piece.site_a, piece.site_b, points))
                open_boundary = piece.continued
        return areas, boundaries
