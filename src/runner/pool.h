// A pool of worker processes that run trials (`posebench worker`): each
// trial in its own process among `jobs`, so a crash or a time-out is
// recorded with its status and the sweep goes on. PCL-free.
#pragma once

#include <deque>
#include <functional>
#include <string>
#include <vector>

#include "eval/record.h"

namespace pb {

// OpenMP threads per worker: OMP_NUM_THREADS when the user set it (a
// positive integer), else the cores shared out among the workers,
// max(1, cores / jobs), so that jobs x threads never exceeds the cores and
// recorded times are not inflated by oversubscription.
int omp_threads_per_worker(int jobs, int host_cores);

// False in an AddressSanitizer build: ASan reserves terabytes of address
// space for its shadow memory, so an RLIMIT_AS cap would end every worker at
// start-up, and its operator new dies instead of throwing bad_alloc. There
// the memory limit is not applied (the runner says so).
extern const bool kMemoryLimitApplies;

// Called once by each worker: a trial's freed buffers stay with the process
// for the next trial. A worker runs one trial after another, and a trial's
// large buffers (the 640x480 cloud, the voxel grid's keys, the normals) are
// freed at its end; glibc gives them back to the kernel (blocks from 128 KiB
// to a few MiB come from mmap, and the heap's free top beyond about twice
// the largest such block is trimmed), so the next trial faulted every page
// in again. What ran before then decided a method's time: PPF alone on the
// table frames spent 13.9 ms in preprocessing, 9.0 ms after CVFH had grown
// the heap (results/bench/README.md, twenty-fourth round). Kept as
// latency-sensitive programs do: blocks under 64 MiB from the heap, and up to
// 1 GiB of freed heap not returned. It changes when memory goes back, never a
// result; a worker's resident size stays near its peak. glibc only (a no-op
// elsewhere and under AddressSanitizer, which has its own allocator).
void keep_freed_memory();

struct PoolOptions {
  std::string binary;    // the posebench executable
  std::string context;   // the first line every worker reads (trial.h context_json)
  std::string log_path;  // workers' stderr
  int jobs = 1;
  int omp_threads = 1;   // OMP_NUM_THREADS each worker gets (jobs x omp_threads <= cores: no oversubscription)
  double timeout_s = 300;
  long memory_limit_mb = 0;  // RLIMIT_AS of each worker (0 = none): a trial over it is "out_of_memory"
};

// Runs the trials `inputs[i]` for every i in `pending`, calling on_record
// with each finished, crashed ("error") or timed-out ("timeout") trial's
// record, in completion order.
void run_in_workers(const PoolOptions& opt, const std::vector<TrialRecord>& inputs, std::deque<long> pending,
                    const std::function<void(long, const TrialRecord&)>& on_record);

}  // namespace pb
