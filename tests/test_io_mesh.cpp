// Mesh loading (assimp) and binary PLY writing.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "core/error.h"
#include "io/mesh_io.h"
#include "io/ply_check.h"
#include "temp_dir.h"

namespace fs = std::filesystem;
using namespace pb;

namespace {

std::string pbtest_slurp(const std::string& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

using pbtest::TempDir;

// Every undirected edge used by exactly two faces, once in each direction.
bool closed_and_oriented(const Mesh& m) {
  std::map<std::pair<int, int>, int> directed;
  for (const auto& f : m.faces)
    for (int k = 0; k < 3; ++k) directed[{f[k], f[(k + 1) % 3]}]++;
  for (const auto& [e, n] : directed) {
    if (n != 1) return false;
    auto it = directed.find({e.second, e.first});
    if (it == directed.end() || it->second != 1) return false;
  }
  return true;
}

double signed_volume(const Mesh& m) {
  double v = 0;
  for (const auto& f : m.faces)
    v += m.vertices[f[0]].cast<double>().dot(m.vertices[f[1]].cast<double>().cross(m.vertices[f[2]].cast<double>())) / 6;
  return v;
}

// An octahedron with odd coordinates (not representable exactly in decimal).
Mesh octahedron() {
  Mesh m;
  const float a = 12.345678f, b = 0.1f, c = 1e-3f;
  m.vertices = {{a, 0, 0}, {-a, 0, 0}, {0, a + b, 0}, {0, -a, c}, {0, 0, a * 2}, {0, 0, -a}};
  // +x=0 -x=1 +y=2 -y=3 +z=4 -z=5, outward counter-clockwise.
  m.faces = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4}, {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
  return m;
}

template <typename F>
void expect_mesh_error(F&& f, const std::string& file) {
  try {
    f();
    ADD_FAILURE() << "no InputError for " << file;
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), file);
    EXPECT_EQ(e.field(), "mesh");
    EXPECT_NE(std::string(e.what()).find(file), std::string::npos) << e.what();
  }
}

}  // namespace

