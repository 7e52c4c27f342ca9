"""Request and response helpers shared by both clients: packed numbers read straight off the
wire, paths, solver options and enum names, streamed pieces, meshes from arrays."""
from typing import Dict

import grpc
import numpy as np

import json

from .errors import InvalidArgumentError
from .results import PathPoint, Travel
from .v1 import geodex_pb2 as pb


def _varint(data, i):
    shift = result = 0
    while True:
        b = data[i]
        i += 1
        result |= (b & 0x7F) << shift
        if b < 0x80:
            return result, i
        shift += 7


def split_packed(data: bytes, wanted: Dict[int, str]):
    """Splits a serialized message: the packed repeated fields numbered in `wanted` (number ->
    numpy dtype) become arrays, without a Python object per value; the other fields stay bytes, to
    be parsed as the message. Accepts the unpacked encoding too (a proto3 writer may use it).
    (Debian's python3-protobuf exposes no buffer for a repeated double.)"""
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


def simplex(where):
    kind = where.WhichOneof("point")
    if kind == "vertex":
        return ("v", where.vertex)
    if kind == "edge":
        return ("e", getattr(where.edge, "from"), where.edge.to, where.edge.t)
    if kind == "face":
        return ("f", where.face.face, where.face.b0, where.face.b1, where.face.b2)
    return ("p",)


def path_points(points):
    return [PathPoint((p.position.x, p.position.y, p.position.z), simplex(p.where))
            for p in points]


def invalid(message, field):
    return InvalidArgumentError(grpc.StatusCode.INVALID_ARGUMENT, message, field=field)


def travel_cost(travel) -> "pb.TravelCost":
    """A geodex.Travel (or a dict of its fields, or a TravelCost message) as a TravelCost."""
    if isinstance(travel, pb.TravelCost):
        return travel
    if isinstance(travel, dict):
        travel = Travel(**travel)
    if not isinstance(travel, Travel):
        raise invalid("travel: expected a geodex.Travel, got %r" % (travel,), "options.travel")
    out = pb.TravelCost(speed_kmh=travel.speed_kmh, max_slope_deg=travel.max_slope_deg,
                        inbound=bool(travel.inbound))
    if travel.epsilon is not None:
        out.epsilon = travel.epsilon
    speed = travel.speed
    if speed is None:
        speed = "constant" if travel.speed_table is None else "table"
    out.speed_model = enum_value(pb.SpeedModel, "SPEED_MODEL_", speed,
                                 "options.travel.speed_model")
    if travel.speed_table is not None:
        try:
            rows = np.asarray(travel.speed_table, dtype=np.float64)
        except (TypeError, ValueError):
            rows = None
        if rows is None or (rows.size and (rows.ndim != 2 or rows.shape[1] != 2)):
            raise invalid("travel.speed_table: expected rows of (slope_deg, speed_kmh), got %r"
                          % (travel.speed_table,), "options.travel.speed_table")
        for slope_deg, speed_kmh in rows.reshape(-1, 2).tolist():
            out.speed_table.add(slope_deg=slope_deg, speed_kmh=speed_kmh)
    if travel.face_weights is not None:
        out.face_weights.extend(np.asarray(travel.face_weights, dtype=np.float64).tolist())
    if travel.friction_geojson is not None:
        text = travel.friction_geojson
        out.friction_geojson = text if isinstance(text, str) else json.dumps(text)
    return out


def solver_options(options, travel=None):
    """SolverOptions from keyword arguments; lambda is spelled `lambda_` (or options={...});
    `travel` (a geodex.Travel) becomes options.travel. An unknown name is an
    InvalidArgumentError naming it and the valid ones."""
    solver = dict(options.pop("options", {}))
    if "lambda_" in options:
        solver["lambda"] = options.pop("lambda_")
    solver.update(options)
    if travel is None:
        travel = solver.pop("travel", None)
    else:
        solver.pop("travel", None)
    if travel is not None:
        solver["travel"] = travel_cost(travel)
    valid = [f.name for f in pb.SolverOptions.DESCRIPTOR.fields]
    for name in solver:
        if name not in valid:
            raise invalid("unknown option %r (solver options: %s; per call: timeout, max_snap)" % (
                name, ", ".join("lambda_" if v == "lambda" else v for v in valid)),
                "options." + name)
    if isinstance(solver.get("lambda_scale"), str):
        solver["lambda_scale"] = enum_value(pb.LambdaScale, "LAMBDA_SCALE_",
                                            solver["lambda_scale"], "lambda_scale")
    return pb.SolverOptions(**solver)


def enum_value(enum, prefix, name, field):
    """An enum value by its short name ("max_edge", "isochrones"), or InvalidArgumentError listing
    the valid ones."""
    full = prefix + str(name).upper()
    if full in enum.keys():
        return enum.Value(full)
    valid = [k[len(prefix):].lower() for k in enum.keys() if not k.endswith("UNSPECIFIED")]
    raise invalid("%s: unknown value %r (valid: %s)" % (field, name, ", ".join(valid)), field)


def reassemble(pieces, start):
    """Items streamed in pieces: a piece continues the previous item when that one said
    `continued`. `start(piece)` makes a new item with a `points` list."""
    items, open_item = [], False
    for piece in pieces:
        if not open_item:
            items.append(start(piece))
        items[-1][-1].extend(path_points(piece.points))
        open_item = piece.continued
    return items


def off_text(vertices, faces) -> bytes:
    """A mesh from arrays as OFF text with coordinates that round-trip exactly (%.17g): the
    server computes the same mesh id as for a file with these float64 values."""
    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces)
    # Shapes checked here, naming the argument (a reshape would fail with numpy's own words, or
    # silently regroup an (m, 2) array into triangles).
    for array, what, field in ((v, "vertices", "vertices"), (f, "faces", "faces")):
        if array.ndim != 2 or array.shape[1] != 3:
            raise invalid("upload((vertices, faces)): %s has shape %s; expected (n, 3) (%s)" % (
                what, array.shape, "x, y, z per vertex" if what == "vertices"
                else "three vertex ids per triangle"), field)
    if f.size and not np.issubdtype(f.dtype, np.integer):
        raise invalid("upload((vertices, faces)): faces must be integer vertex ids, not %s" %
                      f.dtype, "faces")
    f = f.astype(np.int64)
    bad = np.argwhere((f < 0) | (f >= len(v)))
    if len(bad):
        i, k = (int(x) for x in bad[0])
        raise invalid("upload((vertices, faces)): faces[%d, %d] is %d: no such vertex (vertices "
                      "has %d rows)" % (i, k, f[i, k], len(v)), "faces")
    bad = np.argwhere(~np.isfinite(v))
    if len(bad):
        raise invalid("upload((vertices, faces)): vertices[%d] is not finite" % int(bad[0][0]),
                      "vertices")
    lines = ["OFF", "%d %d 0" % (len(v), len(f))]
    lines += ["%.17g %.17g %.17g" % tuple(row) for row in v.tolist()]
    lines += ["3 %d %d %d" % tuple(row) for row in f.tolist()]
    return ("\n".join(lines) + "\n").encode()
