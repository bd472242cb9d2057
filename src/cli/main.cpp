// posebench: one binary, one subcommand per job (generate, render-views,
// export-pcd, recognize, run, report, ...).
#include <unistd.h>

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <memory>
#include <iostream>

#include "cli/command.h"
#include "core/error.h"
#include "core/log.h"
#include "core/memory.h"

namespace pb::cli {

std::vector<CommandEntry>& commands() {
  static std::vector<CommandEntry> c;
  return c;
}

std::string self_path() {
  char buf[4096];
  const ssize_t n = readlink("/proc/self/exe", buf, sizeof buf - 1);
  if (n <= 0) return "posebench";
  buf[n] = '\0';
  return buf;
}

void add_log_flags(CLI::App& app, bool* quiet) {
  auto verbose = std::make_shared<bool>(false), q = std::make_shared<bool>(false);
  app.add_flag("-v,--verbose", *verbose, "log more: a line per finished trial");
  app.add_flag("-q,--quiet", *q, "log warnings and errors only (no progress)");
  app.parse_complete_callback([verbose, q, quiet] {
    if (quiet) *quiet = *q;
    pb::set_log_level(*q ? pb::LogLevel::warn : *verbose ? pb::LogLevel::debug : pb::LogLevel::info);
  });
}

Command::Command(std::string name, std::string summary, CommandFn fn) {
  commands().push_back({std::move(name), std::move(summary), std::move(fn)});
}

}  // namespace pb::cli

static void usage() {
  auto cmds = pb::cli::commands();
  std::sort(cmds.begin(), cmds.end(), [](const auto& a, const auto& b) { return a.name < b.name; });
  std::cout << "posebench: recognition and 6-DoF pose estimation benchmark\n\n"
               "usage: posebench COMMAND [options]   (posebench COMMAND --help)\n\ncommands:\n";
  for (const auto& c : cmds) std::printf("  %-14s %s\n", c.name.c_str(), c.summary.c_str());
}

int main(int argc, char** argv) {
  // Every command times recognition as the runner's workers do (`recognize`
  // over a folder of frames calls it once per frame): freed buffers stay
  // with the process.
  pb::keep_freed_memory();
  if (argc < 2 || std::string(argv[1]) == "--help" || std::string(argv[1]) == "-h") {
    usage();
    return argc < 2 ? pb::kExitInputError : 0;
  }
  const std::string name = argv[1];
  for (const auto& c : pb::cli::commands()) {
    if (c.name != name) continue;
    std::string prog = std::string("posebench ") + name;
    std::vector<char*> args(argv + 1, argv + argc);
    args[0] = prog.data();
    try {
      return c.fn(static_cast<int>(args.size()), args.data());
    } catch (const pb::InputError& e) {
      std::cerr << "posebench " << name << ": error: " << e.what() << "\n";
      return pb::kExitInputError;
    } catch (const CLI::ParseError& e) {
      std::cerr << "posebench " << name << ": error: " << e.what() << "\n";
      return pb::kExitInputError;
    } catch (const std::filesystem::filesystem_error& e) {
      // A path the OS refuses (a name too long, a component that is a file,
      // no permission): the user's input, named by the error itself.
      std::cerr << "posebench " << name << ": error: " << e.path1().string() << ": " << e.code().message() << "\n";
      return pb::kExitInputError;
    } catch (const std::exception& e) {
      std::cerr << "posebench " << name << ": internal error: " << e.what() << "\n";
      return pb::kExitFailure;
    }
  }
  std::cerr << "posebench: error: unknown command '" << name << "' (posebench --help lists them)\n";
  return pb::kExitInputError;
}
