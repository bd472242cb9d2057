// Mesh loading through assimp and binary PLY writing.
#include "io/mesh_io.h"

#include <assimp/Importer.hpp>
#include <algorithm>
#include <cctype>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <sstream>
#include <sys/stat.h>
#include <unordered_map>

#include "core/error.h"
#include "core/hash.h"
#include "io/ply_check.h"
#include "io/png.h"

namespace pb {

namespace {

struct VertexKey {
  float x, y, z;
  bool operator==(const VertexKey& o) const {
    return std::memcmp(this, &o, sizeof(VertexKey)) == 0;
  }
};
// The map only looks vertices up (indices follow first appearance, the map
// is never iterated), so the hash does not affect the output.
struct VertexKeyHash {
  size_t operator()(const VertexKey& k) const {
    static_assert(sizeof(VertexKey) == 3 * sizeof(float), "VertexKey must have no padding");
    return static_cast<size_t>(Fnv1a64().bytes(&k, sizeof k).digest());
  }
};

void collect(const aiScene* scene, const aiNode* node, const aiMatrix4x4& parent,
             std::vector<Vec3f>* verts, std::vector<Eigen::Vector3i>* faces,
             std::unordered_map<VertexKey, int, VertexKeyHash>* index) {
  const aiMatrix4x4 T = parent * node->mTransformation;
  for (unsigned m = 0; m < node->mNumMeshes; ++m) {
    const aiMesh* mesh = scene->mMeshes[node->mMeshes[m]];
    std::vector<int> remap(mesh->mNumVertices);
    for (unsigned i = 0; i < mesh->mNumVertices; ++i) {
      const aiVector3D p = T * mesh->mVertices[i];
      VertexKey k{p.x, p.y, p.z};
      if (k.x == 0.f) k.x = 0.f;  // -0 and +0 merge
      if (k.y == 0.f) k.y = 0.f;
      if (k.z == 0.f) k.z = 0.f;
      auto it = index->find(k);
      if (it == index->end()) {
        it = index->emplace(k, static_cast<int>(verts->size())).first;
        verts->emplace_back(k.x, k.y, k.z);
      }
      remap[i] = it->second;
    }
    for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
      const aiFace& face = mesh->mFaces[f];
      if (face.mNumIndices != 3) continue;  // points and lines
      const Eigen::Vector3i tri(remap[face.mIndices[0]], remap[face.mIndices[1]], remap[face.mIndices[2]]);
      if (tri[0] == tri[1] || tri[1] == tri[2] || tri[0] == tri[2]) continue;  // degenerate after merging
      faces->push_back(tri);
    }
  }
  for (unsigned c = 0; c < node->mNumChildren; ++c) collect(scene, node->mChildren[c], T, verts, faces, index);
}

void put_u32(std::string* out, uint32_t v) {
  for (int i = 0; i < 4; ++i) out->push_back(static_cast<char>((v >> (8 * i)) & 0xff));
}
void put_f32(std::string* out, float f) {
  uint32_t v;
  std::memcpy(&v, &f, 4);
  put_u32(out, v);
}

}  // namespace

Mesh load_mesh(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) throw InputError(path, "mesh", "mesh file not found");
  if (!S_ISREG(st.st_mode)) throw InputError(path, "mesh", "not a regular file");
  {
    std::ifstream probe(path, std::ios::binary);
    if (!probe) throw InputError(path, "mesh", "mesh file is not readable");
  }
  if (st.st_size == 0) throw InputError(path, "mesh", "mesh file is empty");
  {
    // assimp loops forever on a PLY whose header never ends: check it first.
    std::string ext = path.size() >= 4 ? path.substr(path.size() - 4) : "";
    for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    if (ext == ".ply") {
      // assimp loops forever on a header that never ends and crashes on face
      // indices out of range (found by fuzzing): check the structure first.
      std::ifstream in(path, std::ios::binary);
      const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
      check_ply(path, bytes);
    }
  }

  Assimp::Importer importer;
  // Drop point and line primitives; keep triangles only.
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE, aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  // ValidateDataStructure runs first, on what the importer produced: an
  // importer that misreads a malformed file into inconsistent data (face
  // indices past the vertices) is stopped there, before the post-processing
  // steps that crashed on it (found by fuzzing).
  const aiScene* scene = importer.ReadFile(path, aiProcess_ValidateDataStructure | aiProcess_Triangulate |
                                                     aiProcess_JoinIdenticalVertices | aiProcess_SortByPType);
  if (!scene) throw InputError(path, "mesh", std::string("cannot read mesh: ") + importer.GetErrorString());
  if (!scene->mRootNode || scene->mNumMeshes == 0) throw InputError(path, "mesh", "file contains no mesh");

  // Merge all meshes of the file (node transforms applied) into one, joining
  // vertices with identical positions: assimp's JoinIdenticalVertices keeps
  // vertices apart when their normals differ (STL, flat-shaded OBJ).
  Mesh out;
  std::unordered_map<VertexKey, int, VertexKeyHash> index;
  collect(scene, scene->mRootNode, aiMatrix4x4(), &out.vertices, &out.faces, &index);
  if (out.faces.empty()) throw InputError(path, "mesh", "mesh has no triangles");
  for (const auto& v : out.vertices)
    if (!v.allFinite()) throw InputError(path, "mesh", "mesh has a non-finite vertex coordinate");
  out.compute_vertex_normals();
  return out;
}

void write_ply(const std::string& path, const Mesh& mesh) {
  const bool normals = !mesh.vertex_normals.empty() && mesh.vertex_normals.size() == mesh.vertices.size();
  std::ostringstream h;
  h << "ply\nformat binary_little_endian 1.0\ncomment posebench model, units: mm\n"
    << "element vertex " << mesh.vertices.size() << "\n"
    << "property float x\nproperty float y\nproperty float z\n";
  if (normals) h << "property float nx\nproperty float ny\nproperty float nz\n";
  h << "element face " << mesh.faces.size() << "\n"
    << "property list uchar int vertex_indices\nend_header\n";
  std::string out = h.str();
  out.reserve(out.size() + mesh.vertices.size() * (normals ? 24 : 12) + mesh.faces.size() * 13);
  const int n = static_cast<int>(mesh.vertices.size());
  for (size_t i = 0; i < mesh.vertices.size(); ++i) {
    for (int k = 0; k < 3; ++k) put_f32(&out, mesh.vertices[i][k]);
    if (normals)
      for (int k = 0; k < 3; ++k) put_f32(&out, mesh.vertex_normals[i][k]);
  }
  for (const auto& f : mesh.faces) {
    out.push_back(3);
    for (int k = 0; k < 3; ++k) {
      if (f[k] < 0 || f[k] >= n) throw InputError(path, "mesh", "face index out of range");
      put_u32(&out, static_cast<uint32_t>(f[k]));
    }
  }
  atomic_write_bytes(path, out.data(), out.size());
}

}  // namespace pb
