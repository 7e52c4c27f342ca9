#!/usr/bin/python3
"""Upload a mesh, then a distance field, a shortest path, a matrix and a Voronoi diagram.

usage: example.py HOST:PORT MESH_FILE
"""
import sys

import geodex
from geodex import vertex


def main():
    target, path = sys.argv[1], sys.argv[2]
    with geodex.GeodexClient(target) as client:
        print("health:", "SERVING" if client.health() else "NOT_SERVING")
        mesh = client.upload(path)
        print("mesh:", mesh.name, mesh.vertex_count, "vertices", mesh.face_count, "faces")
        n = mesh.vertex_count
        distances, labels, stats, _ = client.distance_field(mesh.name, [vertex(0), vertex(n // 2)],
                                                            want_stats=True)
        print("field: farthest vertex at", max(d for d in distances if d != float("inf")),
              "windows:", stats.windows_created)
        path = client.shortest_path(mesh.name, vertex(0), vertex(n - 1))
        print("path: length", path.length, "with", len(path.points), "points, from",
              path.points[0].simplex, "to", path.points[-1].simplex)
        rows = client.distance_matrix(mesh.name, [vertex(0), vertex(5)], [vertex(7), vertex(99)])
        print("matrix:", rows)
        voronoi = client.voronoi(mesh.name, [vertex(0), vertex(n // 3), vertex(2 * n // 3)])
        print("voronoi:", {site: round(area, 6) for site, area in voronoi.areas.items()},
              len(voronoi.boundaries), "boundaries")
        try:
            client.distance_field(mesh.name, [vertex(n + 5)])
        except geodex.InvalidArgumentError as error:
            print("error:", type(error).__name__, "field", error.field)


main()
