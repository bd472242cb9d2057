// A structural check of a PLY file before assimp reads it: assimp 5.2 loops
// forever on a header that never ends and crashes (SIGSEGV, found by
// fuzz/fuzz_mesh.cpp) on faces whose vertex indices are out of range and
// aborts on faces of fewer than 3 vertices, so all are rejected here with an InputError naming the file and what is wrong.
#pragma once

#include <string>

namespace pb {

// Parses the header (format, elements, properties) and walks the body of an
// ascii or binary PLY: every declared value present and, for a "face"
// element's vertex_indices / vertex_index list, at least 3 indices, each in
// [0, vertex count). InputError(path, "mesh", ...) otherwise.
void check_ply(const std::string& path, const std::string& bytes);

}  // namespace pb
