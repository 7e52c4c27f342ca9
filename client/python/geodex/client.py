"""GeodexClient: blocking calls to geodexd (geodex.v1) over Debian's python3-grpcio.

Every method of the API is here; streamed answers are reassembled; failures raise the typed
exceptions of geodex.errors. Points are geodex.v1 SurfacePoint messages (see vertex(), edge_point(),
face_point(), position(), and on a DEM's mesh map_point(), lon_lat()).

A control loop's policy, the same on every method:

- `timeout=` (seconds) bounds the whole call, retries included (the client's `timeout` when not
  given). When it passes, DeadlineExceededError.
- UNAVAILABLE (the server not listening yet, restarting, draining) and RESOURCE_EXHAUSTED with
  reason QUEUE_FULL (every worker busy) are retried with exponential backoff (`RetryPolicy`:
  4 attempts, 0.2 s doubled each time), while the deadline leaves room; a limit (reason LIMIT)
  never is. With `wait_for_ready=True` an attempt waits for the server to come up instead.
- A mesh this client uploaded (from a path, bytes or arrays) that the server lost (NOT_FOUND,
  reason MESH_NOT_FOUND: a restarted replica) is uploaded again, once, and the call retried.

Fields, labels, directions and matrices come back as numpy arrays read straight from the packed
wire bytes (no Python object per value).
"""
import dataclasses
import os
import time
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple, Union

import grpc
import numpy as np

from .errors import DeadlineExceededError, InvalidArgumentError, from_rpc_error
from .v1 import geodex_pb2 as pb
from .v1 import geodex_pb2_grpc as pb_grpc

CHUNK_BYTES = 1 << 20


def vertex(v: int) -> "pb.SurfacePoint":
    """A vertex as a SurfacePoint."""
    return pb.SurfacePoint(vertex=v)


def edge_point(a: int, b: int, t: float) -> "pb.SurfacePoint":
    """The point (1 - t) * a + t * b on the edge between vertices a and b."""
    return pb.SurfacePoint(edge=pb.EdgePoint(to=b, t=t, **{"from": a}))


def face_point(face: int, b0: float, b1: float, b2: float) -> "pb.SurfacePoint":
    """A point inside a face, by barycentric coordinates in the file's corner order."""
    return pb.SurfacePoint(face=pb.FacePoint(face=face, b0=b0, b1=b1, b2=b2))


def position(x: float, y: float, z: float) -> "pb.SurfacePoint":
    """A 3D position, snapped to the surface by the server."""
    return pb.SurfacePoint(position=pb.Position(x=x, y=y, z=z))


def map_point(x: float, y: float) -> "pb.SurfacePoint":
    """On a DEM's mesh (uploaded as a GeoTIFF): a map point in the raster's CRS, dropped
    vertically onto the surface by the server (the CLI's g:X:Y)."""
    return pb.SurfacePoint(map_point=pb.MapPoint(x=x, y=y))


def lon_lat(lon: float, lat: float) -> "pb.SurfacePoint":
    """On a DEM's mesh: a WGS 84 longitude/latitude in degrees, dropped likewise (ll:LON:LAT)."""
    return pb.SurfacePoint(lon_lat=pb.LonLat(lon=lon, lat=lat))


# --- results: one kind of object, dataclasses; each also unpacks like a tuple ---------------

class _Unpacks:
    def __iter__(self):  # the fields marked unpack=False (added later) are left out
        return iter(getattr(self, f.name) for f in dataclasses.fields(self)
                    if f.metadata.get("unpack", True))


@dataclasses.dataclass
class PathPoint(_Unpacks):
    """A point of a path or polyline: its position (x, y, z) and the simplex it lies on,
    ("v", vertex) / ("e", from, to, t) / ("f", face, b0, b1, b2)."""
    position: Tuple[float, float, float]
    simplex: tuple


@dataclasses.dataclass
class Path(_Unpacks):
    """An exact shortest path: its length and its points (`length, points = path`); with
    want_stats, the solve's SolveStats in `stats` (solve_ms, windows_created, cached, ...)."""
    length: float
    points: List[PathPoint]
    stats: Any = dataclasses.field(default=None, compare=False, metadata={"unpack": False})


