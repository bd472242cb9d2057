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

struct PoolOptions {
  std::string binary;    // the posebench executable
  std::string context;   // the first line every worker reads (trial.h context_json)
  std::string log_path;  // workers' stderr
  int jobs = 1;
  double timeout_s = 300;
};

// Runs the trials `inputs[i]` for every i in `pending`, calling on_record
// with each finished, crashed ("error") or timed-out ("timeout") trial's
// record, in completion order.
void run_in_workers(const PoolOptions& opt, const std::vector<TrialRecord>& inputs, std::deque<long> pending,
                    const std::function<void(long, const TrialRecord&)>& on_record);

}  // namespace pb
