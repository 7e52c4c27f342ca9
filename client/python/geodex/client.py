"""GeodexClient: blocking calls to geodexd (geodex.v1) over Debian's python3-grpcio.

Every method of the API is here; streamed answers are reassembled; failures raise the typed
exceptions of geodex.errors. Points are geodex.v1 SurfacePoint messages (see vertex(), edge_point(),
face_point(), position(), and on a DEM's mesh map_point(), lon_lat()).
"""
import collections
import functools
import os

import grpc

from .errors import from_rpc_error
from .v1 import geodex_pb2 as pb
from .v1 import geodex_pb2_grpc as pb_grpc

CHUNK_BYTES = 1 << 20


def vertex(v):
    """A vertex as a SurfacePoint."""
    return pb.SurfacePoint(vertex=v)


def edge_point(a, b, t):
    """The point (1 - t) * a + t * b on the edge between vertices a and b."""
    return pb.SurfacePoint(edge=pb.EdgePoint(to=b, t=t, **{"from": a}))


def face_point(face, b0, b1, b2):
    """A point inside a face, by barycentric coordinates in the file's corner order."""
    return pb.SurfacePoint(face=pb.FacePoint(face=face, b0=b0, b1=b1, b2=b2))


def position(x, y, z):
    """A 3D position, snapped to the surface by the server."""
    return pb.SurfacePoint(position=pb.Position(x=x, y=y, z=z))


def map_point(x, y):
    """On a DEM's mesh (uploaded as a GeoTIFF): a map point in the raster's CRS, dropped
    vertically onto the surface by the server (the CLI's g:X:Y)."""
    return pb.SurfacePoint(map_point=pb.MapPoint(x=x, y=y))


def lon_lat(lon, lat):
    """On a DEM's mesh: a WGS 84 longitude/latitude in degrees, dropped likewise (ll:LON:LAT)."""
    return pb.SurfacePoint(lon_lat=pb.LonLat(lon=lon, lat=lat))


# A point of a path or polyline: its position (x, y, z) and the simplex it lies on,
# ("v", vertex) / ("e", from, to, t) / ("f", face, b0, b1, b2).
PathPoint = collections.namedtuple("PathPoint", "position simplex")
# A distance field: per vertex the distance (inf where unreachable), the nearest source's index,
# the solve's stats (with want_stats), and with want_directions the geodesic direction field:
# per vertex the unit tangent (x, y, z) towards the nearest source, (0, 0, 0) at a source, NaNs
# where unreachable ([] otherwise).
Field = collections.namedtuple("Field", "distances labels stats directions")
# An exact shortest path: its length and its points (a 2-tuple: `length, points = ...`).
Path = collections.namedtuple("Path", "length points")
# Where a 3D position lands: the surface point (a SurfacePoint), its position, how far it moved.
Located = collections.namedtuple("Located", "point position distance")
# distances at surface points: the unfolding estimate and the exact distance, each with its source;
# with want_directions each point's geodesic direction (x, y, z) towards its nearest source.
PointDistances = collections.namedtuple("PointDistances",
                                        "estimates estimate_labels exact exact_labels directions")
# Approximate isolines (paper section 6.1): the levels and (level, closed, [PathPoint]) lines.
Isolines = collections.namedtuple("Isolines", "levels lines")
# Approximate Voronoi diagram: {site: area}, [(site_a, site_b, [PathPoint])], [(a, b)] adjacency.
Voronoi = collections.namedtuple("Voronoi", "areas boundaries adjacency")
# Approximate Delaunay triangulation: [(site_a, site_b, length, [PathPoint])], [(a, b, c)].
Delaunay = collections.namedtuple("Delaunay", "edges triangles")


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
    """SolverOptions from keyword arguments; lambda is spelled `lambda_` (or options={...})."""
    solver = dict(options.pop("options", {}))
    if "lambda_" in options:
        solver["lambda"] = options.pop("lambda_")
    solver.update(options)
    return pb.SolverOptions(**solver)


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


