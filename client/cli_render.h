#pragma once

// geodex render MESH --sources SPEC [--isolines K] [--voronoi] [--delaunay] [--path A B]
//               --output out.png|.ply|.gltf [--view iso|top|bottom|front|back|left|right]
//               [--size WxH]

#include <string>

#include "cli_commands.h"

namespace geodex::cli {

class Backend;

int RunRender(Backend& backend, const Args& args);

}  // namespace geodex::cli
