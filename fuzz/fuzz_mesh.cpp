// Meshes (io/mesh_io.h load_mesh: our pre-checks, then assimp). The first
// byte picks the file extension assimp sees: ply, obj, stl or off.
#include "fuzz_util.h"
#include "io/mesh_io.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  static const char* kExt[4] = {"ply", "obj", "stl", "off"};
  const std::string path = pbfuzz::write_file(std::string("mesh.") + kExt[data[0] % 4], data + 1, size - 1);
  pbfuzz::accept_or_reject([&] { pb::load_mesh(path); });
  return 0;
}
