#!/usr/bin/python3
"""A planner's queries through the geodex Python package, as examples/planner_cpp does in C++.

usage: planner.py HOST:PORT MESH_FILE FROM TO

Line 1: the exact geodesic length from vertex FROM to vertex TO, alone (%.17g); then the path's
points with their simplices, a distance matrix between waypoints (a numpy array), the 2 nearest
waypoints of each, and a call whose timeout is too short (DeadlineExceededError; the same client
then answers).
"""
import os
import sys

import geodex
from geodex import vertex


def main():
    target, mesh_file, start, end = sys.argv[1], sys.argv[2], int(sys.argv[3]), int(sys.argv[4])
    with geodex.GeodexClient(target, timeout=60, wait_for_ready=True) as client:
        mesh = client.upload(mesh_file)  # once, by content hash; again if the server loses it
        path = client.shortest_path(mesh.name, vertex(start), vertex(end))
        print("%.17g" % path.length)
        print("path: %d points" % len(path.points))
        for point in path.points:
            print("  ", point.simplex)
        middle = path.points[len(path.points) // 2].simplex
        waypoints = [vertex(start), geodex.edge_point(*middle[1:]) if middle[0] == "e"
                     else vertex(middle[1]) if middle[0] == "v" else geodex.face_point(*middle[1:]),
                     vertex(end)]
        matrix = client.distance_matrix(mesh.name, waypoints, waypoints)
        print("matrix %d x %d:" % matrix.shape)
        print(matrix)
        print("2 nearest:")
        print(client.distance_matrix(mesh.name, waypoints, waypoints, k_nearest=2))
        unique = 1e9 + os.getpid()  # a field of its own: a cached one could be back in any time
        try:
            client.distance_field(mesh.name, [vertex(start)], timeout=1e-6, max_distance=unique)
            print("deadline 1 us: answered")
            return 1
        except geodex.DeadlineExceededError as error:
            print("deadline 1 us:", error)
        field = client.distance_field(mesh.name, [vertex(start)], timeout=60, max_distance=unique)
        print("deadline 60 s: %d distances" % len(field.distances))
    return 0


sys.exit(main())
