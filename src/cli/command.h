// Subcommands of the posebench binary. Each lives in its own cli/*.cpp and
// registers itself with a static Command object; main dispatches by name.
// A command parses its own arguments (CLI11) and returns the exit code.
// InputError escaping a command becomes exit code 2 with its message.
#pragma once

#include <CLI/CLI.hpp>

#include <functional>
#include <string>
#include <vector>

namespace pb::cli {

using CommandFn = std::function<int(int argc, char** argv)>;  // argv[0] = "posebench NAME"

// The running posebench executable (/proc/self/exe; "posebench" if unknown):
// what `run` starts its workers and the generator with.
std::string self_path();

struct Command {
  Command(std::string name, std::string summary, CommandFn fn);
};

struct CommandEntry {
  std::string name, summary;
  CommandFn fn;
};
std::vector<CommandEntry>& commands();

// -v / --verbose (debug: a line per trial) and -q / --quiet (warnings
// only; also sets *quiet, e.g. a command's "no progress bar") for the log
// (core/log.h); applied when parsing succeeds.
void add_log_flags(CLI::App& app, bool* quiet = nullptr);

// Parses with CLI11. Returns -1 to go on, otherwise the exit code to return:
// 0 after --help (printed), 2 after a usage error (message printed).
inline int parse(CLI::App& app, int argc, char** argv) {
  try {
    app.parse(argc, argv);
    return -1;
  } catch (const CLI::CallForHelp& e) {
    app.exit(e);
    return 0;
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return 2;
  }
}
#define PB_CLI_PARSE(app, argc, argv)                                     \
  do {                                                                    \
    const int _pb_rc = ::pb::cli::parse(app, argc, argv);                 \
    if (_pb_rc >= 0) return _pb_rc;                                       \
  } while (0)

}  // namespace pb::cli
