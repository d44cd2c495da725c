// A small parser for "motiondb COMMAND [ARGS] [--flag] [--option VALUE]" command lines.
#ifndef MOTIONDB_UTIL_COMMAND_LINE_H_
#define MOTIONDB_UTIL_COMMAND_LINE_H_

#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "absl/status/statusor.h"

namespace motiondb::cli {

class CommandLine {
 public:
  // Splits `args` into positionals and options. `value_options` take a value ("--fps 30" or
  // "--fps=30") and may repeat; `flags` take none. Any other "--name" is an error, and so is
  // "-o", which is read as "--out" when "out" is a value option.
  static absl::StatusOr<CommandLine> Parse(const std::vector<std::string>& args,
                                           const std::set<std::string>& value_options,
                                           const std::set<std::string>& flags);

  const std::vector<std::string>& positionals() const { return positionals_; }
  bool flag(const std::string& name) const { return flags_.count(name) > 0; }
  // The option's last value, or nullopt.
  std::optional<std::string> value(const std::string& name) const;
  // Every value the option was given, in order (options may repeat: --tag a --tag b).
  std::vector<std::string> values(const std::string& name) const;
  // The option's value as a number, nullopt when absent, an error when not a number.
  absl::StatusOr<std::optional<double>> number(const std::string& name) const;
  absl::StatusOr<std::optional<int>> integer(const std::string& name) const;

 private:
  std::vector<std::string> positionals_;
  std::set<std::string> flags_;
  std::map<std::string, std::vector<std::string>> values_;
};

}  // namespace motiondb::cli

#endif  // MOTIONDB_UTIL_COMMAND_LINE_H_
