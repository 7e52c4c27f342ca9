"""Typed exceptions for geodexd's errors.

Every failed call raises a GeodexError subclass chosen by the gRPC status code, carrying what the
server sent as data (never parsed out of the message): `code` (grpc.StatusCode), `message`,
`field` (the request field a google.rpc.BadRequest names, e.g. "sources[0].vertex"), `reason` and
`flag` (a google.rpc.ErrorInfo's reason, e.g. "LIMIT", "QUEUE_FULL", "UNREACHABLE", and the server
flag that set a limit, e.g. "max_targets"). The original grpc.RpcError is `__cause__`.
"""
import os

import grpc
from google.protobuf import descriptor_pb2, descriptor_pool, message_factory


class GeodexError(Exception):
    """A geodexd call failed."""

    def __init__(self, code, message, field="", reason="", flag=""):
        super().__init__(message)
        self.code, self.message = code, message
        self.field, self.reason, self.flag = field, reason, flag

    def __str__(self):
        return "%s: %s" % (self.code.name if self.code else "ERROR", self.message)


class InvalidArgumentError(GeodexError):
    """A bad request or mesh; `field` names the request field."""


class NotFoundError(GeodexError):
    """An unknown mesh (name, alias or id)."""


class UnreachableError(GeodexError):
    """The path's target is not reachable from its source (FAILED_PRECONDITION, UNREACHABLE)."""


class ResourceExhaustedError(GeodexError):
    """A server limit (`flag` names it; reason LIMIT), the mesh budget, or a full queue
    (reason QUEUE_FULL: retry later)."""


class UnauthenticatedError(GeodexError):
    """The server wants a bearer token and the call had no valid one."""


class UnavailableError(GeodexError):
    """The server cannot be reached, or is shutting down."""


class DeadlineExceededError(GeodexError):
    """The call's timeout passed; the server stopped the solve."""


class CancelledError(GeodexError):
    """The call was cancelled."""


class DataLossError(GeodexError):
    """A stored mesh failed verification on the server."""


_BY_CODE = {
    grpc.StatusCode.INVALID_ARGUMENT: InvalidArgumentError,
    grpc.StatusCode.OUT_OF_RANGE: InvalidArgumentError,
    grpc.StatusCode.NOT_FOUND: NotFoundError,
    grpc.StatusCode.FAILED_PRECONDITION: UnreachableError,
    grpc.StatusCode.RESOURCE_EXHAUSTED: ResourceExhaustedError,
    grpc.StatusCode.UNAUTHENTICATED: UnauthenticatedError,
    grpc.StatusCode.UNAVAILABLE: UnavailableError,
    grpc.StatusCode.DEADLINE_EXCEEDED: DeadlineExceededError,
    grpc.StatusCode.CANCELLED: CancelledError,
    grpc.StatusCode.DATA_LOSS: DataLossError,
}

_classes = None


def _detail_classes():
    """google.rpc Status, BadRequest and ErrorInfo from the descriptor set the build wrote next to
    this package (_rpc_details.desc), in a private pool so that another copy of these protos in
    the process (googleapis-common-protos) cannot clash."""
    global _classes
    if _classes is None:
        from . import __path__ as package_path
        for directory in package_path:
            path = os.path.join(directory, "_rpc_details.desc")
            if os.path.exists(path):
                break
        else:
            _classes = {}
            return _classes
        files = descriptor_pb2.FileDescriptorSet()
        with open(path, "rb") as f:
            files.ParseFromString(f.read())
        pool = descriptor_pool.DescriptorPool()
        for file in files.file:
            pool.Add(file)
        factory = message_factory.MessageFactory(pool)
        _classes = {name: factory.GetPrototype(pool.FindMessageTypeByName("google.rpc." + name))
                    for name in ("Status", "BadRequest", "ErrorInfo")}
    return _classes


def from_rpc_error(error):
    """The typed exception for a grpc.RpcError (with the details the server attached)."""
    code = error.code() if hasattr(error, "code") else None
    message = error.details() if hasattr(error, "details") else str(error)
    field = reason = flag = ""
    classes = _detail_classes()
    metadata = error.trailing_metadata() if hasattr(error, "trailing_metadata") else None
    for key, value in metadata or ():
        if key != "grpc-status-details-bin" or not classes:
            continue
        status = classes["Status"].FromString(value)
        for detail in status.details:
            kind = detail.type_url.rsplit("/", 1)[-1]
            if kind == "google.rpc.BadRequest":
                violations = classes["BadRequest"].FromString(detail.value).field_violations
                if violations:
                    field = violations[0].field
            elif kind == "google.rpc.ErrorInfo":
                info = classes["ErrorInfo"].FromString(detail.value)
                reason, flag = info.reason, info.metadata.get("flag", "")
    return _BY_CODE.get(code, GeodexError)(code, message, field, reason, flag)
