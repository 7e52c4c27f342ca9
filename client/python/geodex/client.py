"""GeodexClient: blocking calls to geodexd (geodex.v1) over Debian's python3-grpcio.
(geodex.aio.AsyncGeodexClient has the same methods for asyncio.)

Every method of the API is here; streamed answers are reassembled; failures raise the typed
exceptions of geodex.errors. Points are geodex.v1 SurfacePoint messages (see vertex(), edge_point(),
face_point(), position(), and on a DEM's mesh map_point(), lon_lat()).

A control loop's policy, the same on every method:

- `timeout=` (seconds) bounds the whole call, retries included (the client's `timeout` when not
  given). When it passes, DeadlineExceededError.
- UNAVAILABLE (the server not listening yet, restarting, draining) is retried while the server
  may be restarting: each retry waits for the channel to connect again, for up to 30 s from the
  first failure (`RetryPolicy.reconnect_wait`: geodexd's shutdown grace plus its start), within
  the call's deadline, so a call made during a restart on the same address succeeds. The channel
  tries to reconnect every 0.1 to 1 s. RESOURCE_EXHAUSTED with reason QUEUE_FULL (every worker
  busy) is retried with exponential backoff (`RetryPolicy`: 4 attempts, 0.2 s doubled each
  time); a limit (reason LIMIT) never is. With `wait_for_ready=True` every attempt waits for the
  server to come up.
- A mesh this client uploaded (from a path, bytes or arrays) that the server lost (NOT_FOUND,
  reason MESH_NOT_FOUND: a restarted replica) is uploaded again, once, and the call retried.
- `max_snap=` (or the client's `max_snap`) on every method that takes points: the server refuses
  a position farther than that from the surface (InvalidArgumentError naming it, e.g. field
  "sources[1].position"). Without it positions are snapped, each answer says how far
  (`snap_distances`), and one snapped beyond 1% of the mesh's diagonal raises a
  `SnapWarning` through warnings.warn, as the CLI warns.

Fields, labels, directions and matrices come back as numpy arrays read straight from the packed
wire bytes (no Python object per value).
"""
import functools
import time
from typing import Any, Dict, Optional

import grpc

from . import _plans
from ._plans import Plans, Rpc, SnapWarning, credentials, mesh_metadata, multicallable
from .points import edge_point, face_point, lon_lat, map_point, position, vertex
from .results import (Delaunay, DistanceMatrix, Field, GisFile, Isolines, Located, Mesh, Path,
                      PathPoint, PointDistances, RetryPolicy, Voronoi)

CHUNK_BYTES = _plans.CHUNK_BYTES


def _blocking(plan):
    @functools.wraps(plan)
    def method(self, *args, **kwargs):
        return self._drive(plan(self, *args, **kwargs), kwargs.get("timeout"))
    return _plans.answered(plan, method)


class GeodexClient(Plans):
    """Blocking calls with a deadline (`timeout` seconds per call, retries included), retries and
    re-upload as the module says; mesh-scoped calls carry the mesh id as x-mesh-id (for a
    mesh-affine gateway). `token`: a bearer token (over TLS with `root_pem`). Calls from several
    threads at once are fine."""

    def __init__(self, target: str, timeout: float = 600.0, token: Optional[str] = None,
                 root_pem: Optional[bytes] = None, retry: Optional[RetryPolicy] = None,
                 wait_for_ready: bool = False, max_snap: Optional[float] = None):
        super().__init__(timeout, retry, wait_for_ready, max_snap)
        secure = credentials(token, root_pem)
        options = _plans.CHANNEL_OPTIONS
        self.channel = (grpc.insecure_channel(target, options) if secure is None
                        else grpc.secure_channel(target, secure, options))
        self._callables: Dict[tuple, Any] = {}

    def close(self):
        self.channel.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def _attempt(self, rpc: Rpc, seconds: float):
        call = multicallable(self.channel, self._callables, rpc)
        request = rpc.request() if rpc.client_stream else rpc.request
        answer = call(request, timeout=seconds, metadata=mesh_metadata(rpc.mesh),
                      wait_for_ready=self.wait_for_ready)
        if not rpc.stream:
            return answer
        messages = []
        for message in answer:
            if rpc.on_message is not None:
                rpc.on_message(message)
            messages.append(message)
        return messages

    def _call(self, rpc: Rpc, policy: _plans.Policy):
        while True:
            seconds = policy.seconds_left()
            try:
                return self._attempt(rpc, seconds)
            except grpc.RpcError as rpc_error:
                action, value = policy.after(rpc_error, rpc.mesh)
                if action == "raise":
                    raise value from rpc_error
                if action == "retry":
                    time.sleep(value)
                elif action == "reconnect":  # the server restarting: wait for it to listen again
                    time.sleep(value)
                    try:
                        grpc.channel_ready_future(self.channel).result(
                            timeout=policy.reconnect_left())
                    except grpc.FutureTimeoutError:
                        raise policy.last_error from rpc_error
                else:
                    self._run(self._reupload(value), policy)
                if rpc.on_message is not None and hasattr(rpc.on_message, "restart"):
                    rpc.on_message.restart()

    def _run(self, plan, policy: _plans.Policy):
        answer = None
        try:
            while True:
                answer = self._call(plan.send(answer), policy)
        except StopIteration as done:
            return done.value

    def _drive(self, plan, timeout: Optional[float]):
        policy = self._policy(timeout)
        try:
            return self._run(plan, policy)
        finally:
            self._note(policy)


GeodexClient._make_methods(_blocking)

__all__ = ["GeodexClient", "RetryPolicy", "SnapWarning", "Mesh", "Field", "Path", "PathPoint",
           "Located", "PointDistances", "DistanceMatrix", "GisFile", "Isolines", "Voronoi",
           "Delaunay", "vertex", "edge_point", "face_point", "position", "map_point", "lon_lat"]
