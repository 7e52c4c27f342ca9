#!/usr/bin/python3
"""Upload a mesh, then a distance field, a shortest path and a Voronoi diagram.

usage: example.py HOST:PORT MESH_FILE
"""
import sys

from geodex_client import GeodexClient, vertex


def main():
    target, path = sys.argv[1], sys.argv[2]
    client = GeodexClient(target)
    print("health:", "SERVING" if client.health() else "NOT_SERVING")
    mesh = client.upload(path)
    print("mesh:", mesh.name, mesh.vertex_count, "vertices", mesh.face_count, "faces")
    n = mesh.vertex_count
    distances, labels, stats = client.distance_field(mesh.name, [vertex(0), vertex(n // 2)],
                                                     want_stats=True)
    print("field: farthest vertex at", max(d for d in distances if d != float("inf")),
          "windows:", stats.windows_created)
    length, points = client.shortest_path(mesh.name, vertex(0), vertex(n - 1))
    print("path: length", length, "with", len(points), "points")
    rows = client.distance_matrix(mesh.name, [vertex(0), vertex(5)], [vertex(7), vertex(99)])
    print("matrix:", rows)
    areas, boundaries = client.voronoi(mesh.name, [vertex(0), vertex(n // 3), vertex(2 * n // 3)])
    print("voronoi:", {site: round(area, 6) for site, area in areas.items()},
          len(boundaries), "boundaries")


main()
