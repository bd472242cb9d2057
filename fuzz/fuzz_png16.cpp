// Depth PNGs (io/png.h): the header probe and the 16-bit gray decoder.
#include "fuzz_util.h"
#include "io/png.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = pbfuzz::write_file("depth.png", data, size);
  pbfuzz::accept_or_reject([&] { pb::read_png_header(path); });
  pbfuzz::accept_or_reject([&] { pb::read_depth_png(path, 0.1); });
  return 0;
}
