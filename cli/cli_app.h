// Option parsing shared by the rdm verbs (CLI11): `--help` prints every option with its
// default to stdout; an unknown option or a malformed value is a usage error (exit code 2)
// reported as "rdm VERB: unknown option --x".
#pragma once

#include <CLI/CLI.hpp>

#include <optional>
#include <string>

#include "commands.h"

namespace rdm::cli {

// A verb's App: every option shows its default value in --help.
class VerbApp : public CLI::App {
 public:
  VerbApp(const std::string& verb, const std::string& description);
};

// Parses `args` into `app`. Returns nullopt to continue, or the exit code to return now:
// 0 after printing --help, 2 after reporting a usage error on stderr. A number outside its
// option's range is reported in words (number_checks.h).
std::optional<int> parseArgs(CLI::App& app, const Args& args);

// Prints "rdm VERB: message" on stderr and returns `code`.
int fail(const std::string& verb, const std::string& message, int code = 1);

// "rdm <build id>": the same build id the daemon reports in its jobs.
std::string versionText();

}  // namespace rdm::cli
