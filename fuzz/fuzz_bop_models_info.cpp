// A BOP dataset's models/models_info.json (io/bop.h read_models_info).
#include "fuzz_util.h"
#include "io/bop.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = pbfuzz::write_file("models_info.json", data, size);
  pbfuzz::accept_or_reject([&] { pb::read_models_info(path); });
  return 0;
}
