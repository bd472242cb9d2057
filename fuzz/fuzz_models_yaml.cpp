// The model registry (models/models.yaml; models/registry.h ModelRegistry::load).
#include "fuzz_util.h"
#include "models/registry.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = pbfuzz::write_file("models.yaml", data, size);
  pbfuzz::accept_or_reject([&] { pb::ModelRegistry::load(path); });
  return 0;
}
