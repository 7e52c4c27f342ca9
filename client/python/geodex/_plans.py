"""Every method of the API, once, as a plan: a generator that builds the requests, yields each
call as an `Rpc`, receives its answer and returns the result. `GeodexClient` runs a plan blocking,
`AsyncGeodexClient` awaits it; both run the same policy (`Policy`: one deadline per call,
retries, re-upload), so the two clients cannot drift apart.
"""
import dataclasses
import functools
import json
import os
import sys
import time
import warnings
from typing import (Any, Callable, Dict, Generator, List, Optional, Sequence, Tuple, TypeVar,
                    Union)

import grpc
import numpy as np

from . import _wire
from .errors import DeadlineExceededError, from_rpc_error
from .results import (Delaunay, DistanceMatrix, Field, GisFile, Isolines, Located, Mesh, Path,
                      PointDistances, RetryPolicy, Travel, Voronoi)
from .v1 import geodex_pb2 as pb

CHUNK_BYTES = 1 << 20
# A position snapped farther than this fraction of the mesh's diagonal gets a warning (the CLI's).
SNAP_WARN_FRACTION = 0.01

MeshSource = Union[str, "os.PathLike[str]", bytes, Tuple[Any, Any]]
T = TypeVar("T")
Plan = Generator["Rpc", Any, T]


def mesh_name(mesh):
    """A mesh as the API names it: "kitten" (an alias or an id, as the CLI takes it) is
    "meshes/kitten"; "meshes/kitten" stays."""
    if isinstance(mesh, str) and mesh and not mesh.startswith("meshes/"):
        return "meshes/" + mesh
    return mesh


def _bare_mesh_names(plan_method):
    """`plan_method` taking its `mesh` argument (the first) bare or as a resource name."""
    if "mesh" not in plan_method.__code__.co_varnames[1:2]:
        return plan_method

    @functools.wraps(plan_method)
    def named(self, *args, **kwargs):
        if args:
            args = (mesh_name(args[0]),) + args[1:]
        elif "mesh" in kwargs:
            kwargs["mesh"] = mesh_name(kwargs["mesh"])
        return plan_method(self, *args, **kwargs)
    return named


def answered(plan_method, method):
    """`method` (a client's wrapper of `plan_method`) annotated with what it returns: the plan's
    result type (Path), not the generator a plan is (help() and type checkers read this)."""
    annotations = dict(getattr(plan_method, "__annotations__", {}))
    returned = annotations.get("return")
    args = getattr(returned, "__args__", None)
    if args and len(args) == 3:
        annotations["return"] = args[2]
    method.__annotations__ = annotations
    return method


class SnapWarning(UserWarning):
    """A position was snapped more than 1% of the mesh's diagonal onto the surface (pass
    `max_snap=` to refuse such points instead)."""


@dataclasses.dataclass
class Rpc:
    """One call of a plan. `method`: a geodex.v1.Geodex method name, or a full path. `request`: a
    message, or for a client stream a function returning an iterator of messages. `response`: the
    message class, or None for the raw bytes. `stream`: the answer is the list of messages.
    `on_message`: called with each streamed message as it arrives."""
    method: str
    request: Any
    response: Optional[type]
    stream: bool = False
    client_stream: bool = False
    mesh: Optional[str] = None
    on_message: Optional[Callable[[Any], None]] = None

    @property
    def path(self) -> str:
        return self.method if self.method.startswith("/") else "/geodex.v1.Geodex/" + self.method


def credentials(token: Optional[str], root_pem: Optional[bytes]):
    """TLS credentials (with a bearer token) for a secure channel, or None for an insecure one."""
    if root_pem is None and token is None:
        return None
    out = grpc.ssl_channel_credentials(root_certificates=root_pem)
    if token is not None:
        out = grpc.composite_channel_credentials(out, grpc.access_token_call_credentials(token))
    return out


# The channel reconnects soon after a server comes back (gRPC's default waits 1 s, then 1.6 s,
# 2.6 s, ... between attempts: a 0.5 s restart was seen only after 6 s).
CHANNEL_OPTIONS = [("grpc.initial_reconnect_backoff_ms", 100),
                   ("grpc.min_reconnect_backoff_ms", 100),
                   ("grpc.max_reconnect_backoff_ms", 1000)]


