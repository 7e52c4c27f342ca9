#!/usr/bin/python3
"""A robot planner's workload against a running geodexd (issue 56): many starts, short goals,
each start asked again and again, every call with a 0.1 s timeout, from 1, 4 and 16 concurrent
clients. Prints one Markdown row per client count: calls, failures (any error, deadline included),
p50/p99 of the first call from a start and of the repeats, and queries per second.

The mesh is an n x n grid of bumps (2 (n - 1)^2 faces; n = 211: 88,200 faces), made here, so the
bench needs nothing but the server and the geodex package.

usage: planner_bench.py HOST:PORT [GRID_N] [STARTS_PER_CLIENT] [CALLS_PER_START] [TIMEOUT_S]
"""
import sys
import threading
import time

import numpy

import geodex
from geodex import vertex


def bumpy_grid(n):
    # Vertex (i, j) is j * n + i; each cell split along its rising diagonal.
    x, y = numpy.meshgrid(numpy.linspace(0, 1, n), numpy.linspace(0, 1, n))
    heights = 0.05 * numpy.sin(9 * x) * numpy.cos(7 * y)
    corner = (numpy.arange(n - 1)[None, :] + n * numpy.arange(n - 1)[:, None]).ravel()
    lower = numpy.stack([corner, corner + 1, corner + n + 1], 1)
    upper = numpy.stack([corner, corner + n + 1, corner + n], 1)
    return numpy.column_stack([x.ravel(), y.ravel(), heights.ravel()]), numpy.vstack([lower, upper])


def main():
    target = sys.argv[1]
    n = int(sys.argv[2]) if len(sys.argv) > 2 else 211
    starts_per_client = int(sys.argv[3]) if len(sys.argv) > 3 else 40
    calls_per_start = int(sys.argv[4]) if len(sys.argv) > 4 else 4
    timeout = float(sys.argv[5]) if len(sys.argv) > 5 else 0.1
    with geodex.GeodexClient(target, timeout=300, wait_for_ready=True) as setup:
        mesh = setup.upload(bumpy_grid(n), name="planner-grid")
    print("| clients | calls | failed | first p50 ms | first p99 ms | repeat p50 ms | repeat p99 ms"
          " | queries/s |")
    print("|---:|---:|---:|---:|---:|---:|---:|---:|")
    used = set()
    for clients in (1, 4, 16):
        first, repeat, failed = [], [], [0]
        lock = threading.Lock()
        # Every client its own starts, unseen by the server before (a field cached from an
        # earlier row would make its first calls traces); goals a few cells away.
        plans = []
        rng = numpy.random.default_rng(clients)
        for _ in range(clients):
            starts = []
            while len(starts) < starts_per_client:
                i, j = (int(v) for v in rng.integers(5, n - 5, size=2))
                if (i, j) in used:
                    continue
                used.add((i, j))
                starts.append((i, j))
            plans.append(starts)

        def run(starts):
            with geodex.GeodexClient(target, timeout=timeout) as client:
                for i, j in starts:
                    for k in range(calls_per_start):
                        di, dj = ((3, 1), (-2, 4), (4, -3), (-1, -4))[k % 4]
                        goal = (j + dj) * n + (i + di)
                        t0 = time.perf_counter()
                        try:
                            client.shortest_path(mesh.name, vertex(j * n + i), vertex(goal))
                            ms = (time.perf_counter() - t0) * 1e3
                            with lock:
                                (first if k == 0 else repeat).append(ms)
                        except geodex.GeodexError:
                            with lock:
                                failed[0] += 1

        threads = [threading.Thread(target=run, args=(plan,)) for plan in plans]
        t0 = time.perf_counter()
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        wall = time.perf_counter() - t0
        calls = clients * starts_per_client * calls_per_start

        def pct(values, q):
            return "%.2f" % numpy.percentile(values, q) if values else "-"
        print("| %d | %d | %d | %s | %s | %s | %s | %.0f |" % (
            clients, calls, failed[0], pct(first, 50), pct(first, 99), pct(repeat, 50),
            pct(repeat, 99), (len(first) + len(repeat)) / wall))


main()
