// BOP results files (eval/bop_csv.h read_bop_results_csv, what `posebench
// score` reads from any tool) and the file-name convention. The first byte
// picks the file name: one that follows METHOD_DATASET-SPLIT.csv or not.
#include "eval/bop_csv.h"
#include "fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  const std::string path = pbfuzz::write_file(data[0] & 1 ? "method_dataset-test.csv" : "results.csv", data + 1, size - 1);
  pb::parse_bop_results_filename(path);
  pbfuzz::accept_or_reject([&] { pb::read_bop_results_csv(path); });
  return 0;
}