def multicallable(channel, cache: Dict[tuple, Any], rpc: "Rpc"):
    """The channel's callable for `rpc` (blocking or grpc.aio alike), made once per kind."""
    key = (rpc.path, rpc.stream, rpc.client_stream, rpc.response)
    found = cache.get(key)
    if found is None:
        kind = (channel.stream_unary if rpc.client_stream else
                channel.unary_stream if rpc.stream else channel.unary_unary)
        found = kind(rpc.path, request_serializer=serializer,
                     response_deserializer=deserializer(rpc.response))
        cache[key] = found
    return found


def mesh_metadata(mesh_name):
    """x-mesh-id for a mesh-affine gateway, when the name is an id."""
    if not mesh_name:
        return ()
    key = mesh_name[len("meshes/"):] if mesh_name.startswith("meshes/") else mesh_name
    if len(key) == 64 and all(c in "0123456789abcdef" for c in key):
        return (("x-mesh-id", key),)
    return ()


class Policy:
    """What a failed attempt leads to: ("retry", seconds to wait), ("reconnect", seconds to wait,
    then wait up to reconnect_left() for the channel to connect), ("reupload", mesh) or ("raise",
    error). UNAVAILABLE is retried while the server may be restarting (RetryPolicy.reconnect_wait)
    and QUEUE_FULL max_attempts times, with backoff, while the deadline leaves room; a mesh this
    client uploaded and the server lost is uploaded again, once."""

    def __init__(self, retry: RetryPolicy, deadline: float, uploads: Dict[str, tuple]):
        self.retry, self.deadline, self.uploads = retry, deadline, uploads
        self.backoff, self.tries, self.reuploaded = retry.initial_backoff, 0, False
        self.retries = self.reuploads = 0
        self.unavailable_since: Optional[float] = None
        self.last_error = None  # the last UNAVAILABLE, raised when the server does not come back

    def reconnect_left(self) -> float:
        """How long a reconnecting retry may wait for the channel: within the deadline and
        reconnect_wait of the first UNAVAILABLE."""
        now = time.monotonic()
        return max(0.0, min(self.deadline - now,
                            self.unavailable_since + self.retry.reconnect_wait - now))

    def seconds_left(self) -> float:
        """Before an attempt: the time it may take, or DeadlineExceededError (the first attempt
        is always made)."""
        self.tries += 1
        left = self.deadline - time.monotonic()
        if left <= 0 and self.tries > 1:
            raise DeadlineExceededError(grpc.StatusCode.DEADLINE_EXCEEDED,
                                        "the call's timeout passed (after %d attempts)" %
                                        (self.tries - 1))
        return max(left, 1e-6)

    def after(self, rpc_error: grpc.RpcError, mesh: Optional[str]):
        error = from_rpc_error(rpc_error)
        error.__cause__ = rpc_error
        code = error.code
        now = time.monotonic()
        if code == grpc.StatusCode.UNAVAILABLE:
            if self.unavailable_since is None:
                self.unavailable_since = now
            self.last_error = error
            wait = min(self.backoff, 1.0)
            if (now + wait < self.unavailable_since + self.retry.reconnect_wait
                    and self.deadline - now > wait):
                self.backoff *= self.retry.multiplier
                self.retries += 1
                return "reconnect", wait
            return "raise", error
        retryable = (self.retry.retry_queue_full and code == grpc.StatusCode.RESOURCE_EXHAUSTED
                     and error.reason == "QUEUE_FULL")
        if (retryable and self.tries < self.retry.max_attempts
                and self.deadline - now > self.backoff):
            wait = self.backoff
            self.backoff *= self.retry.multiplier
            self.retries += 1
            return "retry", wait
        if (code == grpc.StatusCode.NOT_FOUND and error.reason == "MESH_NOT_FOUND"
                and not self.reuploaded and mesh in self.uploads):
            self.reuploaded = True
            self.reuploads += 1
            return "reupload", mesh
        return "raise", error


def _snaps(response) -> np.ndarray:
    return np.array(response.snap_distances, dtype=np.float64)


def _stacklevel() -> int:
    """warnings.warn's stacklevel that names the first caller outside this package (the user's
    line, whichever client and however deep the plan)."""
    package = os.path.dirname(os.path.abspath(__file__))
    frame, level = sys._getframe(1), 1
    while frame is not None and os.path.dirname(os.path.abspath(frame.f_code.co_filename)) == package:
        frame, level = frame.f_back, level + 1
    return level


