#include <CLI/CLI.hpp>
#include <iostream>

#include "cli/command.h"

static pb::cli::Command cmd("version", "print the version", [](int argc, char** argv) {
  CLI::App app{"print the posebench version"};
  PB_CLI_PARSE(app, argc, argv);
  std::cout << "posebench 0.1.0\n";
  return 0;
});