def _typed_errors(method):
    """Re-raises a grpc.RpcError as the typed GeodexError subclass (geodex.errors)."""
    @functools.wraps(method)
    def wrapper(*args, **kwargs):
        try:
            return method(*args, **kwargs)
        except grpc.RpcError as error:
            raise from_rpc_error(error) from error
    return wrapper


class GeodexClient:
    """Blocking calls with a deadline (`timeout` seconds); mesh-scoped calls carry the mesh id as
    x-mesh-id (for a mesh-affine gateway). `token`: a bearer token (over TLS with `root_pem`)."""

    def __init__(self, target, timeout=600.0, token=None, root_pem=None):
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
        key = mesh_name[len("meshes/"):] if mesh_name.startswith("meshes/") else mesh_name
        if len(key) == 64 and all(c in "0123456789abcdef" for c in key):
            return (("x-mesh-id", key),)
        return ()

    def _call(self, rpc, request, mesh=None):
        return rpc(request, timeout=self.timeout,
                   metadata=self._metadata(mesh) if mesh else ())

    # --- meshes ---

    @_typed_errors
    def health(self):
        """True when the server says SERVING."""
        return self._health(b"", timeout=self.timeout) == b"\x08\x01"

    @_typed_errors
    def upload(self, path, name="", pin=False, dem_step=None, barrier_below=None):
        """Uploads a mesh file in 1 MiB chunks (idempotent); returns the Mesh resource.

        A GeoTIFF (.tif, .tiff) is a DEM: geodexd makes it a mesh in metres and keeps its map
        (Mesh.terrain), so map_point() and lon_lat() work on it. `dem_step` uses every Nth cell;
        `barrier_below` leaves out cells lower than that many metres (the sea at 0)."""
        dem = None
        if path.lower().endswith((".tif", ".tiff")) or dem_step or barrier_below is not None:
            dem = pb.DemOptions(step=dem_step or 0)
            if barrier_below is not None:
                dem.barrier_below = barrier_below

        def requests():
            metadata = pb.CreateMeshMetadata(
                file_name=os.path.basename(path), display_name=name, pin=pin,
                total_bytes=os.path.getsize(path))
            if dem is not None:
                metadata.format = pb.MESH_FORMAT_GEOTIFF
                metadata.dem.CopyFrom(dem)
            yield pb.CreateMeshRequest(metadata=metadata)
            with open(path, "rb") as f:
                while True:
                    chunk = f.read(CHUNK_BYTES)
                    if not chunk:
                        return
                    yield pb.CreateMeshRequest(chunk=chunk)
        return self.stub.CreateMesh(requests(), timeout=self.timeout)

    @_typed_errors
    def get_mesh(self, mesh):
        """The Mesh resource ("meshes/{id}" or "meshes/{name}")."""
        return self._call(self.stub.GetMesh, pb.GetMeshRequest(name=mesh), mesh)

    @_typed_errors
    def list_meshes(self):
        """Every stored Mesh resource (all pages)."""
        meshes, token = [], ""
        while True:
            response = self._call(self.stub.ListMeshes, pb.ListMeshesRequest(page_token=token))
            meshes.extend(response.meshes)
            token = response.next_page_token
            if not token:
                return meshes

    @_typed_errors
    def derive_mesh(self, mesh, below=None, polygons_geojson="", name="", pin=False, width=0.0):
        """The stored mesh without what a barrier covers, stored by the server (by its content's
        id); returns its Mesh resource. `below`: faces with a corner lower than this z go (the
        sea at 0 on a DEM's mesh); `polygons_geojson`: the text (or a dict) of GeoJSON polygons,
        cut exactly out of the surface (WGS 84 on a DEM's mesh, the mesh's x y otherwise);
        lines in it are slits (paths go around their ends), or with `width` (metres) walls that
        wide, as are its points."""
        if not isinstance(polygons_geojson, str):
            import json
            polygons_geojson = json.dumps(polygons_geojson)
        barrier = pb.Barrier(polygons_geojson=polygons_geojson, width=width)
        if below is not None:
            barrier.below = below
        return self._call(self.stub.DeriveMesh, pb.DeriveMeshRequest(
            mesh=mesh, barrier=barrier, display_name=name, pin=pin), mesh)

    @_typed_errors
    def export_gis(self, mesh, product, sources, points=(), levels=(), count=0, native_crs=False,
                   **options):
        """A GIS file of a DEM's mesh, as the CLI writes it with --output FILE.geojson / FILE.tif:
        its bytes. `product`: "isochrones" (levels or count), "voronoi", "delaunay", "path"
        (sources[0] to points[0]), "points" (distances at `points`), "distance_raster",
        "label_raster"; GeoJSON is RFC 7946 unless `native_crs`."""
        request = pb.ExportGisRequest(
            mesh=mesh, product=pb.GisProduct.Value("GIS_PRODUCT_" + product.upper()),
            sources=sources, points=points, levels=levels, count=count, native_crs=native_crs,
            options=_solver_options(options))
        metadata = self._metadata(mesh)
        return b"".join(m.data for m in self.stub.ExportGis(request, timeout=self.timeout,
                                                             metadata=metadata))

    @_typed_errors
    def delete_mesh(self, mesh):
        self._call(self.stub.DeleteMesh, pb.DeleteMeshRequest(name=mesh), mesh)

    # --- queries ---

    @_typed_errors
    def distance_field(self, mesh, sources, want_stats=False, want_directions=False, **options):
        """Field(distances, labels, stats, directions) for every vertex, reassembled from the
        streamed chunks. `options`: SolverOptions fields (lambda_, lambda_scale, max_distance)."""
        request = pb.ComputeDistanceFieldRequest(
            mesh=mesh, sources=sources, options=_solver_options(options), want_stats=want_stats,
            want_directions=want_directions)
        distances, labels, stats, flat = [], [], None, []
        for chunk in self._call(self.stub.ComputeDistanceField, request, mesh):
            assert chunk.offset == len(distances)
            distances.extend(chunk.distances_f64)
            labels.extend(chunk.labels)
            flat.extend(chunk.directions)
            if chunk.HasField("stats"):
                stats = chunk.stats
        directions = [tuple(flat[i:i + 3]) for i in range(0, len(flat), 3)]
        return Field(distances, labels, stats, directions)

    @_typed_errors
    def shortest_path(self, mesh, start, end, **options):
        """The exact shortest path: Path(length, [PathPoint(position, simplex), ...]). An
        unreachable end raises UnreachableError."""
        response = self._call(self.stub.FindShortestPath, pb.FindShortestPathRequest(
            mesh=mesh, to=end, options=_solver_options(options), **{"from": start}), mesh)
        return Path(response.distance, _path_points(response.points))

    @_typed_errors
    def shortest_paths(self, mesh, pairs, **options):
        """Many exact shortest paths in one call, [(start, end), ...] -> [Path, ...]; pairs from
        the same start share one solve. An unreachable end gives Path(inf, [])."""
        request = pb.FindShortestPathsRequest(
            mesh=mesh, pairs=[pb.ShortestPathPair(to=end, **{"from": start}) for start, end in pairs],
            options=_solver_options(options))
        response = self._call(self.stub.FindShortestPaths, request, mesh)
        return [Path(p.distance, _path_points(p.points)) for p in response.paths]

    @_typed_errors
    def distance_matrix(self, mesh, sources, targets, k_nearest=0, on_progress=None, **options):
        """Exact distances, one row per source: [[d(source, target), ...], ...]. `k_nearest`
        keeps only each source's k nearest targets (the rest are inf). The server streams rows as
        they finish: `on_progress(rows_received, rows, fraction_solved)`, when given, is called per
        message."""
        request = pb.ComputeDistanceMatrixRequest(
            mesh=mesh, sources=sources, targets=targets, k_nearest=k_nearest,
            options=_solver_options(options))
        values, rows, cols = [], 0, 0
        for chunk in self._call(self.stub.ComputeDistanceMatrix, request, mesh):
            assert chunk.offset == len(values)
            rows, cols = chunk.rows, chunk.cols
            values.extend(chunk.values_f64)
            if on_progress is not None and cols:
                on_progress(len(values) // cols, rows, chunk.progress)
        return [values[r * cols:(r + 1) * cols] for r in range(rows)]

    @_typed_errors
    def point_distances(self, mesh, sources, points, want_directions=False, **options):
        """Distances at surface points: PointDistances(estimates, estimate_labels, exact,
        exact_labels, directions): the paper's section-4 estimate from the field, and the exact
        value; with want_directions, each point's unit direction (x, y, z) along its shortest path
        towards its nearest source ((0, 0, 0) at a source, NaN where unreachable), else []."""
        request = pb.EstimateDistancesRequest(
            mesh=mesh, sources=sources, points=points, mode=pb.POINT_DISTANCE_MODE_BOTH,
            options=_solver_options(options), want_directions=want_directions)
        r = self._call(self.stub.EstimateDistances, request, mesh)
        d = list(r.exact_directions)
        directions = [tuple(d[i:i + 3]) for i in range(0, len(d), 3)]
        return PointDistances(list(r.estimates), list(r.estimate_labels), list(r.exact),
                              list(r.exact_labels), directions)

    @_typed_errors
    def locate(self, mesh, positions, max_snap=None):
        """The nearest surface point to each (x, y, z): [Located(point, position, distance)]. With
        `max_snap`, a position farther than that from the surface raises InvalidArgumentError
        naming it (field "positions[i]")."""
        request = pb.LocatePointsRequest(
            mesh=mesh, positions=[pb.Position(x=x, y=y, z=z) for x, y, z in positions])
        if max_snap is not None:
            request.max_snap = max_snap
        response = self._call(self.stub.LocatePoints, request, mesh)
        return [Located(p.point, (p.position.x, p.position.y, p.position.z), p.distance)
                for p in response.points]

    @_typed_errors
    def isolines(self, mesh, sources, levels=None, count=0, **options):
        """Approximate isolines of the field of `sources` (paper section 6.1) at `levels`, or at
        `count` - 1 evenly spaced levels: Isolines(levels, [(level, closed, [PathPoint])])."""
        request = pb.ComputeIsolinesRequest(mesh=mesh, sources=sources, levels=levels or [],
                                            count=count, options=_solver_options(options))
        all_levels, pieces = [], []
        for message in self._call(self.stub.ComputeIsolines, request, mesh):
            all_levels.extend(message.levels)
            pieces.extend(message.isolines)
        lines = _reassemble(pieces, lambda p: (p.level, p.closed, []))
        return Isolines(all_levels, lines)

    @_typed_errors
    def voronoi(self, mesh, sites, **options):
        """The approximate Voronoi diagram: Voronoi({site: area}, [(site_a, site_b, [PathPoint])],
        [(a, b)]), with boundaries reassembled from their streamed pieces."""
        request = pb.ComputeVoronoiRequest(mesh=mesh, sources=sites, omit_cell_faces=True,
                                           options=_solver_options(options))
        areas, pieces, adjacency = {}, [], []
        for message in self._call(self.stub.ComputeVoronoi, request, mesh):
            for cell in message.cells:
                areas[cell.site] = cell.area
            pieces.extend(message.boundaries)
            adjacency.extend((pair.a, pair.b) for pair in message.adjacency)
        boundaries = _reassemble(pieces, lambda p: (p.site_a, p.site_b, []))
        return Voronoi(areas, boundaries, adjacency)

    @_typed_errors
    def delaunay(self, mesh, sites, **options):
        """The approximate Delaunay triangulation (paper sections 6.3-6.4):
        Delaunay([(site_a, site_b, length, [PathPoint])], [(a, b, c)])."""
        request = pb.ComputeDelaunayRequest(mesh=mesh, sources=sites,
                                            options=_solver_options(options))
        pieces, triangles = [], []
        for message in self._call(self.stub.ComputeDelaunay, request, mesh):
            pieces.extend(message.edges)
            triangles.extend((t.a, t.b, t.c) for t in message.triangles)
        edges = _reassemble(pieces, lambda p: (p.site_a, p.site_b, p.length, []))
        return Delaunay(edges, triangles)
