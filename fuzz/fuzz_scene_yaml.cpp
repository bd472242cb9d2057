// Scene generator configs (scenes/scene_config.h load_scene_settings).
#include "fuzz_util.h"
#include "scenes/scene_config.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = pbfuzz::write_file("scene.yaml", data, size);
  pbfuzz::accept_or_reject([&] { pb::load_scene_settings(path); });
  return 0;
}
