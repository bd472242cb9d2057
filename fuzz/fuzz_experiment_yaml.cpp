// Experiment configs (runner/experiment.h load_experiment), as `run` reads them.
#include "fuzz_util.h"
#include "runner/experiment.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = pbfuzz::write_file("experiment.yaml", data, size);
  pbfuzz::accept_or_reject([&] { pb::load_experiment(path); });
  return 0;
}