@dataclasses.dataclass(eq=False)
class Field(_Unpacks):
    """A distance field: per vertex the distance (float64, inf where unreachable) and the nearest
    source's index (uint32), the solve's stats (with want_stats, else None), and with
    want_directions the geodesic direction field, shape (n, 3): per vertex the unit tangent
    towards the nearest source, (0, 0, 0) at a source, NaN where unreachable (shape (0, 3)
    otherwise)."""
    distances: np.ndarray
    labels: np.ndarray
    stats: Any
    directions: np.ndarray


@dataclasses.dataclass
class Located(_Unpacks):
    """Where a 3D position lands: the surface point (a SurfacePoint), its position, how far it
    moved."""
    point: Any
    position: Tuple[float, float, float]
    distance: float


@dataclasses.dataclass(eq=False)
class PointDistances(_Unpacks):
    """Distances at surface points (arrays, one entry per point): the unfolding estimate and the
    exact distance, each with its source; with want_directions each point's geodesic direction
    towards its nearest source, shape (n, 3) (else (0, 3))."""
    estimates: np.ndarray
    estimate_labels: np.ndarray
    exact: np.ndarray
    exact_labels: np.ndarray
    directions: np.ndarray


@dataclasses.dataclass
class Isolines(_Unpacks):
    """Approximate isolines (paper section 6.1): the levels and (level, closed, [PathPoint])
    lines."""
    levels: List[float]
    lines: list


@dataclasses.dataclass
class Voronoi(_Unpacks):
    """Approximate Voronoi diagram: {site: area}, [(site_a, site_b, [PathPoint])] boundaries,
    [(a, b)] adjacency."""
    areas: Dict[int, float]
    boundaries: list
    adjacency: List[Tuple[int, int]]


@dataclasses.dataclass
class Delaunay(_Unpacks):
    """Approximate Delaunay triangulation: [(site_a, site_b, length, [PathPoint])] edges and
    [(a, b, c)] triangles."""
    edges: list
    triangles: List[Tuple[int, int, int]]


@dataclasses.dataclass
class Mesh:
    """A mesh as geodexd stores it. `name` is canonical, "meshes/<64-hex id>"; `aliases` are all
    the names given to it (the first upload's `display_name` and later ones: "kitten" makes
    "meshes/kitten" work wherever the name does). `terrain` is the DEM's map
    (a geodex.v1.Terrain message) for a DEM's mesh, else None. `resource` is the full message."""
    name: str
    display_name: str
    aliases: List[str]
    vertex_count: int
    face_count: int
    upload_bytes: int
    memory_bytes: int
    pinned: bool
    components: int
    boundary_edges: int
    terrain: Any
    resource: Any = dataclasses.field(repr=False, compare=False)

    @property
    def id(self) -> str:
        return self.name[len("meshes/"):]

    @staticmethod
    def from_proto(m) -> "Mesh":
        names = [n for n in [m.display_name, *m.aliases] if n]
        return Mesh(m.name, m.display_name, names, m.vertex_count, m.face_count,
                    m.upload_bytes, m.memory_bytes, m.pinned, m.components, m.boundary_edges,
                    m.terrain if m.HasField("terrain") else None, m)


@dataclasses.dataclass
class RetryPolicy:
    """Which failures are tried again, how often and how far apart (see the module's docstring).
    Retries happen only while the call's deadline leaves room for the wait."""
    max_attempts: int = 4
    initial_backoff: float = 0.2
    multiplier: float = 2.0
    retry_queue_full: bool = True


# --- reading packed numbers straight off the wire -------------------------------------------

def _varint(data, i):
    shift = result = 0
    while True:
        b = data[i]
        i += 1
        result |= (b & 0x7F) << shift
        if b < 0x80:
            return result, i
        shift += 7


