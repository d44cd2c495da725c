// The command-line conventions of every motiondb program (the motiondb CLI, the benchmark
// programs), on CLI11: `--help` prints the generated usage of the command it follows, with every
// flag and its default, and `--version` the version, both to stdout with exit code 0; an unknown
// option, a bad or missing value prints one line, "PROGRAM COMMAND: what is wrong", then
// "run 'PROGRAM COMMAND --help' for usage", to stderr and exits 2.
#ifndef MOTIONDB_UTIL_CLI_CONVENTIONS_H_
#define MOTIONDB_UTIL_CLI_CONVENTIONS_H_

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <CLI/CLI.hpp>

#include "absl/status/statusor.h"

namespace motiondb::cli {

// The exit code of a command line that cannot be run as given.
inline constexpr int kUsageExitCode = 2;

// Value checks whose messages name what was expected and what was given (CLI11 prefixes the
// flag): a number, finite and at least `min` (or above `min` with `NumberAbove`); a whole
// number at least `min`.
CLI::Validator NumberAtLeast(double min);
CLI::Validator NumberAbove(double min);
CLI::Validator WholeAtLeast(int64_t min);
// An existing file (CLI::ExistingFile without its "FILE" in the help's value names).
CLI::Validator ExistingFile();
// Makes `option` take one of `choices`, named "a|b|c" in the help; returns it.
CLI::Option* OneOf(CLI::Option* option, const std::vector<std::string>& choices);

// "JOINT=VALUE" given to `flag` as a joint name and a number; the error names the flag.
absl::StatusOr<std::pair<std::string, double>> ParseJointValue(const std::string& text,
                                                               const std::string& flag);

// Parses `argv` into `app` and its subcommands. Returns nullopt when the program should go on
// (`ChosenCommand(app)` is then the command to run), or the exit code when it must stop: 0
// after printing the help or the version, 2 after a usage error.
std::optional<int> ParseCommandLine(CLI::App& app, int argc, const char* const* argv);

// The deepest subcommand the command line named (`app` itself when it named none).
const CLI::App& ChosenCommand(const CLI::App& app);
// "motiondb space create": the program's and the commands' names down to `app`.
std::string CommandPath(const CLI::App& app);
// Prints "PATH: message" and the hint to PATH's --help to stderr; returns kUsageExitCode.
int UsageError(const CLI::App& app, const std::string& message);

}  // namespace motiondb::cli

#endif  // MOTIONDB_UTIL_CLI_CONVENTIONS_H_
