#pragma once

// geodex render MESH --sources SPEC [--isolines K] [--voronoi] [--delaunay] [--path A B]
//               --output out.png|.ply|.gltf [--view iso|top|bottom|front|back|left|right]
//               [--size WxH]

#include <string>

#include "cli_commands.h"

namespace geodex::cli {

int RunRender(const Args& args, const std::string& server = "");

}  // namespace geodex::cli