def _split_packed(data: bytes, wanted: Dict[int, str]):
    """Splits a serialized message: the packed repeated fields numbered in `wanted` (number ->
    numpy dtype) become arrays, without a Python object per value; the other fields stay bytes, to
    be parsed as the message. Accepts the unpacked encoding too (a proto3 writer may use it)."""
    parts: Dict[int, list] = {n: [] for n in wanted}
    rest = bytearray()
    view = memoryview(data)
    i, n = 0, len(data)
    while i < n:
        start = i
        key, i = _varint(data, i)
        number, wire = key >> 3, key & 7
        if wire == 0:
            _, i = _varint(data, i)
            begin = i
        elif wire == 1:
            begin, i = i, i + 8
        elif wire == 5:
            begin, i = i, i + 4
        elif wire == 2:
            length, begin = _varint(data, i)
            i = begin + length
        else:
            raise ValueError("unsupported wire type %d" % wire)
        if number in wanted:
            parts[number].append(view[begin:i])
        else:
            rest += view[start:i]
    arrays = {num: np.frombuffer(b"".join(chunks), dtype=wanted[num]) if chunks
              else np.zeros(0, dtype=wanted[num]) for num, chunks in parts.items()}
    return arrays, bytes(rest)


def _simplex(where):
    kind = where.WhichOneof("point")
    if kind == "vertex":
        return ("v", where.vertex)
    if kind == "edge":
        return ("e", getattr(where.edge, "from"), where.edge.to, where.edge.t)
    if kind == "face":
        return ("f", where.face.face, where.face.b0, where.face.b1, where.face.b2)
    return ("p",)


def _path_points(points):
    return [PathPoint((p.position.x, p.position.y, p.position.z), _simplex(p.where))
            for p in points]


def _solver_options(options):
    """SolverOptions from keyword arguments; lambda is spelled `lambda_` (or options={...}).
    An unknown name is an InvalidArgumentError naming it and the valid ones."""
    solver = dict(options.pop("options", {}))
    if "lambda_" in options:
        solver["lambda"] = options.pop("lambda_")
    solver.update(options)
    valid = [f.name for f in pb.SolverOptions.DESCRIPTOR.fields]
    for name in solver:
        if name not in valid:
            raise InvalidArgumentError(
                grpc.StatusCode.INVALID_ARGUMENT,
                "unknown option %r (solver options: %s; per call: timeout)" % (
                    name, ", ".join("lambda_" if v == "lambda" else v for v in valid)),
                field="options." + name)
    if isinstance(solver.get("lambda_scale"), str):
        solver["lambda_scale"] = _enum_value(pb.LambdaScale, "LAMBDA_SCALE_", solver["lambda_scale"],
                                             "lambda_scale")
    return pb.SolverOptions(**solver)


def _enum_value(enum, prefix, name, field):
    """An enum value by its short name ("max_edge", "isochrones"), or InvalidArgumentError listing
    the valid ones."""
    full = prefix + str(name).upper()
    if full in enum.keys():
        return enum.Value(full)
    valid = [k[len(prefix):].lower() for k in enum.keys() if not k.endswith("UNSPECIFIED")]
    raise InvalidArgumentError(grpc.StatusCode.INVALID_ARGUMENT,
                               "%s: unknown value %r (valid: %s)" % (field, name, ", ".join(valid)),
                               field=field)


def _reassemble(pieces, start):
    """Items streamed in pieces: a piece continues the previous item when that one said
    `continued`. `start(piece)` makes a new item with a `points` list."""
    items, open_item = [], False
    for piece in pieces:
        if not open_item:
            items.append(start(piece))
        items[-1][-1].extend(_path_points(piece.points))
        open_item = piece.continued
    return items


def _off_text(vertices, faces) -> bytes:
    """A mesh from arrays as OFF text with coordinates that round-trip exactly (%.17g): the
    server computes the same mesh id as for a file with these float64 values."""
    v = np.asarray(vertices, dtype=np.float64).reshape(-1, 3)
    f = np.asarray(faces, dtype=np.int64).reshape(-1, 3)
    lines = ["OFF", "%d %d 0" % (len(v), len(f))]
    lines += ["%.17g %.17g %.17g" % tuple(row) for row in v.tolist()]
    lines += ["3 %d %d %d" % tuple(row) for row in f.tolist()]
    return ("\n".join(lines) + "\n").encode()


