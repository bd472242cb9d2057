// records.jsonl of a results folder (runner/store.h ResultStore::read_file),
// as `report`, `merge` and a resumed `run` read it.
#include "fuzz_util.h"
#include "runner/store.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = pbfuzz::write_file("records.jsonl", data, size);
  pbfuzz::accept_or_reject([&] { pb::ResultStore::read_file(path); });
  return 0;
}
