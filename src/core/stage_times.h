// Seconds per stage of one recognition call, in the data path's order. The
// one list of the stages: recognition fills the fields, and records, the
// CLI's JSON and text, and the reports name and read them through
// StageTimes::each.
#pragma once

namespace pb {

struct StageTimes {
  double preprocess = 0, describe = 0, match = 0, group = 0, initial_pose = 0, refine = 0, verify = 0;

  double total() const { return preprocess + describe + match + group + initial_pose + refine + verify; }

  // f(name, member) for every stage in order; the name is the key records
  // and JSON use.
  template <class F>
  static void each(F&& f) {
    f("preprocess", &StageTimes::preprocess);
    f("describe", &StageTimes::describe);
    f("match", &StageTimes::match);
    f("group", &StageTimes::group);
    f("initial_pose", &StageTimes::initial_pose);
    f("refine", &StageTimes::refine);
    f("verify", &StageTimes::verify);
  }
};

}  // namespace pb
