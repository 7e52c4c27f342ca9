"""geodex: a Python client for geodexd, the exact geodesic service.

    import geodex
    with geodex.GeodexClient("127.0.0.1:50051") as client:
        mesh = client.upload("tests/data/kitten.off", name="kitten")   # or bytes, or arrays
        length, points = client.shortest_path(mesh.name, geodex.vertex(0), geodex.vertex(1250))

geodex.aio.AsyncGeodexClient has the same methods for asyncio. Errors raise geodex.GeodexError
subclasses (geodex.errors). The geodex.v1 message modules are generated from
proto/geodex/v1/geodex.proto: by `pip install ./client/python`, or by the CMake build into
build/python (put both build/python and client/python on PYTHONPATH to use this source tree
directly).
"""
import pkgutil

# The generated geodex.v1 modules may live in another directory of sys.path (build/python).
__path__ = pkgutil.extend_path(__path__, __name__)

from .client import GeodexClient  # noqa: E402
from .errors import (CancelledError, DataLossError, DeadlineExceededError,  # noqa: E402
                     GeodexError, InvalidArgumentError, NotFoundError, ResourceExhaustedError,
                     UnauthenticatedError, UnavailableError, UnreachableError)
from .points import edge_point, face_point, lon_lat, map_point, position, vertex  # noqa: E402
from ._plans import SnapWarning  # noqa: E402
from .results import (Delaunay, DistanceMatrix, Field, GisFile, Isolines, Located,  # noqa: E402
                      Mesh, Path, PathPoint, PointDistances, RetryPolicy, Travel, Voronoi)

# Written at build time from CMakeLists.txt's project version (setup.py for pip, CMake for
# build/python): one version for geodex, geodexd and this package.
from ._version import __version__  # noqa: E402
__all__ = [
    "GeodexClient", "RetryPolicy", "Travel", "Mesh", "vertex", "edge_point", "face_point",
    "position", "map_point", "lon_lat", "Field", "Path", "PathPoint", "Located", "PointDistances",
    "DistanceMatrix", "GisFile", "Isolines", "Voronoi", "Delaunay", "SnapWarning", "GeodexError",
    "InvalidArgumentError", "NotFoundError", "UnreachableError", "ResourceExhaustedError",
    "UnauthenticatedError", "UnavailableError", "DeadlineExceededError", "CancelledError",
    "DataLossError",
]
