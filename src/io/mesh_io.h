// Mesh files: anything assimp reads (OBJ, PLY, STL, OFF, ...) in, PLY out.
#pragma once

#include <string>

#include "core/types.h"

namespace pb {

// Loads and triangulates every mesh of the file into one Mesh, merging
// duplicate vertices. Throws InputError(path, "mesh", ...) when the file is
// missing, unreadable, or has no triangles.
Mesh load_mesh(const std::string& path);

// Writes a binary little-endian PLY with vertex positions (and normals when
// present) and triangle faces, as BOP's models/obj_XXXXXX.ply (mm).
void write_ply(const std::string& path, const Mesh& mesh);

}  // namespace pb
