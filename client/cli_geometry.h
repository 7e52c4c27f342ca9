#pragma once

// The geodex commands for the approximate geometry of a distance field (paper section 6):
// isolines, the Voronoi diagram and the Delaunay triangulation.

#include <string>

#include "cli_commands.h"

namespace geodex::cli {

// geodex isolines MESH --sources SPEC (--levels L1,L2,... | --count K) [--output FILE]
class Backend;

int RunIsolines(Backend& backend, const Args& args);
// geodex voronoi MESH --sites SPEC [--output FILE]
int RunVoronoi(Backend& backend, const Args& args);
// geodex delaunay MESH --sites SPEC [--output FILE]
int RunDelaunay(Backend& backend, const Args& args);

}  // namespace geodex::cli
