"""AsyncGeodexClient: geodexd from asyncio (grpc.aio), with the methods, arguments, results,
errors and policy of the blocking GeodexClient (geodex.client) - the same plans run by both.

    async with geodex.aio.AsyncGeodexClient("127.0.0.1:50051") as client:
        mesh = await client.upload("tests/data/kitten.off")
        path = await client.shortest_path(mesh.name, geodex.vertex(0), geodex.vertex(9),
                                          timeout=1.0)

Backoff between retries is an asyncio.sleep: other tasks run meanwhile. on_progress callbacks run
on the event loop.
"""
import asyncio
import functools
from typing import Any, Dict, Optional

import grpc
import grpc.aio

from . import _plans
from ._plans import Plans, Rpc, credentials, mesh_metadata, multicallable
from .results import RetryPolicy


def _awaitable(plan):
    @functools.wraps(plan)
    async def method(self, *args, **kwargs):
        return await self._drive(plan(self, *args, **kwargs), kwargs.get("timeout"))
    return _plans.answered(plan, method)


class AsyncGeodexClient(Plans):
    """The asyncio twin of GeodexClient: `await client.method(...)` for every method there, with
    the same `timeout=`, retries, re-upload and `max_snap=`. Use it from one event loop."""

    def __init__(self, target: str, timeout: float = 600.0, token: Optional[str] = None,
                 root_pem: Optional[bytes] = None, retry: Optional[RetryPolicy] = None,
                 wait_for_ready: bool = False, max_snap: Optional[float] = None):
        super().__init__(timeout, retry, wait_for_ready, max_snap)
        secure = credentials(token, root_pem)
        options = _plans.CHANNEL_OPTIONS
        self.channel = (grpc.aio.insecure_channel(target, options) if secure is None
                        else grpc.aio.secure_channel(target, secure, options))
        self._callables: Dict[tuple, Any] = {}

    async def close(self):
        await self.channel.close()

    async def __aenter__(self):
        return self

    async def __aexit__(self, *exc):
        await self.close()

    async def _attempt(self, rpc: Rpc, seconds: float):
        call = multicallable(self.channel, self._callables, rpc)
        request = rpc.request() if rpc.client_stream else rpc.request
        answer = call(request, timeout=seconds, metadata=mesh_metadata(rpc.mesh),
                      wait_for_ready=self.wait_for_ready)
        if not rpc.stream:
            return await answer
        messages = []
        async for message in answer:
            if rpc.on_message is not None:
                rpc.on_message(message)
            messages.append(message)
        return messages

    async def _call(self, rpc: Rpc, policy: _plans.Policy):
        while True:
            seconds = policy.seconds_left()
            try:
                return await self._attempt(rpc, seconds)
            except grpc.RpcError as rpc_error:
                action, value = policy.after(rpc_error, rpc.mesh)
                if action == "raise":
                    raise value from rpc_error
                if action == "retry":
                    await asyncio.sleep(value)
                elif action == "reconnect":  # the server restarting: wait for it to listen again
                    await asyncio.sleep(value)
                    try:
                        await asyncio.wait_for(self.channel.channel_ready(),
                                               timeout=policy.reconnect_left())
                    except asyncio.TimeoutError:
                        raise policy.last_error from rpc_error
                else:
                    await self._run(self._reupload(value), policy)
                if rpc.on_message is not None and hasattr(rpc.on_message, "restart"):
                    rpc.on_message.restart()

    async def _run(self, plan, policy: _plans.Policy):
        answer = None
        try:
            while True:
                answer = await self._call(plan.send(answer), policy)
        except StopIteration as done:
            return done.value

    async def _drive(self, plan, timeout: Optional[float]):
        policy = self._policy(timeout)
        try:
            return await self._run(plan, policy)
        finally:
            self._note(policy)


AsyncGeodexClient._make_methods(_awaitable)

__all__ = ["AsyncGeodexClient"]
