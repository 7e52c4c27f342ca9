"""What the clients return: one kind of result object, dataclasses, each also unpacking like a
tuple of its main fields (`length, points = client.shortest_path(...)`).

Every answer to a request that takes points carries `snap_distances`: how far each request point
moved onto the surface, in request order (numpy float64; 0 for vertices, edge and face points and
map points). Every answer with distances carries `travel_epsilon`: 0.0 when they are exact metres,
> 0 when the request's `travel=` made them travel times in seconds, each within
(1 + travel_epsilon) of the least time (`travel_exact` True: exact times, one weight at a constant
speed). The fields marked "not unpacked" are left out of tuple
unpacking.
"""
import dataclasses
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np


def _extra(default=None):
    """A field added after the tuple shape was fixed: not unpacked, not compared."""
    return dataclasses.field(default=default, compare=False, metadata={"unpack": False})


def _no_snaps():
    return dataclasses.field(default_factory=lambda: np.zeros(0), compare=False, repr=False,
                             metadata={"unpack": False})


def _exact():
    """travel_epsilon: 0.0 (exact metres) unless the answer is a travel time."""
    return dataclasses.field(default=0.0, compare=False, metadata={"unpack": False})


@dataclasses.dataclass
class Travel:
    """Travel time instead of length (geodex.v1.TravelCost, docs/travel.md), the `travel=` of
    every query that takes solver options: its answers are then in SECONDS (the answer's
    `travel_epsilon` > 0). With a constant speed each is at least the least travel time and at
    most (1 + epsilon) times it; with a slope-dependent speed no bound is proved (epsilon is the
    spacing of the server's Steiner points along each edge).

    `speed_kmh`: the constant speed on a face of weight 1 (km/h, > 0; leave it 0 with a
    slope-dependent speed). `speed`: "constant", "tobler" (Tobler's hiking function: 6 km/h
    slightly downhill, slower up and steeply down; a walker zigzags where that is quicker) or
    "table" (None: "table" when speed_table is given, else "constant"). `speed_table`: rows
    (slope in degrees, > 0 uphill, speed in km/h), at least 2, slopes strictly increasing in
    [-90, 90] with the first <= 0 <= the last, speeds > 0; linear between rows, steeper slopes
    cannot be walked. `inbound`: with a slope-dependent speed, times to REACH the sources instead
    of from them (paths are walked from their start and refuse it). `epsilon`: in (0, 1) (None: the
    server's default for the speed model, 0.01 constant, 0.125 slope-dependent). `max_slope_deg`: faces steeper than this (degrees from the x-y plane) are
    impassable (0: no limit). `face_weights`: one friction per face of the mesh, in order (> 0,
    inf impassable; None: 1). `friction_geojson`: GeoJSON polygons (text or a dict) with a
    numeric "friction" property; each face takes the friction of the polygon holding its
    centroid (WGS 84 on a DEM's mesh unless the GeoJSON names its CRS, else the mesh's x y): on
    a mesh derived with the same polygons (derive_mesh(friction_geojson=...)) region boundaries
    are exact, on any other as fine as its faces. At
    most one of face_weights and friction_geojson. Not with want_directions, delaunay() or the
    unfolding estimates (point_distances() then returns exact values only). The server checks
    the values: a bad one is an InvalidArgumentError naming its field
    (`"options.travel.speed_table[1]"`)."""
    speed_kmh: float = 0.0
    epsilon: Optional[float] = None
    max_slope_deg: float = 0.0
    face_weights: Optional[Sequence[float]] = None
    friction_geojson: Union[None, str, Dict[str, Any]] = None
    speed: Optional[str] = None
    speed_table: Optional[Sequence[Tuple[float, float]]] = None
    inbound: bool = False


