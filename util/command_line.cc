#include "util/command_line.h"

#include <charconv>
#include <cmath>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"

namespace motiondb::cli {

absl::StatusOr<CommandLine> CommandLine::Parse(const std::vector<std::string>& args,
                                               const std::set<std::string>& value_options,
                                               const std::set<std::string>& flags) {
  CommandLine line;
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& arg = args[i] == "-o" && value_options.count("out") ? "--out" : args[i];
    if (arg.size() < 3 || arg.compare(0, 2, "--") != 0) {
      line.positionals_.push_back(arg);
      continue;
    }
    std::string name = arg.substr(2);
    std::optional<std::string> inline_value;
    if (const size_t eq = name.find('='); eq != std::string::npos) {
      inline_value = name.substr(eq + 1);
      name.resize(eq);
    }
    if (flags.count(name)) {
      if (inline_value)
        return absl::InvalidArgumentError(absl::StrCat("--", name, " takes no value"));
      line.flags_.insert(name);
    } else if (value_options.count(name)) {
      if (!inline_value) {
        if (i + 1 == args.size()) {
          return absl::InvalidArgumentError(absl::StrCat("--", name, " needs a value"));
        }
        inline_value = args[++i];
      }
      line.values_[name].push_back(*inline_value);
    } else {
      return absl::InvalidArgumentError(absl::StrCat("unknown option --", name));
    }
  }
  return line;
}

std::optional<std::string> CommandLine::value(const std::string& name) const {
  const auto it = values_.find(name);
  if (it == values_.end()) return std::nullopt;
  return it->second.back();
}

std::vector<std::string> CommandLine::values(const std::string& name) const {
  const auto it = values_.find(name);
  return it == values_.end() ? std::vector<std::string>() : it->second;
}

absl::StatusOr<std::optional<double>> CommandLine::number(const std::string& name) const {
  const std::optional<std::string> text = value(name);
  if (!text) return std::nullopt;
  double result = 0;
  const auto [ptr, ec] = std::from_chars(text->data(), text->data() + text->size(), result);
  if (ec != std::errc() || ptr != text->data() + text->size() || !std::isfinite(result)) {
    return absl::InvalidArgumentError(
        absl::StrCat("--", name, " expects a number, got '", *text, "'"));
  }
  return result;
}

absl::StatusOr<std::optional<int>> CommandLine::integer(const std::string& name) const {
  const std::optional<std::string> text = value(name);
  if (!text) return std::nullopt;
  int result = 0;
  const auto [ptr, ec] = std::from_chars(text->data(), text->data() + text->size(), result);
  if (ec != std::errc() || ptr != text->data() + text->size()) {
    return absl::InvalidArgumentError(
        absl::StrCat("--", name, " expects a whole number, got '", *text, "'"));
  }
  return result;
}

}  // namespace motiondb::cli