def _metres_and_seconds(path, travel_epsilon):
    """(length_m, time_s) of a FindShortestPathResponse: metres always, seconds with a travel cost."""
    travel = travel_epsilon > 0
    return (path.length_m if (path.length_m > 0 or travel) else path.distance,
            path.distance if travel else None)


def _point_names(*groups) -> List[str]:
    """Request-order names of points: ("sources", 2), ("to", None) -> sources[0], sources[1], to."""
    names = []
    for name, count in groups:
        names += [name] if count is None else ["%s[%d]" % (name, i) for i in range(count)]
    return names


class Plans:
    """The API. Each public method documented here is a plan; the clients turn every plan into a
    method of the same name and signature (`timeout=` bounds the whole call, retries included;
    `max_snap=` refuses positions farther than that from the surface, checked by the server;
    `travel=` (a geodex.Travel) on every query with solver options answers in travel-time
    seconds within the result's `travel_epsilon`)."""

    _PLANS = ("health", "upload", "get_mesh", "list_meshes", "derive_mesh", "delete_mesh",
              "export_gis", "distance_field", "shortest_path", "shortest_paths",
              "distance_matrix", "point_distances", "locate", "isolines", "voronoi", "delaunay")

    def __init__(self, timeout: float, retry: Optional[RetryPolicy], wait_for_ready: bool,
                 max_snap: Optional[float]):
        self.timeout = timeout
        self.retry = retry or RetryPolicy()
        self.wait_for_ready = wait_for_ready
        self.max_snap = max_snap
        self.retries = 0    # attempts made again (UNAVAILABLE, a full queue)
        self.reuploads = 0  # meshes uploaded again after the server lost them
        # What this client uploaded, to upload it again: name -> (bytes, file name, DemOptions).
        self._uploads: Dict[str, tuple] = {}
        self._diagonals: Dict[str, float] = {}  # mesh name -> bounding-box diagonal

    @classmethod
    def _make_methods(cls, wrap):
        for name in cls._PLANS:
            setattr(cls, name, wrap(_bare_mesh_names(getattr(Plans, name))))

    def _policy(self, timeout: Optional[float]) -> Policy:
        return Policy(self.retry, time.monotonic() + (self.timeout if timeout is None else timeout),
                      self._uploads)

    def _note(self, policy: Policy):
        self.retries += policy.retries
        self.reuploads += policy.reuploads

    # --- shared pieces of plans ---

    def _max_snap(self, request, max_snap):
        limit = self.max_snap if max_snap is None else max_snap
        if limit is not None:
            request.max_snap = limit
        return request

    def _warn_far_snaps(self, mesh: str, snaps: np.ndarray, names: List[str]) -> Plan[None]:
        """warnings.warn (SnapWarning) for each point snapped beyond 1% of the diagonal."""
        if not len(snaps) or float(np.max(snaps)) <= 0:
            return
        if mesh not in self._diagonals:
            m = yield Rpc("GetMesh", pb.GetMeshRequest(name=mesh), pb.Mesh, mesh=mesh)
            self._diagonals[mesh] = Mesh.from_proto(m).diagonal
        limit = SNAP_WARN_FRACTION * self._diagonals[mesh]
        for name, d in zip(names, snaps.tolist()):
            if d > limit:
                warnings.warn("%s is %.6g from the surface of %s (over 1%% of its diagonal); "
                              "snapped (max_snap= refuses such points)" % (name, d, mesh),
                              SnapWarning, stacklevel=_stacklevel())

    def _upload_rpc(self, data, file_name, name, pin, dem) -> Plan[Mesh]:
        def requests():
            meta = pb.CreateMeshMetadata(file_name=file_name, display_name=name, pin=pin,
                                         total_bytes=len(data))
            if dem is not None:
                meta.format = pb.MESH_FORMAT_GEOTIFF
                meta.dem.CopyFrom(dem)
            yield pb.CreateMeshRequest(metadata=meta)
            for offset in range(0, len(data), CHUNK_BYTES):
                yield pb.CreateMeshRequest(chunk=data[offset:offset + CHUNK_BYTES])
        resource = yield Rpc("CreateMesh", requests, pb.Mesh, client_stream=True)
        return Mesh.from_proto(resource)

    def _reupload(self, mesh: str) -> Plan[Mesh]:
        data, file_name, dem = self._uploads[mesh]
        return (yield from self._upload_rpc(data, file_name, "", False, dem))

    # --- meshes ---

    def health(self, timeout: Optional[float] = None) -> Plan[bool]:
        """True when the server says SERVING."""
        # grpc.health.v1 without its generated module: HealthCheckRequest{} is empty bytes and
        # HealthCheckResponse{status: SERVING} is 08 01.
        answer = yield Rpc("/grpc.health.v1.Health/Check", b"", None)
        return answer == b"\x08\x01"

    def upload(self, source: MeshSource, name: str = "", pin: bool = False,
               dem_step: Optional[int] = None, barrier_below: Optional[float] = None,
               z_tolerance: float = 0.0, file_name: Optional[str] = None,
               timeout: Optional[float] = None) -> Plan[Mesh]:
        """Uploads a mesh in 1 MiB chunks (idempotent: by content hash) and returns its `Mesh`.

        `source`: a file path; the file's bytes (give `file_name`, whose extension names the
        format: "mesh.off", "mesh.ply.gz", "dem.tif"); or a `(vertices, faces)` pair of arrays
        (n x 3 coordinates, m x 3 vertex ids), sent as float64 OFF text, so its mesh id equals
        that of a file with the same values. `name` gives it an alias.

        A GeoTIFF (.tif, .tiff) is a DEM: geodexd makes it a mesh in metres and keeps its map
        (Mesh.terrain), so map_point() and lon_lat() work on it. `dem_step` uses every Nth cell;
        `barrier_below` leaves out cells lower than that many metres (the sea at 0);
        `z_tolerance` > 0 makes it an adaptive TIN within that height of every cell (the CLI's
        --z-tolerance; Mesh.terrain then reports max_vertical_deviation)."""
        if isinstance(source, tuple):
            # Named as what the user passed (server messages echo it), not a file they never wrote.
            data, file_name = _wire.off_text(*source), file_name or "(vertices, faces).off"
        elif isinstance(source, (bytes, bytearray, memoryview)):
            if not file_name:
                raise _wire.invalid("upload(bytes): give file_name (its extension names the "
                                    "format, e.g. 'mesh.off')", "file_name")
            data = bytes(source)
        else:
            path = os.fspath(source)
            with open(path, "rb") as f:
                data = f.read()
            file_name = file_name or os.path.basename(path)
        dem = None
        if (file_name.lower().endswith((".tif", ".tiff")) or dem_step or barrier_below is not None
                or z_tolerance):
            dem = pb.DemOptions(step=dem_step or 0, z_tolerance=z_tolerance)
            if barrier_below is not None:
                dem.barrier_below = barrier_below
        mesh = yield from self._upload_rpc(data, file_name, name, pin, dem)
        for key in [mesh.name] + (["meshes/" + name] if name else []):
            self._uploads[key] = (data, file_name, dem)
            self._diagonals[key] = mesh.diagonal
        return mesh

    def get_mesh(self, mesh: str, timeout: Optional[float] = None) -> Plan[Mesh]:
        """The mesh ("meshes/{id}" or "meshes/{name}")."""
        resource = yield Rpc("GetMesh", pb.GetMeshRequest(name=mesh), pb.Mesh, mesh=mesh)
        return Mesh.from_proto(resource)

    def list_meshes(self, timeout: Optional[float] = None) -> Plan[List[Mesh]]:
        """Every stored mesh (all pages)."""
        meshes, token = [], ""
        while True:
            response = yield Rpc("ListMeshes", pb.ListMeshesRequest(page_token=token),
                                 pb.ListMeshesResponse)
            meshes.extend(Mesh.from_proto(m) for m in response.meshes)
            token = response.next_page_token
            if not token:
                return meshes

    def derive_mesh(self, mesh: str, below: Optional[float] = None,
                    polygons_geojson: Union[str, dict] = "", name: str = "", pin: bool = False,
                    width: float = 0.0, timeout: Optional[float] = None,
                    friction_geojson: Union[str, dict] = "") -> Plan[Mesh]:
        """The stored mesh without what a barrier covers, stored by the server (by its content's
        id); returns its Mesh. `below`: faces with a corner lower than this z go (the sea at 0 on
        a DEM's mesh); `polygons_geojson`: the text (or a dict) of GeoJSON polygons, cut exactly
        out of the surface (WGS 84 on a DEM's mesh, the mesh's x y otherwise); lines in it are
        slits (paths go around their ends), or with `width` (metres) walls that wide, as are its
        points. `friction_geojson`: friction polygons (as Travel's) whose outlines are cut in,
        nothing removed: travel on the derived mesh with the same polygons has exact regions."""
        if not isinstance(polygons_geojson, str):
            polygons_geojson = json.dumps(polygons_geojson)
        if not isinstance(friction_geojson, str):
            friction_geojson = json.dumps(friction_geojson)
        barrier = pb.Barrier(polygons_geojson=polygons_geojson, width=width)
        if below is not None:
            barrier.below = below
        resource = yield Rpc("DeriveMesh", pb.DeriveMeshRequest(
            mesh=mesh, barrier=barrier, display_name=name, pin=pin,
            friction_geojson=friction_geojson), pb.Mesh, mesh=mesh)
        return Mesh.from_proto(resource)

    def delete_mesh(self, mesh: str, timeout: Optional[float] = None) -> Plan[None]:
        """Deletes the mesh (its aliases with it)."""
        yield Rpc("DeleteMesh", pb.DeleteMeshRequest(name=mesh), None, mesh=mesh)
        self._uploads.pop(mesh, None)

    def export_gis(self, mesh: str, product: str, sources: Sequence, points: Sequence = (),
                   levels: Sequence[float] = (), count: int = 0, native_crs: bool = False,
                   max_snap: Optional[float] = None, timeout: Optional[float] = None,
                   travel: Optional[Travel] = None, **options) -> Plan[GisFile]:
        """A GIS file of a DEM's mesh, as the CLI writes it with --output FILE.geojson / FILE.tif:
        its bytes (a GisFile: bytes with `media_type` and `snap_distances`). `product`:
        "isochrones" (levels or count), "voronoi", "delaunay", "path" (sources[0] to points[0]),
        "points" (distances at `points`), "distance_raster", "label_raster"; GeoJSON is RFC 7946
        unless `native_crs`."""
        request = self._max_snap(pb.ExportGisRequest(
            mesh=mesh, product=_wire.enum_value(pb.GisProduct, "GIS_PRODUCT_", product, "product"),
            sources=sources, points=points, levels=levels, count=count, native_crs=native_crs,
            options=_wire.solver_options(options, travel)), max_snap)
        messages = yield Rpc("ExportGis", request, pb.ExportGisResponse, stream=True, mesh=mesh)
        out = GisFile(b"".join(m.data for m in messages))
        out.media_type = messages[0].media_type if messages else ""
        out.snap_distances = _snaps(messages[0]) if messages else np.zeros(0)
        out.travel_epsilon = messages[0].travel_epsilon if messages else 0.0
        out.travel_exact = messages[0].travel_exact if messages else False
        yield from self._warn_far_snaps(mesh, out.snap_distances,
                                        _point_names(("sources", len(sources)),
                                                     ("points", len(points))))
        return out

    # --- queries ---

    def distance_field(self, mesh: str, sources: Sequence, want_stats: bool = False,
                       want_directions: bool = False, max_snap: Optional[float] = None,
                       timeout: Optional[float] = None, travel: Optional[Travel] = None,
                       **options) -> Plan[Field]:
        """Field(distances, labels, stats, directions) for every vertex, as numpy arrays read
        from the streamed chunks (`snap_distances`: one per source). `options`: SolverOptions
        fields (lambda_, lambda_scale, max_distance)."""
        request = self._max_snap(pb.ComputeDistanceFieldRequest(
            mesh=mesh, sources=sources, options=_wire.solver_options(options, travel),
            want_stats=want_stats, want_directions=want_directions), max_snap)
        raws = yield Rpc("ComputeDistanceField", request, None, stream=True, mesh=mesh)
        distances, labels, directions, stats, snaps = [], [], [], None, np.zeros(0)
        travel_epsilon, travel_exact = 0.0, False
        for k, raw in enumerate(raws):
            arrays, rest = _wire.split_packed(raw, {3: "<f8", 5: "<u4", 8: "<f8", 9: "<f8"})
            head = pb.ComputeDistanceFieldResponse.FromString(rest)
            if head.offset != sum(len(d) for d in distances):
                raise _wire.invalid("the field's chunks arrived out of order", "")
            distances.append(arrays[3])
            labels.append(arrays[5])
            directions.append(arrays[8])
            if k == 0:
                snaps = arrays[9]
                travel_epsilon, travel_exact = head.travel_epsilon, head.travel_exact
            if head.HasField("stats"):
                stats = head.stats
        yield from self._warn_far_snaps(mesh, snaps, _point_names(("sources", len(sources))))
        return Field(np.concatenate(distances) if distances else np.zeros(0),
                     np.concatenate(labels) if labels else np.zeros(0, "<u4"), stats,
                     (np.concatenate(directions) if directions else np.zeros(0)).reshape(-1, 3),
                     snaps, travel_epsilon, travel_exact)

    def shortest_path(self, mesh: str, start, end, want_stats: bool = False,
                      max_snap: Optional[float] = None, timeout: Optional[float] = None,
                      travel: Optional[Travel] = None, **options) -> Plan[Path]:
        """The exact shortest path: Path(length, [PathPoint(position, simplex), ...]), with the
        solve's stats when `want_stats` and the snap distances of (start, end). An unreachable
        end raises UnreachableError."""
        request = self._max_snap(pb.FindShortestPathRequest(
            mesh=mesh, to=end, options=_wire.solver_options(options, travel), want_stats=want_stats,
            **{"from": start}), max_snap)
        response = yield Rpc("FindShortestPath", request, pb.FindShortestPathResponse, mesh=mesh)
        path = Path(response.distance, _wire.path_points(response.points),
                    response.stats if response.HasField("stats") else None, _snaps(response),
                    response.travel_epsilon, *_metres_and_seconds(response, response.travel_epsilon),
                    response.travel_exact)
        yield from self._warn_far_snaps(mesh, path.snap_distances, ["start", "end"])
        return path

    def shortest_paths(self, mesh: str, pairs: Sequence[Tuple[Any, Any]],
                       max_snap: Optional[float] = None, timeout: Optional[float] = None,
                       travel: Optional[Travel] = None, **options) -> Plan[List[Path]]:
        """Many exact shortest paths in one call, [(start, end), ...] -> [Path, ...]; pairs from
        the same start share one solve. An unreachable end gives Path(inf, [])."""
        request = self._max_snap(pb.FindShortestPathsRequest(
            mesh=mesh, pairs=[pb.ShortestPathPair(to=end, **{"from": start})
                              for start, end in pairs],
            options=_wire.solver_options(options, travel)), max_snap)
        response = yield Rpc("FindShortestPaths", request, pb.FindShortestPathsResponse,
                             mesh=mesh)
        paths = [Path(p.distance, _wire.path_points(p.points), None, _snaps(p),
                      response.travel_epsilon, *_metres_and_seconds(p, response.travel_epsilon),
                      response.travel_exact)
                 for p in response.paths]
        names = ["pairs[%d].%s" % (i, end) for i in range(len(paths)) for end in ("from", "to")]
        all_snaps = (np.concatenate([p.snap_distances for p in paths]) if paths
                     else np.zeros(0))
        yield from self._warn_far_snaps(mesh, all_snaps, names)
        return paths

    def distance_matrix(self, mesh: str, sources: Sequence, targets: Sequence, k_nearest: int = 0,
                        on_progress: Optional[Callable[[int, int, float], None]] = None,
                        max_snap: Optional[float] = None, timeout: Optional[float] = None,
                        travel: Optional[Travel] = None, **options) -> Plan[DistanceMatrix]:
        """Exact distances as a (sources x targets) float64 array (a DistanceMatrix: a numpy
        array with `snap_distances`, the sources' then the targets'). `k_nearest` keeps only each
        source's k nearest targets (the rest are inf). The server streams rows as they finish:
        `on_progress(rows_received, rows, fraction_solved)`, when given, is called with those
        three arguments as each message arrives (rows_received rows of `rows` are in; the server
        has solved `fraction_solved` of the matrix)."""
        request = self._max_snap(pb.ComputeDistanceMatrixRequest(
            mesh=mesh, sources=sources, targets=targets, k_nearest=k_nearest,
            options=_wire.solver_options(options, travel)), max_snap)
        state = {"values": [], "rows": 0, "cols": 0, "received": 0, "snaps": np.zeros(0),
                 "travel_epsilon": 0.0, "travel_exact": False}

        def on_message(raw):
            arrays, rest = _wire.split_packed(raw, {4: "<f8", 8: "<f8"})
            head = pb.ComputeDistanceMatrixResponse.FromString(rest)
            if head.offset == 0 and not state["values"]:
                state["snaps"] = arrays[8]
                state["travel_epsilon"] = head.travel_epsilon
                state["travel_exact"] = head.travel_exact
            if head.offset != state["received"]:
                raise _wire.invalid("the matrix's rows arrived out of order", "")
            state["rows"], state["cols"] = head.rows, head.cols
            state["values"].append(arrays[4])
            state["received"] += len(arrays[4])
            if on_progress is not None and head.cols:
                on_progress(state["received"] // head.cols, head.rows, head.progress)

        def restart():  # a retried stream starts over
            state.update(values=[], received=0)

        yield Rpc("ComputeDistanceMatrix", request, None, stream=True, mesh=mesh,
                  on_message=_Restartable(on_message, restart))
        flat = np.concatenate(state["values"]) if state["values"] else np.zeros(0)
        matrix = flat.reshape(state["rows"], state["cols"]).view(DistanceMatrix)
        matrix.snap_distances = state["snaps"]
        matrix.travel_epsilon = state["travel_epsilon"]
        matrix.travel_exact = state["travel_exact"]
        yield from self._warn_far_snaps(mesh, matrix.snap_distances,
                                        _point_names(("sources", len(sources)),
                                                     ("targets", len(targets))))
        return matrix

    def point_distances(self, mesh: str, sources: Sequence, points: Sequence,
                        want_directions: bool = False, max_snap: Optional[float] = None,
                        timeout: Optional[float] = None, travel: Optional[Travel] = None,
                        **options) -> Plan[PointDistances]:
        """Distances at surface points: PointDistances(estimates, estimate_labels, exact,
        exact_labels, directions): the paper's section-4 estimate from the field, and the exact
        value; with want_directions, each point's unit direction (x, y, z) along its shortest path
        towards its nearest source ((0, 0, 0) at a source, NaN where unreachable). With `travel`,
        the exact travel times only (the unfolding estimate is of metres: `estimates` empty)."""
        mode = pb.POINT_DISTANCE_MODE_BOTH if travel is None else pb.POINT_DISTANCE_MODE_EXACT
        request = self._max_snap(pb.EstimateDistancesRequest(
            mesh=mesh, sources=sources, points=points, mode=mode,
            options=_wire.solver_options(options, travel), want_directions=want_directions),
            max_snap)
        r = yield Rpc("EstimateDistances", request, pb.EstimateDistancesResponse, mesh=mesh)
        out = PointDistances(np.array(r.estimates, dtype=np.float64),
                             np.array(r.estimate_labels, dtype=np.uint32),
                             np.array(r.exact, dtype=np.float64),
                             np.array(r.exact_labels, dtype=np.uint32),
                             np.array(r.exact_directions, dtype=np.float64).reshape(-1, 3),
                             _snaps(r), r.travel_epsilon, r.travel_exact)
        yield from self._warn_far_snaps(mesh, out.snap_distances,
                                        _point_names(("sources", len(sources)),
                                                     ("points", len(points))))
        return out

    def locate(self, mesh: str, positions: Sequence[Tuple[float, float, float]],
               max_snap: Optional[float] = None,
               timeout: Optional[float] = None) -> Plan[List[Located]]:
        """The nearest surface point to each (x, y, z): [Located(point, position, distance)]. With
        `max_snap`, a position farther than that from the surface raises InvalidArgumentError
        naming it (field "positions[i]")."""
        request = self._max_snap(pb.LocatePointsRequest(
            mesh=mesh, positions=[pb.Position(x=x, y=y, z=z) for x, y, z in positions]), max_snap)
        response = yield Rpc("LocatePoints", request, pb.LocatePointsResponse, mesh=mesh)
        return [Located(p.point, (p.position.x, p.position.y, p.position.z), p.distance)
                for p in response.points]

    def isolines(self, mesh: str, sources: Sequence, levels: Optional[Sequence[float]] = None,
                 count: int = 0, max_snap: Optional[float] = None,
                 timeout: Optional[float] = None, travel: Optional[Travel] = None,
                 **options) -> Plan[Isolines]:
        """Approximate isolines of the field of `sources` (paper section 6.1) at `levels`, or at
        `count` - 1 evenly spaced levels: Isolines(levels, [(level, closed, [PathPoint])])."""
        request = self._max_snap(pb.ComputeIsolinesRequest(
            mesh=mesh, sources=sources, levels=levels or [], count=count,
            options=_wire.solver_options(options, travel)), max_snap)
        messages = yield Rpc("ComputeIsolines", request, pb.ComputeIsolinesResponse, stream=True,
                             mesh=mesh)
        all_levels, pieces = [], []
        for message in messages:
            all_levels.extend(message.levels)
            pieces.extend(message.isolines)
        snaps = _snaps(messages[0]) if messages else np.zeros(0)
        yield from self._warn_far_snaps(mesh, snaps, _point_names(("sources", len(sources))))
        return Isolines(all_levels, _wire.reassemble(pieces, lambda p: (p.level, p.closed, [])),
                        snaps, messages[0].travel_epsilon if messages else 0.0,
                        messages[0].travel_exact if messages else False)

    def voronoi(self, mesh: str, sites: Sequence, max_snap: Optional[float] = None,
                timeout: Optional[float] = None, travel: Optional[Travel] = None,
                **options) -> Plan[Voronoi]:
        """The approximate Voronoi diagram: Voronoi({site: area}, [(site_a, site_b, [PathPoint])],
        [(a, b)]), with boundaries reassembled from their streamed pieces."""
        request = self._max_snap(pb.ComputeVoronoiRequest(
            mesh=mesh, sources=sites, omit_cell_faces=True,
            options=_wire.solver_options(options, travel)), max_snap)
        messages = yield Rpc("ComputeVoronoi", request, pb.ComputeVoronoiResponse, stream=True,
                             mesh=mesh)
        areas, pieces, adjacency = {}, [], []
        for message in messages:
            for cell in message.cells:
                areas[cell.site] = cell.area
            pieces.extend(message.boundaries)
            adjacency.extend((pair.a, pair.b) for pair in message.adjacency)
        snaps = _snaps(messages[0]) if messages else np.zeros(0)
        yield from self._warn_far_snaps(mesh, snaps, _point_names(("sites", len(sites))))
        return Voronoi(areas, _wire.reassemble(pieces, lambda p: (p.site_a, p.site_b, [])),
                       adjacency, snaps, messages[0].travel_epsilon if messages else 0.0,
                       messages[0].travel_exact if messages else False)

    def delaunay(self, mesh: str, sites: Sequence, max_snap: Optional[float] = None,
                 timeout: Optional[float] = None, travel: Optional[Travel] = None,
                 **options) -> Plan[Delaunay]:
        """The approximate Delaunay triangulation (paper sections 6.3-6.4):
        Delaunay([(site_a, site_b, length, [PathPoint])], [(a, b, c)]). Exact engine only:
        `travel` is refused (InvalidArgumentError naming options.travel)."""
        request = self._max_snap(pb.ComputeDelaunayRequest(
            mesh=mesh, sources=sites, options=_wire.solver_options(options, travel)), max_snap)
        messages = yield Rpc("ComputeDelaunay", request, pb.ComputeDelaunayResponse, stream=True,
                             mesh=mesh)
        pieces, triangles = [], []
        for message in messages:
            pieces.extend(message.edges)
            triangles.extend((t.a, t.b, t.c) for t in message.triangles)
        snaps = _snaps(messages[0]) if messages else np.zeros(0)
        yield from self._warn_far_snaps(mesh, snaps, _point_names(("sites", len(sites))))
        return Delaunay(_wire.reassemble(pieces, lambda p: (p.site_a, p.site_b, p.length, [])),
                        triangles, snaps)


class _Restartable:
    """An on_message callback whose state a retried stream resets first."""

    def __init__(self, callback, restart):
        self.callback, self.restart = callback, restart

    def __call__(self, message):
        self.callback(message)


def serializer(message) -> bytes:
    return message if isinstance(message, bytes) else message.SerializeToString()


def deserializer(response_type):
    return (lambda b: b) if response_type is None else response_type.FromString
