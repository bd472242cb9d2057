// A pool of worker processes that run trials (`posebench worker`): each
// trial in its own process among `jobs`, so a crash or a time-out is
// recorded with its status and the sweep goes on. PCL-free.
#pragma once

#include <deque>
#include <functional>
#include <string>
#include <vector>

#include "core/memory.h"
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

// keep_freed_memory() (core/memory.h): called once by each worker.

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
