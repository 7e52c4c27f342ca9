"""Surface points for requests: geodex.v1 SurfacePoint messages.

A vertex, an edge point, a face point (barycentric, in the file's corner order), a 3D position
(snapped to the surface by the server: see `max_snap` on every method), and on a DEM's mesh a map
point or a longitude/latitude (dropped vertically onto the surface).
"""
from .v1 import geodex_pb2 as pb


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
    """A 3D position, snapped to the surface by the server (how far: each answer's
    `snap_distances`; `max_snap=` refuses a position farther than that)."""
    return pb.SurfacePoint(position=pb.Position(x=x, y=y, z=z))


def map_point(x: float, y: float) -> "pb.SurfacePoint":
    """On a DEM's mesh (uploaded as a GeoTIFF): a map point in the raster's CRS, dropped
    vertically onto the surface by the server (the CLI's g:X:Y)."""
    return pb.SurfacePoint(map_point=pb.MapPoint(x=x, y=y))


def lon_lat(lon: float, lat: float) -> "pb.SurfacePoint":
    """On a DEM's mesh: a WGS 84 longitude/latitude in degrees, dropped likewise (ll:LON:LAT)."""
    return pb.SurfacePoint(lon_lat=pb.LonLat(lon=lon, lat=lat))
