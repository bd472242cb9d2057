// A BOP dataset's camera.json (io/bop.h read_camera_json).
#include "fuzz_util.h"
#include "io/bop.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = pbfuzz::write_file("camera.json", data, size);
  double scale = 0;
  pbfuzz::accept_or_reject([&] { pb::read_camera_json(path, &scale); });
  return 0;
}
