#include "client/commands.h"

#include <cstdlib>
#include <iostream>
#include <memory>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "util/cli_conventions.h"

namespace motiondb::cli {
namespace {

constexpr char kGlobalGroup[] = "Global options (before or after the command)";
constexpr char kOfflineGroup[] = "Offline commands (no server needed)";
constexpr char kServerGroup[] = "Server commands";

// The global options, in one place: on the root, and on each command that takes them (bound to
// the same variables, so either position sets them). `connection`: the server's options too.
void AddGlobalFlags(CLI::App* command, GlobalOptions* global, bool connection) {
  std::vector<CLI::Option*> added;
  if (connection) {
    ConnectionOptions& c = global->connection;
    // The environment sets the default, so that an explicit --server still wins.
    if (const char* server = std::getenv("MOTIONDB_SERVER"); server != nullptr && *server != '\0') {
      c.server = server;
    }
    added = {
        command->add_option("--server", c.server, "the server's address (or $MOTIONDB_SERVER)")
            ->type_name("ADDR")
            ->capture_default_str(),
        command->add_option("--token", c.token, "bearer token (or $MOTIONDB_TOKEN)")
            ->type_name("T"),
        command
            ->add_option("--token-file", c.token_file,
                         "the token is FILE's contents (or $MOTIONDB_TOKEN_FILE's)")
            ->type_name("FILE")
            ->check(ExistingFile()),
        command->add_option("--tls-ca", c.tls_ca, "use TLS, trusting this CA certificate")
            ->type_name("FILE")
            ->check(ExistingFile()),
        command->add_option("--timeout", c.timeout_s, "seconds each call may take")
            ->type_name("S")
            ->capture_default_str()
            ->check(NumberAbove(0)),
    };
  }
  added.push_back(command->add_flag("--json", global->json, "machine-readable output (JSON)"));
  for (CLI::Option* option : added) option->group(kGlobalGroup);
}

int ExitCode(const CLI::App& command, const absl::Status& status) {
  if (status.ok()) return 0;
  if (!status.message().empty()) {
    std::cerr << CommandPath(command) << ": " << status.message() << "\n";
  }
  return 1;
}

}  // namespace

Commands::Commands(CLI::App* root, const std::string& version) : root_(root) {
  root_->set_version_flag("--version", absl::StrCat(root_->get_name(), " ", version));
  root_->require_subcommand(0, 1);
  AddGlobalFlags(root_, &global_, /*connection=*/true);
  runners_[root_] = [this] {
    std::cerr << root_->help();
    return kUsageExitCode;
  };
}

CLI::App* Commands::AddGroup(CLI::App* parent, const std::string& name,
                             const std::string& description) {
  CLI::App* group = parent->add_subcommand(name, description)->group(kServerGroup);
  group->require_subcommand(0, 1);
  runners_[group] = [group] {
    std::vector<std::string> names;
    for (const CLI::App* sub : group->get_subcommands([](const CLI::App*) { return true; })) {
      names.push_back(sub->get_name());
    }
    return UsageError(*group, absl::StrCat("give a command: ", absl::StrJoin(names, ", ")));
  };
  return group;
}

CLI::App* Commands::AddOffline(CLI::App* parent, const std::string& name,
                               const std::string& description, bool json,
                               std::function<absl::Status()> body) {
  CLI::App* command = parent->add_subcommand(name, description)->group(kOfflineGroup);
  if (json) AddGlobalFlags(command, &global_, /*connection=*/false);
  runners_[command] = [command, body = std::move(body)] { return ExitCode(*command, body()); };
  return command;
}

CLI::App* Commands::AddServer(CLI::App* parent, const std::string& name,
                              const std::string& description,
                              std::function<absl::Status(const ServerConnection&)> body) {
  CLI::App* command = parent->add_subcommand(name, description)->group(kServerGroup);
  AddGlobalFlags(command, &global_, /*connection=*/true);
  runners_[command] = [this, command, body = std::move(body)] {
    const absl::StatusOr<ServerConnection> connection =
        ServerConnection::Connect(global_.connection);
    if (!connection.ok()) return UsageError(*command, std::string(connection.status().message()));
    return ExitCode(*command, body(*connection));
  };
  return command;
}

CLI::App* Commands::AddHelp() {
  auto words = std::make_shared<std::vector<std::string>>();
  CLI::App* help =
      root_->add_subcommand("help", "the commands, or one command's flags")->group("Help");
  help->add_option("COMMAND", *words, "a command, e.g. search or space create");
  runners_[help] = [this, help, words] {
    const CLI::App* at = root_;
    for (const std::string& word : *words) {
      const std::vector<const CLI::App*> named =
          at->get_subcommands([&](const CLI::App* sub) { return sub->check_name(word); });
      if (named.empty()) {
        return UsageError(*help,
                          absl::StrCat("unknown command '", absl::StrJoin(*words, " "), "'"));
      }
      at = named.front();
    }
    std::cout << at->get_formatter()->make_help(at, CommandPath(*at), CLI::AppFormatMode::Normal);
    return 0;
  };
  return help;
}

int Commands::Run() const { return runners_.at(&ChosenCommand(*root_))(); }

absl::Status ReportedFailure() { return absl::UnknownError(""); }

void AddFrameRangeFlags(CLI::App* command, const std::string& what, FrameRangeFlags* range) {
  command->add_option("--from", range->from, absl::StrCat("first frame of ", what))
      ->type_name("F")
      ->default_str("0")
      ->check(WholeAtLeast(0));
  command->add_option("--to", range->to, absl::StrCat("last frame of ", what, ", inclusive"))
      ->type_name("T")
      ->default_str("last")
      ->check(WholeAtLeast(0));
}

}  // namespace motiondb::cli
