// posebench schema record: the trial record's schema as JSON (keys, types,
// which are required), for scripts that read records.jsonl (they check every
// record against it, as the reporter does).
#include <iostream>

#include "cli/command.h"
#include "core/error.h"
#include "eval/record.h"

static pb::cli::Command schema_cmd("schema", "print a file format's schema as JSON (record)", [](int argc,
                                                                                               char** argv) {
  CLI::App app{"Prints the schema of a posebench file format as JSON. `record`: one line of records.jsonl."};
  std::string what;
  app.add_option("what", what, "record")->required();
  PB_CLI_PARSE(app, argc, argv);
  if (what != "record") throw pb::InputError("", "what", "unknown schema '" + what + "' (known: record)");
  std::cout << pb::record_schema().dump(2) << "\n";
  return 0;
});
