// A BOP test-targets file, e.g. test_targets_bop19.json (io/bop.h
// read_test_targets).
#include "fuzz_util.h"
#include "io/bop.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = pbfuzz::write_file("test_targets.json", data, size);
  pbfuzz::accept_or_reject([&] { pb::read_test_targets(path); });
  return 0;
}
