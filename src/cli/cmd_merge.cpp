// posebench merge DIR [FROM...]: shard records into DIR/records.jsonl.
#include <iostream>

#include "cli/command.h"
#include "runner/merge.h"

static pb::cli::Command merge_cmd(
    "merge", "merge the shards of a sharded run (run --shard I/N) into DIR/records.jsonl", [](int argc, char** argv) {
      CLI::App app{"Merges DIR/shards/*.records.jsonl (and the records of each FROM folder of the same "
                   "experiment) into DIR/records.jsonl, in canonical trial order. A trial recorded twice keeps a "
                   "finished record over a failed one, then the first found (DIR's own records, then shards by "
                   "N and I, then FROM folders in order); duplicates and missing trials are listed. Records of "
                   "another experiment: exit 2, nothing written."};
      std::string dir;
      std::vector<std::string> from;
      bool require_complete = false;
      app.add_option("dir", dir, "results folder of the sharded run")->required();
      app.add_option("from", from, "more results folders of the same experiment to merge in");
      app.add_flag("--require-complete", require_complete, "exit 1 when trials are missing after the merge");
      pb::cli::add_log_flags(app);
      PB_CLI_PARSE(app, argc, argv);
      const pb::MergeReport rep = pb::merge_results(dir, from);
      for (const auto& s : rep.sources) std::cout << "  " << s.records << " records from " << s.file << "\n";
      std::cout << "merged " << rep.records << " of " << rep.trials << " trials into " << dir << "/records.jsonl";
      if (!rep.duplicate_keys.empty())
        std::cout << "; " << rep.duplicate_keys.size() << " recorded more than once (one kept)";
      std::cout << "\n";
      const auto list = [](const char* what, const std::vector<std::string>& keys) {
        if (keys.empty()) return;
        std::cout << keys.size() << " " << what << ":\n";
        for (size_t i = 0; i < keys.size() && i < 20; ++i) std::cout << "  " << keys[i] << "\n";
        if (keys.size() > 20) std::cout << "  ... and " << keys.size() - 20 << " more\n";
      };
      list("duplicates whose outcomes differ beyond timing (not deterministic?)", rep.differing_keys);
      list("trials missing (rerun: posebench run EXPERIMENT --out DIR [--shard I/N])", rep.missing_keys);
      return require_complete && !rep.missing_keys.empty() ? 1 : 0;
    });
