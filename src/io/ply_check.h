// A structural check of a PLY file before assimp reads it. assimp 5.2 loops
// forever on a header that never ends, crashes (SIGSEGV, found by
// fuzz/fuzz_mesh.cpp) on faces whose vertex indices are out of range and on
// property names holding NUL bytes, and aborts on faces of fewer than 3
// vertices; all are rejected here with an InputError naming the file and what
// is wrong.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "core/types.h"

namespace pb {

// Parses the header and walks the body of an ascii or binary PLY. Header:
// first line "ply", then the format line, no control bytes, element and property
// names of [A-Za-z0-9_.-] each declared once, a "vertex" element with scalar
// x, y and z. Body: every declared value present and, for a "face"
// element's vertex_indices / vertex_index list, at least 3 indices, each in
// [0, vertex count). InputError(path, "mesh", ...) otherwise.
void check_ply(const std::string& path, const std::string& bytes);

// The same checks, keeping the vertices' x, y and z (a PLY point cloud; faces
// may be absent). Errors name `field`.
std::vector<Vec3f> read_ply_vertices(const std::string& path, const std::string& bytes, const std::string& field);

// The element counts the header declares, by element name ("vertex",
// "face", ...), read by the same header parser; the body is not read, so
// `bytes` may be the file's beginning as long as it holds the header.
// InputError(path, field) on a header check_ply rejects.
std::map<std::string, uint64_t> ply_element_counts(const std::string& path, const std::string& bytes,
                                                   const std::string& field);

}  // namespace pb
