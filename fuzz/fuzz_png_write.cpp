// The PNG writer (io/png_write.h) on arbitrary pixels: every image written
// must read back, through libpng and zlib, as exactly the pixels written.
// The first byte picks the compressor (low bit set: the masks' run encoder
// on 8-bit gray; else libdeflate on 16-bit depth) and the next the width
// (1-64); the rest are the pixels, as many whole rows as they fill.
#include <vector>

#include "fuzz_util.h"
#include "io/png.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 3) return 0;
  const bool runs = data[0] & 1;
  const int width = 1 + data[1] % 64;
  const size_t row = static_cast<size_t>(width) * (runs ? 1 : 2);
  const int height = static_cast<int>((size - 2) / row);
  if (height == 0) return 0;
  const uint8_t* px = data + 2;
  const std::string path = pbfuzz::write_file("written.png", nullptr, 0);
  if (runs) {
    const std::vector<uint8_t> gray(px, px + row * height);
    pb::write_gray8_png(path, width, height, gray);
    int w = 0, h = 0;
    if (pb::read_gray8_png(path, &w, &h) != gray || w != width || h != height) __builtin_trap();
  } else {
    pb::DepthImage depth(width, height);  // whole millimetres: exact at depth_scale 1
    for (size_t i = 0; i < depth.z.size(); ++i) depth.z[i] = static_cast<float>((px[2 * i] << 8) | px[2 * i + 1]);
    pb::write_depth_png(path, depth, 1.0);
    const pb::DepthImage back = pb::read_depth_png(path, 1.0);
    if (back.width != width || back.height != height || back.z != depth.z) __builtin_trap();
  }
  return 0;
}
