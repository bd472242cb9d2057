// `posebench merge DIR [FROM...]`: the records of a sharded run (and of
// other results folders of the same experiment, e.g. copied back from the
// local disks of cluster nodes) merged into DIR/records.jsonl. PCL-free.
#pragma once

#include <string>
#include <vector>

namespace pb {

struct MergeSource {
  std::string file;    // a records file
  size_t records = 0;  // complete records read from it
};

struct MergeReport {
  std::vector<MergeSource> sources;  // in the order that breaks ties
  size_t trials = 0;                 // of the experiment (DIR/trials.json)
  size_t records = 0;                // in DIR/records.jsonl after the merge
  // Keys recorded more than once with different contents (a shard rerun
  // with another N, a run without --shard beside shards; a record merged
  // earlier and its shard's copy are the same record, not a duplicate). One record is kept: a finished one
  // (status ok or no_hypothesis) before a failed one (error, timeout),
  // then the first in source order.
  std::vector<std::string> duplicate_keys;
  // Of those, keys whose finished records disagree beyond the timing fields
  // (wall_s, train_s, train_from_cache, times) and the scene folder's path
  // (dataset): a trial that is not deterministic, worth a look.
  std::vector<std::string> differing_keys;
  std::vector<std::string> missing_keys;  // trials with no record, in trial order
};

// Merges DIR/records.jsonl, DIR/shards/*.records.jsonl and the same files of
// each FROM folder into DIR/records.jsonl, in the trial order of
// DIR/trials.json; written to a temporary file and renamed into place, so a
// reader sees the old or the new file, never a part. The shard files stay
// (a shard still running may append more; merging again is harmless).
//
// Everything is checked before anything is written: InputError (exit 2),
// DIR untouched, if a FROM folder or a shard header (DIR/shards/I-of-N.json)
// names another experiment hash, a shard file has no header, a record's key
// is not a trial of this experiment, a record is malformed, or another
// process is writing DIR/records.jsonl (a run without --shard, a merge).
MergeReport merge_results(const std::string& dir, const std::vector<std::string>& from = {});

}  // namespace pb