TEST(MeshIo, PlyRoundTripKeepsVerticesFacesAndOrientation) {
  TempDir tmp;
  Mesh m = octahedron();
  ASSERT_TRUE(closed_and_oriented(m));
  ASSERT_GT(signed_volume(m), 0);
  m.compute_vertex_normals();
  const std::string p = tmp / "obj_000001.ply";
  write_ply(p, m);
  EXPECT_FALSE(fs::exists(p + ".tmp"));
  {
    std::ifstream in(p, std::ios::binary);
    std::string head((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_EQ(head.rfind("ply\nformat binary_little_endian 1.0\n", 0), 0u);
    EXPECT_NE(head.find("element vertex 6\n"), std::string::npos);
    EXPECT_NE(head.find("property float nx\n"), std::string::npos);
    EXPECT_NE(head.find("element face 8\n"), std::string::npos);
  }
  const Mesh r = load_mesh(p);
  ASSERT_EQ(r.vertices.size(), m.vertices.size());
  ASSERT_EQ(r.faces.size(), m.faces.size());
  // Map loaded vertices to the originals by exact position (floats are
  // stored bit for bit), then compare faces up to a cyclic rotation.
  std::vector<int> to_orig(r.vertices.size(), -1);
  for (size_t i = 0; i < r.vertices.size(); ++i)
    for (size_t j = 0; j < m.vertices.size(); ++j)
      if (r.vertices[i] == m.vertices[j]) to_orig[i] = static_cast<int>(j);
  for (int k : to_orig) ASSERT_GE(k, 0);
  for (const auto& f : r.faces) {
    const Eigen::Vector3i g(to_orig[f[0]], to_orig[f[1]], to_orig[f[2]]);
    bool found = false;
    for (const auto& h : m.faces)
      for (int s = 0; s < 3; ++s)
        found = found || (h[s] == g[0] && h[(s + 1) % 3] == g[1] && h[(s + 2) % 3] == g[2]);
    EXPECT_TRUE(found) << g.transpose();
  }
  EXPECT_TRUE(closed_and_oriented(r));
  EXPECT_NEAR(signed_volume(r), signed_volume(m), 1e-9 * signed_volume(m));
  EXPECT_EQ(r.vertex_normals.size(), r.vertices.size());
}

TEST(MeshIo, ObjQuadsAreTriangulatedAndObjectsMerged) {
  TempDir tmp;
  const std::string p = tmp / "two_objects.obj";
  // A unit cube as two OBJ objects (bottom+sides / top), quads, with the
  // shared corner vertices repeated in each object.
  std::ofstream(p) << "o lower\n"
                      "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
                      "f 1 4 3 2\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n"
                      "o upper\n"
                      "v 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
                      "f 9 10 11 12\n";
  const Mesh m = load_mesh(p);
  EXPECT_EQ(m.vertices.size(), 8u);  // duplicates across objects merged
  EXPECT_EQ(m.faces.size(), 12u);
  EXPECT_TRUE(closed_and_oriented(m));
  EXPECT_NEAR(signed_volume(m), 1.0, 1e-6);
}

TEST(MeshIo, StlFacetsShareVertices) {
  TempDir tmp;
  const std::string p = tmp / "tet.stl";
  // ASCII STL: per-facet normals and repeated vertices; must weld into a
  // closed tetrahedron of 4 vertices.
  const char* tris[4][3] = {{"0 0 0", "0 1 0", "1 0 0"},
                            {"0 0 0", "1 0 0", "0 0 1"},
                            {"0 0 0", "0 0 1", "0 1 0"},
                            {"1 0 0", "0 1 0", "0 0 1"}};
  std::ofstream out(p);
  out << "solid t\n";
  for (auto& t : tris) {
    out << "facet normal 0 0 0\nouter loop\n";
    for (auto* v : t) out << "vertex " << v << "\n";
    out << "endloop\nendfacet\n";
  }
  out << "endsolid t\n";
  out.close();
  const Mesh m = load_mesh(p);
  EXPECT_EQ(m.vertices.size(), 4u);
  EXPECT_EQ(m.faces.size(), 4u);
  EXPECT_TRUE(closed_and_oriented(m));
  EXPECT_NEAR(signed_volume(m), 1.0 / 6, 1e-7);
}

TEST(MeshIo, BadFilesAreInputErrors) {
  TempDir tmp;
  const std::string missing = tmp / "missing.obj";
  expect_mesh_error([&] { load_mesh(missing); }, missing);
  const std::string empty = tmp / "empty.ply";
  std::ofstream(empty).close();
  expect_mesh_error([&] { load_mesh(empty); }, empty);
  const std::string garbage = tmp / "garbage.ply";
  std::ofstream(garbage) << "ply\nformat binary_little_endian 1.0\nelement vertex 100\nproperty float x\nend_header\nxx";
  expect_mesh_error([&] { load_mesh(garbage); }, garbage);
  // A PLY header cut off before end_header made assimp loop forever.
  const std::string truncated = tmp / "truncated.ply";
  std::ofstream(truncated) << "ply\nformat ascii 1.0\nelement vertex 3\n";
  expect_mesh_error([&] { load_mesh(truncated); }, truncated);
  const std::string lines = tmp / "lines.obj";  // vertices and a polyline, no face
  std::ofstream(lines) << "v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2 3\n";
  expect_mesh_error([&] { load_mesh(lines); }, lines);
  const std::string folder = tmp / "folder.obj";
  fs::create_directory(folder);
  expect_mesh_error([&] { load_mesh(folder); }, folder);
}

// Found by fuzz/fuzz_mesh.cpp: assimp crashed (SIGSEGV) on a face whose
// vertex index is out of range. The PLY check rejects it, ascii or binary,
// and still accepts the same file with valid indices.
TEST(MeshIo, PlyFaceIndexOutOfRangeIsAnInputErrorNotACrash) {
  TempDir tmp;
  const std::string head = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                           "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
                           "0 0 0\n10 0 0\n0 10 0\n";
  const std::string good = tmp / "good.ply", bad = tmp / "bad.ply", negative = tmp / "negative.ply";
  std::ofstream(good) << head << "3 0 1 2\n";
  std::ofstream(bad) << head << "3 0 1 77777\n";
  std::ofstream(negative) << head << "3 0 -1 2\n";
  EXPECT_EQ(load_mesh(good).faces.size(), 1u);
  expect_mesh_error([&] { load_mesh(bad); }, bad);
  expect_mesh_error([&] { load_mesh(negative); }, negative);
  const std::string two = tmp / "two.ply";  // assimp's triangulation aborted on it
  std::ofstream(two) << head << "2 0 1\n";
  expect_mesh_error([&] { load_mesh(two); }, two);
  // Binary: the fuzzer's input, a mutated copy of a generated model.
  Mesh m;
  m.vertices = {{0, 0, 0}, {10, 0, 0}, {0, 10, 0}};
  m.faces = {{0, 1, 2}};
  const std::string bin = tmp / "bin.ply";
  write_ply(bin, m);
  std::string bytes = pbtest_slurp(bin);
  EXPECT_EQ(load_mesh(bin).faces.size(), 1u);
  const int32_t huge = 0x7878c6f8;
  std::memcpy(&bytes[bytes.size() - 4], &huge, 4);  // the last index of the one face
  std::ofstream(bin, std::ios::binary | std::ios::trunc) << bytes;
  expect_mesh_error([&] { load_mesh(bin); }, bin);
  // A comment that contains "end_header" does not end the header (assimp
  // read on and crashed: the second fuzzing finding).
  const std::string comment = tmp / "comment.ply";
  std::ofstream(comment) << "ply\nformat ascii 1.0\ncomment see end_header below\nelement vertex 1\n"
                            "property float x\n";
  expect_mesh_error([&] { load_mesh(comment); }, comment);
  // An element without properties holds no data, whatever its count: no
  // walk over 9999999999 empty records.
  const std::string empty_element = tmp / "empty_element.ply";
  std::ofstream(empty_element) << "ply\nformat ascii 1.0\nelement nothing 9999999999\nelement vertex 3\n"
                                  "property float x\nproperty float y\nproperty float z\nelement face 1\n"
                                  "property list uchar int vertex_indices\nend_header\n0 0 0\n10 0 0\n0 10 0\n3 0 1 2\n";
  EXPECT_NO_THROW(check_ply(empty_element, pbtest_slurp(empty_element)));
  // A count the file cannot hold is rejected before anything is allocated.
  const std::string big = tmp / "big.ply";
  std::ofstream(big) << "ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nproperty float x\n"
                        "property float y\nproperty float z\nend_header\n1234";
  expect_mesh_error([&] { load_mesh(big); }, big);
}

// The header grammar: one fuzzing finding was a binary PLY whose
// property name held NUL bytes (assimp crashed reading it). Each rule below
// is one rejected header; the valid header beside them loads.
TEST(MeshIo, PlyHeaderGrammarIsChecked) {
  TempDir tmp;
  const std::string tail = "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
                           "0 0 0\n10 0 0\n0 10 0\n3 0 1 2\n";
  const std::string xyz = "property float x\nproperty float y\nproperty float z\n";
  const auto header = [&](const std::string& first, const std::string& props) {
    return first + "format ascii 1.0\nelement vertex 3\n" + props + tail;
  };
  const std::string good = tmp / "good.ply";
  std::ofstream(good) << header("ply\n", xyz);
  EXPECT_EQ(load_mesh(good).faces.size(), 1u);
  const std::string crlf = tmp / "crlf.ply";  // CRLF line ends are valid
  std::ofstream(crlf) << header("ply\r\n", xyz);
  EXPECT_NO_THROW(check_ply(crlf, pbtest_slurp(crlf)));
  const std::string utf8 = tmp / "utf8.ply";  // UTF-8 in a comment is valid
  std::ofstream(utf8) << "ply\nformat ascii 1.0\ncomment cr\xc3\xa9\xc3\xa9\nelement vertex 3\n" << xyz << tail;
  EXPECT_EQ(load_mesh(utf8).faces.size(), 1u);
  const std::vector<std::pair<std::string, std::string>> bad = {
      {"nul_in_name", header("ply\n", "property float x\nproperty float y\nproperty float " + std::string(2, '\0') + "z\n")},
      {"magic", header("plyx\n", xyz)},
      {"comment_before_format", header("ply\ncomment first\n", xyz)},
      {"cr_inside_a_line", header("ply\n", "property float x\nproperty float\ry\nproperty float z\n")},
      {"no_z", header("ply\n", "property float x\nproperty float y\n")},
      {"list_z", header("ply\n", "property float x\nproperty float y\nproperty list uchar float z\n")},
      {"twice", header("ply\n", xyz + "property float x\n")},
      {"extra_word", header("ply\n", "property float x\nproperty float y\nproperty float z w\n")},
      {"bad_name", header("ply\n", xyz + "property float n$x\n")},
      {"bad_byte_in_name", header("ply\n", xyz + "property float caf\xc3\xa9\n")},
  };
  for (const auto& [name, text] : bad) {
    SCOPED_TRACE(name);
    const std::string p = tmp / (name + ".ply");
    std::ofstream(p, std::ios::binary) << text;
    expect_mesh_error([&] { load_mesh(p); }, p);
  }
  const std::string no_vertex = tmp / "no_vertex.ply";
  std::ofstream(no_vertex) << "ply\nformat ascii 1.0\nelement point 1\nproperty float x\nend_header\n1\n";
  expect_mesh_error([&] { load_mesh(no_vertex); }, no_vertex);
}

// The element counts come from the same header parser, from the header
// alone: a cut-off body is no error, a broken header is one naming the file
// and the field.
TEST(MeshIo, PlyElementCountsReadTheHeaderAlone) {
  const std::string header = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                             "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
  const auto counts = pb::ply_element_counts("m.ply", header + "0 0", "model");
  EXPECT_EQ(counts, (std::map<std::string, uint64_t>{{"face", 1}, {"vertex", 3}}));
  const auto cloud = pb::ply_element_counts(
      "c.ply", "ply\nformat binary_little_endian 1.0\nelement vertex 0\nproperty float x\nend_header\n", "model");
  EXPECT_EQ(cloud, (std::map<std::string, uint64_t>{{"vertex", 0}}));
  try {
    pb::ply_element_counts("b.ply", "ply\nformat ascii 1.0\nelement vertex x\nend_header\n", "model");
    FAIL() << "a bad element line was accepted";
  } catch (const pb::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("b.ply"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("model"), std::string::npos) << e.what();
  }
  EXPECT_THROW(pb::ply_element_counts("t.ply", "ply\nformat ascii 1.0\nelement vertex 3\n", "model"), pb::InputError);
}