class _Unpacks:
    def __iter__(self):
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
    want_stats, the solve's SolveStats in `stats` (solve_ms, windows_created, cached, ...);
    `snap_distances` of (start, end) (not unpacked). `length` is the path's cost: metres, or with
    a travel cost seconds; `length_m` is always its length along the surface in metres and
    `time_s` its travel time in seconds (None without a travel cost)."""
    length: float
    points: List[PathPoint]
    stats: Any = _extra()
    snap_distances: np.ndarray = _no_snaps()
    travel_epsilon: float = _exact()
    length_m: float = _extra(float("nan"))
    time_s: Optional[float] = _extra()
    travel_exact: bool = _extra(False)


@dataclasses.dataclass(eq=False)
class Field(_Unpacks):
    """A distance field: per vertex the distance (float64, inf where unreachable) and the nearest
    source's index (uint32), the solve's stats (with want_stats, else None), and with
    want_directions the geodesic direction field, shape (n, 3): per vertex the unit tangent
    towards the nearest source, (0, 0, 0) at a source, NaN where unreachable (shape (0, 3)
    otherwise). `snap_distances`: one per source, and `travel_epsilon` (not unpacked)."""
    distances: np.ndarray
    labels: np.ndarray
    stats: Any
    directions: np.ndarray
    snap_distances: np.ndarray = _no_snaps()
    travel_epsilon: float = _exact()
    travel_exact: bool = _extra(False)


class DistanceMatrix(np.ndarray):
    """A (sources x targets) float64 numpy array of exact distances (inf where unreachable or
    beyond k_nearest / max_distance), with `snap_distances`: the sources', then the targets';
    and `travel_epsilon` (> 0: travel times in seconds within that bound)."""

    snap_distances: np.ndarray
    travel_epsilon: float
    travel_exact: bool

    def __array_finalize__(self, obj):
        self.snap_distances = getattr(obj, "snap_distances", np.zeros(0))
        self.travel_epsilon = getattr(obj, "travel_epsilon", 0.0)
        self.travel_exact = getattr(obj, "travel_exact", False)


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
    towards its nearest source, shape (n, 3) (else (0, 3)). `snap_distances`: the sources', then
    the points' (not unpacked)."""
    estimates: np.ndarray
    estimate_labels: np.ndarray
    exact: np.ndarray
    exact_labels: np.ndarray
    directions: np.ndarray
    snap_distances: np.ndarray = _no_snaps()
    travel_epsilon: float = _exact()
    travel_exact: bool = _extra(False)


@dataclasses.dataclass
class Isolines(_Unpacks):
    """Approximate isolines (paper section 6.1): the levels and (level, closed, [PathPoint])
    lines; `snap_distances` of the sources (not unpacked)."""
    levels: List[float]
    lines: list
    snap_distances: np.ndarray = _no_snaps()
    travel_epsilon: float = _exact()
    travel_exact: bool = _extra(False)


@dataclasses.dataclass
class Voronoi(_Unpacks):
    """Approximate Voronoi diagram: {site: area}, [(site_a, site_b, [PathPoint])] boundaries,
    [(a, b)] adjacency; `snap_distances` of the sites (not unpacked)."""
    areas: Dict[int, float]
    boundaries: list
    adjacency: List[Tuple[int, int]]
    snap_distances: np.ndarray = _no_snaps()
    travel_epsilon: float = _exact()
    travel_exact: bool = _extra(False)


@dataclasses.dataclass
class Delaunay(_Unpacks):
    """Approximate Delaunay triangulation: [(site_a, site_b, length, [PathPoint])] edges and
    [(a, b, c)] triangles; `snap_distances` of the sites (not unpacked)."""
    edges: list
    triangles: List[Tuple[int, int, int]]
    snap_distances: np.ndarray = _no_snaps()


class GisFile(bytes):
    """A GIS file's bytes (GeoJSON text or a GeoTIFF), with its `media_type`, the
    `snap_distances` of the request's sources, then points, and `travel_epsilon` (> 0: its
    distances are travel times in seconds within that bound)."""

    media_type: str
    snap_distances: np.ndarray
    travel_epsilon: float = 0.0
    travel_exact: bool = False


@dataclasses.dataclass
class Mesh:
    """A mesh as geodexd stores it. `name` is canonical, "meshes/<64-hex id>"; `aliases` are all
    the names given to it (the first upload's `display_name` and later ones: "kitten" makes
    "meshes/kitten" work wherever the name does). `terrain` is the DEM's map
    (a geodex.v1.Terrain message) for a DEM's mesh, else None. `diagonal` is the length of its
    bounding box's diagonal. `resource` is the full message."""
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

    @property
    def diagonal(self) -> float:
        lo, hi = self.resource.info.bbox_min, self.resource.info.bbox_max
        return float(np.sqrt((hi.x - lo.x) ** 2 + (hi.y - lo.y) ** 2 + (hi.z - lo.z) ** 2))

    @staticmethod
    def from_proto(m) -> "Mesh":
        names = [n for n in [m.display_name, *m.aliases] if n]
        return Mesh(m.name, m.display_name, names, m.vertex_count, m.face_count,
                    m.upload_bytes, m.memory_bytes, m.pinned, m.components, m.boundary_edges,
                    m.terrain if m.HasField("terrain") else None, m)


@dataclasses.dataclass
class RetryPolicy:
    """Which failures are tried again, how often and how far apart (see geodex.client).
    Retries happen only while the call's deadline leaves room for the wait.

    UNAVAILABLE (the server restarting, draining, not yet listening) is retried for up to
    `reconnect_wait` seconds after it is first seen, each retry waiting for the channel to
    connect again (a restart on the same address: geodexd's shutdown grace, 10 s by default, plus
    its start), whatever `max_attempts` says; then UnavailableError. `max_attempts` bounds the
    retries of a full queue (RESOURCE_EXHAUSTED, reason QUEUE_FULL)."""
    max_attempts: int = 4
    initial_backoff: float = 0.2
    multiplier: float = 2.0
    retry_queue_full: bool = True
    reconnect_wait: float = 30.0
