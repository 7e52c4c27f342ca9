// planner_cpp HOST:PORT MESH_FILE FROM TO: the planner library's queries against a geodexd.
#include <cstdio>
#include <cstdlib>

#include "planner.h"

int main(int argc, char** argv) {
  if (argc != 5) {
    std::fprintf(stderr, "usage: %s HOST:PORT MESH_FILE FROM TO\n", argv[0]);
    return 2;
  }
  return RunPlanner(argv[1], argv[2], static_cast<uint32_t>(std::strtoul(argv[3], nullptr, 10)),
                    static_cast<uint32_t>(std::strtoul(argv[4], nullptr, 10)));
}
