#!/usr/bin/python3
"""The HTTP/JSON edge's cost next to gRPC on one geodexd: the same path query (the sample terrain,
vertex 0 to 4224: after the first call a trace of the cached field, so the transport is most of
the time) asked CALLS times through each, alternating blocks of 50, from Python (http.client with
keep-alive and json, against the geodex package over gRPC). Prints the median latency of each and
their ratio, and checks both answers agree to 1e-12.

usage: PYTHONPATH=client/python:build/python http_edge_bench.py GEODEXD [CALLS]   (starts its own geodexd on
127.0.0.1, ports it picks; stops it)
"""
import http.client
import json
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time

import geodex
from geodex import vertex


def main():
    geodexd = sys.argv[1]
    calls = int(sys.argv[2]) if len(sys.argv) > 2 else 1000
    with tempfile.TemporaryDirectory() as tmp:
        log_path = os.path.join(tmp, "geodexd.log")
        with open(log_path, "w") as log:
            proc = subprocess.Popen([geodexd, "--listen", "127.0.0.1:0", "--http_listen",
                                     "127.0.0.1:0", "--metrics_listen", "", "--log_requests=false"],
                                    stdout=log, stderr=subprocess.STDOUT)
            try:
                grpc_port = http_port = None
                for _ in range(400):
                    text = open(log_path).read()
                    g = re.search(r"listening on port (\d+)", text)
                    h = re.search(r"HTTP/JSON API on http://127\.0\.0\.1:(\d+)/", text)
                    if g and h:
                        grpc_port, http_port = g.group(1), h.group(1)
                        break
                    time.sleep(0.05)
                run(grpc_port, http_port, calls)
            finally:
                proc.terminate()
                proc.wait(timeout=30)


def run(grpc_port, http_port, calls):
    connection = http.client.HTTPConnection("127.0.0.1", int(http_port), timeout=60)
    body = json.dumps({"from": {"vertex": 0}, "to": {"vertex": 4224}})
    headers = {"Content-Type": "application/json"}

    def over_http():
        connection.request("POST", "/v1/meshes/terrain:findShortestPath", body, headers)
        answer = connection.getresponse()
        data = answer.read()
        assert answer.status == 200, data
        return json.loads(data)["distance"]

    with geodex.GeodexClient("127.0.0.1:" + grpc_port, timeout=60, wait_for_ready=True) as client:
        def over_grpc():
            return client.shortest_path("terrain", vertex(0), vertex(4224)).length_m

        a, b = over_http(), over_grpc()  # warm: the field is solved once and cached
        assert abs(a - b) <= 1e-12 * max(1.0, abs(b)), (a, b)
        times = {"http": [], "grpc": []}
        for block in range(calls // 50):
            for name, call in (("http", over_http), ("grpc", over_grpc))[::1 if block % 2 else -1]:
                for _ in range(50):
                    t0 = time.perf_counter()
                    call()
                    times[name].append((time.perf_counter() - t0) * 1e3)
    h, g = statistics.median(times["http"]), statistics.median(times["grpc"])
    print(f"calls per protocol: {len(times['http'])}")
    print(f"HTTP/JSON median {h:.3f} ms, gRPC median {g:.3f} ms, HTTP/gRPC {h / g:.2f}x")


if __name__ == "__main__":
    main()
