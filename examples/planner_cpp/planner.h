#pragma once

// The queries a motion planner asks geodexd, in one shared library (libplanner.so).

#include <cstdint>
#include <string>

// Prints, for the mesh file `mesh_file` on the geodexd at `target`:
//   line 1: the exact geodesic length from vertex `from` to vertex `to`, alone (%.17g);
//   then the path's points with the simplex each lies on, a distance matrix between waypoints,
//   the 2 nearest waypoints of each start, a call whose own deadline is too short, an
//   asynchronous path and a cancelled asynchronous field.
// Returns a process exit code (0: every step behaved).
int RunPlanner(const std::string& target, const std::string& mesh_file, uint32_t from, uint32_t to);
