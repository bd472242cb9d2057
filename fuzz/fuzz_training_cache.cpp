// Training cache files (recognition/model.h cache::read). The first byte
// picks the descriptor whose state the file is read as; a fuzzing build reads
// past the key and checksum comparisons (cache.cpp). A broken file must
// read as "rebuild" (false), never crash.
#include <algorithm>

#include "fuzz_util.h"
#include "recognition/model.h"
#include "recognition/registry.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  static const std::vector<std::string> names = [] {  // alphabetical, as scripts/fuzz.sh numbers them
    auto n = pb::descriptor_names();
    std::sort(n.begin(), n.end());
    return n;
  }();
  const std::string path = pbfuzz::write_file("model.bin", data + 1, size - 1);
  pb::TrainedModel m;
  m.descriptor = names[data[0] % names.size()];
  m.settings.descriptor = m.descriptor;
  pb::cache::read(path, pb::cache::Key{}, m);
  return 0;
}
