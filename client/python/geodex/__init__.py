"""geodex: a Python client for geodexd, the exact geodesic service.

    import geodex
    with geodex.GeodexClient("127.0.0.1:50051") as client:
        mesh = client.upload("tests/data/kitten.off", name="kitten")   # or bytes, or arrays
        length, points = client.shortest_path(mesh.name, geodex.vertex(0), geodex.vertex(1250))

Errors raise geodex.GeodexError subclasses (geodex.errors). The geodex.v1 message modules are
generated from proto/geodex/v1/geodex.proto: by `pip install ./client/python`, or by the CMake
build into build/python (put both build/python and client/python on PYTHONPATH to use this source
tree directly).
"""
import pkgutil

# The generated geodex.v1 modules may live in another directory of sys.path (build/python).
__path__ = pkgutil.extend_path(__path__, __name__)

from .client import (Delaunay, Field, GeodexClient, Isolines, Located, Mesh, Path,  # noqa: E402
                     PathPoint, PointDistances, RetryPolicy, Voronoi, edge_point, face_point,
                     lon_lat, map_point, position, vertex)
from .errors import (CancelledError, DataLossError, DeadlineExceededError,  # noqa: E402
                     GeodexError, InvalidArgumentError, NotFoundError, ResourceExhaustedError,
                     UnauthenticatedError, UnavailableError, UnreachableError)

__version__ = "0.1.0"
__all__ = [
    "GeodexClient", "RetryPolicy", "Mesh", "vertex", "edge_point", "face_point", "position", "map_point", "lon_lat",
    "Field", "Path", "PathPoint",
    "Located", "PointDistances", "Isolines", "Voronoi", "Delaunay", "GeodexError",
    "InvalidArgumentError", "NotFoundError", "UnreachableError", "ResourceExhaustedError",
    "UnauthenticatedError", "UnavailableError", "DeadlineExceededError", "CancelledError",
    "DataLossError",
]