MeshSource = Union[str, "os.PathLike[str]", bytes, Tuple[Any, Any]]


class GeodexClient:
    """Blocking calls with a deadline (`timeout` seconds per call, retries included), retries and
    re-upload as the module says; mesh-scoped calls carry the mesh id as x-mesh-id (for a
    mesh-affine gateway). `token`: a bearer token (over TLS with `root_pem`). Not thread-safe
    for its counters only: calls from several threads are fine."""

    def __init__(self, target: str, timeout: float = 600.0, token: Optional[str] = None,
                 root_pem: Optional[bytes] = None, retry: Optional[RetryPolicy] = None,
                 wait_for_ready: bool = False):
        if root_pem is not None or token is not None:
            credentials = grpc.ssl_channel_credentials(root_certificates=root_pem)
            if token is not None:
                credentials = grpc.composite_channel_credentials(
                    credentials, grpc.access_token_call_credentials(token))
            self.channel = grpc.secure_channel(target, credentials)
        else:
            self.channel = grpc.insecure_channel(target)
        self.stub = pb_grpc.GeodexStub(self.channel)
        self.timeout = timeout
        self.retry = retry or RetryPolicy()
        self.wait_for_ready = wait_for_ready
        self.retries = 0    # attempts made again (UNAVAILABLE, a full queue)
        self.reuploads = 0  # meshes uploaded again after the server lost them
        # What this client uploaded, to upload it again: name -> (bytes, file name, DemOptions).
        self._uploads: Dict[str, tuple] = {}
        # The two big streams, read as raw bytes (their numbers become numpy arrays).
        self._raw_field = self.channel.unary_stream(
            "/geodex.v1.Geodex/ComputeDistanceField",
            request_serializer=pb.ComputeDistanceFieldRequest.SerializeToString)
        self._raw_matrix = self.channel.unary_stream(
            "/geodex.v1.Geodex/ComputeDistanceMatrix",
            request_serializer=pb.ComputeDistanceMatrixRequest.SerializeToString)
        # grpc.health.v1 without its generated module: HealthCheckRequest{} is empty bytes and
        # HealthCheckResponse{status: SERVING} is 08 01.
        self._health = self.channel.unary_unary(
            "/grpc.health.v1.Health/Check",
            request_serializer=lambda b: b, response_deserializer=lambda b: b)

    def close(self):
        self.channel.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    @staticmethod
    def _metadata(mesh_name):
        if not mesh_name:
            return ()
        key = mesh_name[len("meshes/"):] if mesh_name.startswith("meshes/") else mesh_name
        if len(key) == 64 and all(c in "0123456789abcdef" for c in key):
            return (("x-mesh-id", key),)
        return ()

    def _run(self, attempt: Callable[[float, tuple], Any], mesh: Optional[str] = None,
             timeout: Optional[float] = None):
        """Runs `attempt(seconds_left, metadata)` (one whole RPC, its stream read) under the
        module's policy: one deadline for the call, retries, one re-upload."""
        deadline = time.monotonic() + (self.timeout if timeout is None else timeout)
        backoff, tries, reuploaded = self.retry.initial_backoff, 0, False
        while True:
            tries += 1
            left = deadline - time.monotonic()
            if left <= 0 and tries > 1:  # the first attempt is always made
                raise DeadlineExceededError(grpc.StatusCode.DEADLINE_EXCEEDED,
                                            "the call's timeout passed (after %d attempts)" % (tries - 1))
            left = max(left, 1e-6)
            try:
                return attempt(left, self._metadata(mesh))
            except grpc.RpcError as rpc_error:
                error = from_rpc_error(rpc_error)
                code = error.code
                retryable = code == grpc.StatusCode.UNAVAILABLE or (
                    self.retry.retry_queue_full and code == grpc.StatusCode.RESOURCE_EXHAUSTED
                    and error.reason == "QUEUE_FULL")
                if (retryable and tries < self.retry.max_attempts
                        and deadline - time.monotonic() > backoff):
                    time.sleep(backoff)
                    backoff *= self.retry.multiplier
                    self.retries += 1
                    continue
                if (code == grpc.StatusCode.NOT_FOUND and error.reason == "MESH_NOT_FOUND"
                        and not reuploaded and mesh in self._uploads):
                    reuploaded = True
                    self.reuploads += 1
                    data, file_name, dem = self._uploads[mesh]
                    self._upload_bytes(data, file_name, "", False, dem,
                                       max(0.001, deadline - time.monotonic()))
                    continue
                raise error from rpc_error

    def _unary(self, rpc, request, mesh=None, timeout=None):
        return self._run(lambda left, md: rpc(request, timeout=left, metadata=md,
                                              wait_for_ready=self.wait_for_ready), mesh, timeout)

    def _stream(self, rpc, request, mesh=None, timeout=None, consume=list):
        return self._run(lambda left, md: consume(rpc(request, timeout=left, metadata=md,
                                                      wait_for_ready=self.wait_for_ready)),
                         mesh, timeout)

    # --- meshes ---

    def health(self, timeout: Optional[float] = None) -> bool:
        """True when the server says SERVING."""
        return self._unary(self._health, b"", timeout=timeout) == b"\x08\x01"

    def _upload_bytes(self, data, file_name, name, pin, dem, timeout):
        def attempt(left, metadata):
            def requests():
                meta = pb.CreateMeshMetadata(file_name=file_name, display_name=name, pin=pin,
                                             total_bytes=len(data))
                if dem is not None:
                    meta.format = pb.MESH_FORMAT_GEOTIFF
                    meta.dem.CopyFrom(dem)
                yield pb.CreateMeshRequest(metadata=meta)
                for offset in range(0, len(data), CHUNK_BYTES):
                    yield pb.CreateMeshRequest(chunk=data[offset:offset + CHUNK_BYTES])
            return self.stub.CreateMesh(requests(), timeout=left, metadata=metadata,
                                        wait_for_ready=self.wait_for_ready)
        return Mesh.from_proto(self._run(attempt, None, timeout))

    def upload(self, source: MeshSource, name: str = "", pin: bool = False,
               dem_step: Optional[int] = None, barrier_below: Optional[float] = None,
               file_name: Optional[str] = None, timeout: Optional[float] = None) -> Mesh:
        """Uploads a mesh in 1 MiB chunks (idempotent: by content hash) and returns its `Mesh`.

        `source`: a file path; the file's bytes (give `file_name`, whose extension names the
        format: "mesh.off", "mesh.ply.gz", "dem.tif"); or a `(vertices, faces)` pair of arrays
        (n x 3 coordinates, m x 3 vertex ids), sent as float64 OFF text, so its mesh id equals
        that of a file with the same values. `name` gives it an alias.

        A GeoTIFF (.tif, .tiff) is a DEM: geodexd makes it a mesh in metres and keeps its map
        (Mesh.terrain), so map_point() and lon_lat() work on it. `dem_step` uses every Nth cell;
        `barrier_below` leaves out cells lower than that many metres (the sea at 0)."""
        if isinstance(source, tuple):
            data, file_name = _off_text(*source), file_name or "arrays.off"
        elif isinstance(source, (bytes, bytearray, memoryview)):
            if not file_name:
                raise InvalidArgumentError(grpc.StatusCode.INVALID_ARGUMENT,
                                           "upload(bytes): give file_name (its extension names "
                                           "the format, e.g. 'mesh.off')", field="file_name")
            data = bytes(source)
        else:
            path = os.fspath(source)
            with open(path, "rb") as f:
                data = f.read()
            file_name = file_name or os.path.basename(path)
        dem = None
        if file_name.lower().endswith((".tif", ".tiff")) or dem_step or barrier_below is not None:
            dem = pb.DemOptions(step=dem_step or 0)
            if barrier_below is not None:
                dem.barrier_below = barrier_below
        mesh = self._upload_bytes(data, file_name, name, pin, dem, timeout)
        for key in [mesh.name] + (["meshes/" + name] if name else []):
            self._uploads[key] = (data, file_name, dem)
        return mesh

    def get_mesh(self, mesh: str, timeout: Optional[float] = None) -> Mesh:
        """The mesh ("meshes/{id}" or "meshes/{name}")."""
        return Mesh.from_proto(self._unary(self.stub.GetMesh, pb.GetMeshRequest(name=mesh), mesh,
                                           timeout))

    def list_meshes(self, timeout: Optional[float] = None) -> List[Mesh]:
        """Every stored mesh (all pages)."""
        meshes, token = [], ""
        while True:
            response = self._unary(self.stub.ListMeshes, pb.ListMeshesRequest(page_token=token),
                                   timeout=timeout)
            meshes.extend(Mesh.from_proto(m) for m in response.meshes)
            token = response.next_page_token
            if not token:
                return meshes

    def derive_mesh(self, mesh: str, below: Optional[float] = None,
                    polygons_geojson: Union[str, dict] = "", name: str = "", pin: bool = False,
                    width: float = 0.0, timeout: Optional[float] = None) -> Mesh:
        """The stored mesh without what a barrier covers, stored by the server (by its content's
        id); returns its Mesh. `below`: faces with a corner lower than this z go (the sea at 0 on
        a DEM's mesh); `polygons_geojson`: the text (or a dict) of GeoJSON polygons, cut exactly
        out of the surface (WGS 84 on a DEM's mesh, the mesh's x y otherwise); lines in it are
        slits (paths go around their ends), or with `width` (metres) walls that wide, as are its
        points."""
        if not isinstance(polygons_geojson, str):
            import json
            polygons_geojson = json.dumps(polygons_geojson)
        barrier = pb.Barrier(polygons_geojson=polygons_geojson, width=width)
        if below is not None:
            barrier.below = below
        return Mesh.from_proto(self._unary(self.stub.DeriveMesh, pb.DeriveMeshRequest(
            mesh=mesh, barrier=barrier, display_name=name, pin=pin), mesh, timeout))

    def export_gis(self, mesh: str, product: str, sources: Sequence, points: Sequence = (),
                   levels: Sequence[float] = (), count: int = 0, native_crs: bool = False,
                   timeout: Optional[float] = None, **options) -> bytes:
        """A GIS file of a DEM's mesh, as the CLI writes it with --output FILE.geojson / FILE.tif:
        its bytes. `product`: "isochrones" (levels or count), "voronoi", "delaunay", "path"
        (sources[0] to points[0]), "points" (distances at `points`), "distance_raster",
        "label_raster"; GeoJSON is RFC 7946 unless `native_crs`."""
        request = pb.ExportGisRequest(
            mesh=mesh, product=_enum_value(pb.GisProduct, "GIS_PRODUCT_", product, "product"),
            sources=sources, points=points, levels=levels, count=count, native_crs=native_crs,
            options=_solver_options(options))
        return self._stream(self.stub.ExportGis, request, mesh, timeout,
                            lambda stream: b"".join(m.data for m in stream))

    def delete_mesh(self, mesh: str, timeout: Optional[float] = None) -> None:
        self._unary(self.stub.DeleteMesh, pb.DeleteMeshRequest(name=mesh), mesh, timeout)
        self._uploads.pop(mesh, None)

    # --- queries ---

    def distance_field(self, mesh: str, sources: Sequence, want_stats: bool = False,
                       want_directions: bool = False, timeout: Optional[float] = None,
                       **options) -> Field:
        """Field(distances, labels, stats, directions) for every vertex, as numpy arrays read
        from the streamed chunks. `options`: SolverOptions fields (lambda_, lambda_scale,
        max_distance)."""
        request = pb.ComputeDistanceFieldRequest(
            mesh=mesh, sources=sources, options=_solver_options(options), want_stats=want_stats,
            want_directions=want_directions)

        def consume(stream):
            distances, labels, directions, stats = [], [], [], None
            for raw in stream:
                arrays, rest = _split_packed(raw, {3: "<f8", 5: "<u4", 8: "<f8"})
                head = pb.ComputeDistanceFieldResponse.FromString(rest)
                if head.offset != sum(len(d) for d in distances):
                    raise InvalidArgumentError(None, "the field's chunks arrived out of order")
                distances.append(arrays[3])
                labels.append(arrays[5])
                directions.append(arrays[8])
                if head.HasField("stats"):
                    stats = head.stats
            return Field(np.concatenate(distances) if distances else np.zeros(0),
                         np.concatenate(labels) if labels else np.zeros(0, "<u4"), stats,
                         (np.concatenate(directions) if directions else np.zeros(0)).reshape(-1, 3))
        return self._stream(self._raw_field, request, mesh, timeout, consume)

    def shortest_path(self, mesh: str, start, end, want_stats: bool = False,
                      timeout: Optional[float] = None, **options) -> Path:
        """The exact shortest path: Path(length, [PathPoint(position, simplex), ...]), with the
        solve's stats when `want_stats`. An unreachable end raises UnreachableError."""
        response = self._unary(self.stub.FindShortestPath, pb.FindShortestPathRequest(
            mesh=mesh, to=end, options=_solver_options(options), want_stats=want_stats,
            **{"from": start}), mesh, timeout)
        return Path(response.distance, _path_points(response.points),
                    response.stats if response.HasField("stats") else None)

    def shortest_paths(self, mesh: str, pairs: Sequence[Tuple[Any, Any]],
                       timeout: Optional[float] = None, **options) -> List[Path]:
        """Many exact shortest paths in one call, [(start, end), ...] -> [Path, ...]; pairs from
        the same start share one solve. An unreachable end gives Path(inf, [])."""
        request = pb.FindShortestPathsRequest(
            mesh=mesh, pairs=[pb.ShortestPathPair(to=end, **{"from": start}) for start, end in pairs],
            options=_solver_options(options))
        response = self._unary(self.stub.FindShortestPaths, request, mesh, timeout)
        return [Path(p.distance, _path_points(p.points)) for p in response.paths]

    def distance_matrix(self, mesh: str, sources: Sequence, targets: Sequence, k_nearest: int = 0,
                        on_progress: Optional[Callable[[int, int, float], None]] = None,
                        timeout: Optional[float] = None, **options) -> np.ndarray:
        """Exact distances as a (sources x targets) float64 array. `k_nearest` keeps only each
        source's k nearest targets (the rest are inf). The server streams rows as they finish:
        `on_progress(rows_received, rows, fraction_solved)`, when given, is called with those
        three arguments for every message that carries rows."""
        request = pb.ComputeDistanceMatrixRequest(
            mesh=mesh, sources=sources, targets=targets, k_nearest=k_nearest,
            options=_solver_options(options))

        def consume(stream):
            values, rows, cols, received = [], 0, 0, 0
            for raw in stream:
                arrays, rest = _split_packed(raw, {4: "<f8"})
                head = pb.ComputeDistanceMatrixResponse.FromString(rest)
                if head.offset != received:
                    raise InvalidArgumentError(None, "the matrix's rows arrived out of order")
                rows, cols = head.rows, head.cols
                values.append(arrays[4])
                received += len(arrays[4])
                if on_progress is not None and cols:
                    on_progress(received // cols, rows, head.progress)
            flat = np.concatenate(values) if values else np.zeros(0)
            return flat.reshape(rows, cols)
        return self._stream(self._raw_matrix, request, mesh, timeout, consume)

    def point_distances(self, mesh: str, sources: Sequence, points: Sequence,
                        want_directions: bool = False, timeout: Optional[float] = None,
                        **options) -> PointDistances:
        """Distances at surface points: PointDistances(estimates, estimate_labels, exact,
        exact_labels, directions): the paper's section-4 estimate from the field, and the exact
        value; with want_directions, each point's unit direction (x, y, z) along its shortest path
        towards its nearest source ((0, 0, 0) at a source, NaN where unreachable)."""
        request = pb.EstimateDistancesRequest(
            mesh=mesh, sources=sources, points=points, mode=pb.POINT_DISTANCE_MODE_BOTH,
            options=_solver_options(options), want_directions=want_directions)
        r = self._unary(self.stub.EstimateDistances, request, mesh, timeout)
        return PointDistances(np.array(r.estimates, dtype=np.float64),
                              np.array(r.estimate_labels, dtype=np.uint32),
                              np.array(r.exact, dtype=np.float64),
                              np.array(r.exact_labels, dtype=np.uint32),
                              np.array(r.exact_directions, dtype=np.float64).reshape(-1, 3))

    def locate(self, mesh: str, positions: Sequence[Tuple[float, float, float]],
               max_snap: Optional[float] = None, timeout: Optional[float] = None) -> List[Located]:
        """The nearest surface point to each (x, y, z): [Located(point, position, distance)]. With
        `max_snap`, a position farther than that from the surface raises InvalidArgumentError
        naming it (field "positions[i]")."""
        request = pb.LocatePointsRequest(
            mesh=mesh, positions=[pb.Position(x=x, y=y, z=z) for x, y, z in positions])
        if max_snap is not None:
            request.max_snap = max_snap
        response = self._unary(self.stub.LocatePoints, request, mesh, timeout)
        return [Located(p.point, (p.position.x, p.position.y, p.position.z), p.distance)
                for p in response.points]

    def isolines(self, mesh: str, sources: Sequence, levels: Optional[Sequence[float]] = None,
                 count: int = 0, timeout: Optional[float] = None, **options) -> Isolines:
        """Approximate isolines of the field of `sources` (paper section 6.1) at `levels`, or at
        `count` - 1 evenly spaced levels: Isolines(levels, [(level, closed, [PathPoint])])."""
        request = pb.ComputeIsolinesRequest(mesh=mesh, sources=sources, levels=levels or [],
                                            count=count, options=_solver_options(options))
        messages = self._stream(self.stub.ComputeIsolines, request, mesh, timeout)
        all_levels, pieces = [], []
        for message in messages:
            all_levels.extend(message.levels)
            pieces.extend(message.isolines)
        return Isolines(all_levels, _reassemble(pieces, lambda p: (p.level, p.closed, [])))

    def voronoi(self, mesh: str, sites: Sequence, timeout: Optional[float] = None,
                **options) -> Voronoi:
        """The approximate Voronoi diagram: Voronoi({site: area}, [(site_a, site_b, [PathPoint])],
        [(a, b)]), with boundaries reassembled from their streamed pieces."""
        request = pb.ComputeVoronoiRequest(mesh=mesh, sources=sites, omit_cell_faces=True,
                                           options=_solver_options(options))
        areas, pieces, adjacency = {}, [], []
        for message in self._stream(self.stub.ComputeVoronoi, request, mesh, timeout):
            for cell in message.cells:
                areas[cell.site] = cell.area
            pieces.extend(message.boundaries)
            adjacency.extend((pair.a, pair.b) for pair in message.adjacency)
        return Voronoi(areas, _reassemble(pieces, lambda p: (p.site_a, p.site_b, [])), adjacency)

    def delaunay(self, mesh: str, sites: Sequence, timeout: Optional[float] = None,
                 **options) -> Delaunay:
        """The approximate Delaunay triangulation (paper sections 6.3-6.4):
        Delaunay([(site_a, site_b, length, [PathPoint])], [(a, b, c)])."""
        request = pb.ComputeDelaunayRequest(mesh=mesh, sources=sites,
                                            options=_solver_options(options))
        pieces, triangles = [], []
        for message in self._stream(self.stub.ComputeDelaunay, request, mesh, timeout):
            pieces.extend(message.edges)
            triangles.extend((t.a, t.b, t.c) for t in message.triangles)
        edges = _reassemble(pieces, lambda p: (p.site_a, p.site_b, p.length, []))
        return Delaunay(edges, triangles)


__all__ = ["GeodexClient", "RetryPolicy", "Mesh", "Field", "Path", "PathPoint", "Located",
           "PointDistances", "Isolines", "Voronoi", "Delaunay", "vertex", "edge_point",
           "face_point", "position", "map_point", "lon_lat"]
