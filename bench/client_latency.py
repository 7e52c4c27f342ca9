#!/usr/bin/python3
"""The Python twin of bench/client_latency.cc: repeated single-target path queries through the
geodex package on a warm mesh, near and far pairs, p50/p99 latency, queries per second, the
server's solve time (SolveStats.solve_ms) and the difference (the client's and the wire's cost).

usage: client_latency.py HOST:PORT MESH_FILE DISTANCES_FILE [CALLS_PER_GROUP] [SEED]
(DISTANCES_FILE: `geodex distances MESH_FILE --sources 0`, so the server caches no field from 0)
"""
import random
import sys
import time

import numpy

import geodex
from geodex import vertex


def main():
    target, mesh_file = sys.argv[1], sys.argv[2]
    distances = numpy.loadtxt(sys.argv[3])
    calls = int(sys.argv[4]) if len(sys.argv) > 4 else 50
    rng = random.Random(int(sys.argv[5]) if len(sys.argv) > 5 else 1)
    with geodex.GeodexClient(target, timeout=120, wait_for_ready=True) as client:
        mesh = client.upload(mesh_file)
        finite = numpy.isfinite(distances)
        top = distances[finite].max()
        ids = numpy.arange(len(distances))
        # Every query from a start the server has not seen (see client_latency.cc).
        # The odd-numbered candidates (client_latency.cc takes the even ones).
        starts = [int(v) for v in ids[finite & (distances <= 0.05 * top) & (ids > 0)]][1::2]
        rng.shuffle(starts)
        near = ids[finite & (distances <= 0.1 * top) & (ids > 0)]
        far = ids[finite & (distances >= 0.5 * top)]
        for group, targets in (("near (<= 15% of D)", near), ("far (>= 45% of D)", far)):
            latency, solve = [], []
            while len(latency) < calls and starts and len(targets):
                start, end = starts.pop(), int(targets[rng.randrange(len(targets))])
                t0 = time.perf_counter()
                path = client.shortest_path(mesh.name, vertex(start), vertex(end), want_stats=True)
                latency.append((time.perf_counter() - t0) * 1e3)
                solve.append(path.stats.solve_ms)
            if not latency:
                continue
            seconds = sum(latency) / 1e3
            overhead = [a - b for a, b in zip(latency, solve)]
            print("| Python | %s | %s | %d | %.3f | %.3f | %.1f | %.3f | %.3f |" % (
                mesh_file, group, len(latency), numpy.percentile(latency, 50),
                numpy.percentile(latency, 99), len(latency) / seconds,
                numpy.percentile(solve, 50), numpy.percentile(overhead, 50)))

main()
