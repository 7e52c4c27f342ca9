#!/usr/bin/python3
"""The Python twin of bench/client_latency.cc: repeated single-target path queries through the
geodex package on a warm mesh, near and far pairs, p50/p99 latency, queries per second, the
server's solve time (SolveStats.solve_ms) and the difference (the client's and the wire's cost).

usage: client_latency.py HOST:PORT MESH_FILE [CALLS_PER_GROUP] [SEED]
"""
import random
import sys
import time

import numpy

import geodex
from geodex import vertex
from geodex.v1 import geodex_pb2 as pb


def main():
    target, mesh_file = sys.argv[1], sys.argv[2]
    calls = int(sys.argv[3]) if len(sys.argv) > 3 else 50
    rng = random.Random(int(sys.argv[4]) if len(sys.argv) > 4 else 1)
    with geodex.GeodexClient(target, timeout=120, wait_for_ready=True) as client:
        mesh = client.upload(mesh_file)
        distances = client.distance_field(mesh.name, [vertex(0)]).distances
        finite = numpy.isfinite(distances)
        top = distances[finite].max()
        ids = numpy.arange(len(distances))
        near = ids[finite & (distances <= 0.1 * top) & (ids > 0)]
        far = ids[finite & (distances >= 0.5 * top)]
        for group, targets in (("near (<= 10% of D)", near), ("far (>= 50% of D)", far)):
            if len(targets) == 0:
                continue
            latency, solve = [], []
            start = time.perf_counter()
            for _ in range(calls):
                end = int(targets[rng.randrange(len(targets))])
                t0 = time.perf_counter()
                client.shortest_path(mesh.name, vertex(0), vertex(end))
                latency.append((time.perf_counter() - t0) * 1e3)
                # The server's solve time of the same query (stats are not part of Path).
                response = client.stub.FindShortestPath(pb.FindShortestPathRequest(
                    mesh=mesh.name, to=vertex(end), want_stats=True, **{"from": vertex(0)}),
                    timeout=120)
                solve.append(response.stats.solve_ms)
            seconds = sum(latency) / 1e3
            p50 = numpy.percentile(latency, 50)
            print("| Python | %s | %s | %d | %.3f | %.3f | %.1f | %.3f | %.3f |" % (
                mesh_file, group, calls, p50, numpy.percentile(latency, 99), calls / seconds,
                numpy.percentile(solve, 50), p50 - numpy.percentile(solve, 50)))


main()
