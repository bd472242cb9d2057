// Linked into every benchmark binary (bench/CMakeLists.txt): the runner's
// allocator policy (core/memory.h) from before main, so that a benchmark
// times recognition as a `posebench run` worker does, freed buffers kept
// for the next call rather than mapped and faulted in again. Without it
// bench_pipeline's CVFH took 20.2 ms per image instead of 16.5 ms, about
// 7,000 page faults per call (results/bench/README.md).
#include "core/memory.h"

namespace {

const bool kKept = (pb::keep_freed_memory(), true);

}  // namespace
