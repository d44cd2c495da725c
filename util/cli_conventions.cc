#include "util/cli_conventions.h"

#include <cmath>
#include <iostream>
#include <vector>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"

namespace motiondb::cli {
namespace {

// Help text starts its descriptions in this column (CLI11's 30 wraps most of our flags).
constexpr size_t kHelpColumn = 34;

// Every subcommand of `app`.
std::vector<const CLI::App*> Subcommands(const CLI::App& app) {
  return app.get_subcommands([](const CLI::App*) { return true; });
}

// Extra arguments are collected rather than thrown at, so that ParseCommandLine can say which
// command did not expect them.
void AllowExtras(CLI::App& app) {
  app.allow_extras();
  for (CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) AllowExtras(*sub);
}

std::string DescribeExtra(const CLI::App& app, const std::string& extra) {
  if (extra.size() > 1 && extra[0] == '-') {
    return absl::StrCat("unknown option ", extra.substr(0, extra.find('=')));
  }
  if (!Subcommands(app).empty()) return absl::StrCat("unknown command '", extra, "'");
  return absl::StrCat("unexpected argument '", extra, "'");
}

// A number from `text` against a lower bound; "" when it passes, else why not.
std::string CheckNumber(const std::string& text, double min, bool inclusive, bool whole) {
  double value = 0;
  if (whole) {
    int64_t integer = 0;
    if (!absl::SimpleAtoi(text, &integer)) {
      return absl::StrCat("expected a whole number, got '", text, "'");
    }
    value = static_cast<double>(integer);
  } else if (!absl::SimpleAtod(text, &value) || !std::isfinite(value)) {
    return absl::StrCat("expected a number, got '", text, "'");
  }
  if (inclusive ? value >= min : value > min) return "";
  return absl::StrCat("must be ", inclusive ? "at least " : "greater than ", min, ", got ", text);
}

}  // namespace

CLI::Validator NumberAtLeast(double min) {
  return CLI::Validator(
      [min](std::string& text) { return CheckNumber(text, min, /*inclusive=*/true, false); }, "");
}

CLI::Validator NumberAbove(double min) {
  return CLI::Validator(
      [min](std::string& text) { return CheckNumber(text, min, /*inclusive=*/false, false); }, "");
}

CLI::Validator WholeAtLeast(int64_t min) {
  return CLI::Validator(
      [min](std::string& text) {
        return CheckNumber(text, static_cast<double>(min), /*inclusive=*/true, /*whole=*/true);
      },
      "");
}

CLI::Validator ExistingFile() { return CLI::ExistingFile.description(""); }

CLI::Option* OneOf(CLI::Option* option, const std::vector<std::string>& choices) {
  return option->type_name(absl::StrJoin(choices, "|"))
      ->check(CLI::IsMember(choices).description(""));
}

const CLI::App& ChosenCommand(const CLI::App& app) {
  const std::vector<CLI::App*> chosen = app.get_subcommands();
  return chosen.empty() ? app : ChosenCommand(*chosen.front());
}

std::string CommandPath(const CLI::App& app) {
  const CLI::App* parent = app.get_parent();
  return parent == nullptr ? app.get_name()
                           : absl::StrCat(CommandPath(*parent), " ", app.get_name());
}

int UsageError(const CLI::App& app, const std::string& message) {
  const std::string path = CommandPath(app);
  std::cerr << path << ": " << message << "\nrun '" << path << " --help' for usage\n";
  return kUsageExitCode;
}

std::optional<int> ParseCommandLine(CLI::App& app, int argc, const char* const* argv) {
  AllowExtras(app);
  app.get_formatter()->column_width(kHelpColumn);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& error) {
    // Help and the version are "errors" with exit code 0, printed to stdout.
    if (error.get_exit_code() == static_cast<int>(CLI::ExitCodes::Success)) return app.exit(error);
    return UsageError(ChosenCommand(app), error.what());
  }
  // What no command on the way down expected, blamed on the command it followed.
  for (const CLI::App* at = &app; at != nullptr;) {
    if (const std::vector<std::string> extras = at->remaining(); !extras.empty()) {
      return UsageError(*at, DescribeExtra(*at, extras.front()));
    }
    const std::vector<CLI::App*> chosen = at->get_subcommands();
    at = chosen.empty() ? nullptr : chosen.front();
  }
  return std::nullopt;
}

absl::StatusOr<std::pair<std::string, double>> ParseJointValue(const std::string& text,
                                                               const std::string& flag) {
  const size_t equals = text.rfind('=');
  double value = 0;
  if (equals == std::string::npos || equals == 0 ||
      !absl::SimpleAtod(text.substr(equals + 1), &value)) {
    return absl::InvalidArgumentError(
        absl::StrCat(flag, ": expected JOINT=NUMBER, got '", text, "'"));
  }
  return std::make_pair(text.substr(0, equals), value);
}

}  // namespace motiondb::cli
