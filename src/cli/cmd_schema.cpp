// posebench schema record: the trial record's schema as JSON (keys, types,
// which are required), for scripts that read records.jsonl (they check every
// record against it, as the reporter does). posebench schema settings: every
// recognition setting's type, default and accepted values, section by section
// (scripts/settings_reference.py writes docs/settings.md from it).
#include <iostream>

#include "cli/command.h"
#include "core/error.h"
#include "eval/record.h"
#include "recognition/settings.h"

static pb::cli::Command schema_cmd("schema", "print a schema as JSON (record, settings)", [](int argc, char** argv) {
  CLI::App app{"Prints a schema as JSON. `record`: one line of records.jsonl. `settings`: the recognition "
               "settings (YAML sections, keys, types, defaults, accepted values)."};
  std::string what;
  app.add_option("what", what, "record or settings")->required();
  PB_CLI_PARSE(app, argc, argv);
  if (what == "record") std::cout << pb::record_schema().dump(2) << "\n";
  else if (what == "settings") std::cout << pb::recognition_settings_schema().dump(2) << "\n";
  else throw pb::InputError("", "what", "unknown schema '" + what + "' (known: record, settings)");
  return 0;
});
