// The motiondb CLI's commands, on CLI11. Each command registers its subcommand, its flags and
// what runs when it is chosen with `Commands`; main.cc parses the command line
// (client/cli_conventions.h) and runs the chosen command. Results go to stdout, errors to
// stderr as "motiondb COMMAND: message"; exit codes are 0, 1 for a failed command and 2 for a
// command line that cannot be run.
#ifndef MOTIONDB_CLIENT_COMMANDS_H_
#define MOTIONDB_CLIENT_COMMANDS_H_

#include <functional>
#include <map>
#include <optional>
#include <string>

#include <CLI/CLI.hpp>

#include "absl/status/status.h"
#include "client/server_connection.h"
#include "motiondb/v1/search_service.pb.h"

namespace motiondb::cli {

// The options every command line may give before the command, and each command that uses them
// after it: --server, --token, --token-file, --tls-ca, --timeout (server commands) and --json.
struct GlobalOptions {
  ConnectionOptions connection;
  bool json = false;
};

class Commands {
 public:
  // Gives `root` --version (printing "motiondb `version`") and the global options.
  Commands(CLI::App* root, const std::string& version);
  Commands(const Commands&) = delete;
  Commands& operator=(const Commands&) = delete;

  CLI::App* root() const { return root_; }
  const GlobalOptions& global() const { return global_; }

  // A command of commands (`space`, `clip`); given alone, it asks for one of them.
  CLI::App* AddGroup(CLI::App* parent, const std::string& name, const std::string& description);
  // An offline command (with `json`, it takes --json); a failure of `body` prints as
  // "motiondb COMMAND: message" and exits 1.
  CLI::App* AddOffline(CLI::App* parent, const std::string& name, const std::string& description,
                       bool json, std::function<absl::Status()> body);
  // A server command: it takes every global option; it connects and runs `body`, whose failure
  // prints and exits as an offline command's does (a connection that cannot be set up, e.g. an
  // empty token file, is a usage error).
  CLI::App* AddServer(CLI::App* parent, const std::string& name, const std::string& description,
                      std::function<absl::Status(const ServerConnection&)> body);

  // `help [COMMAND...]`: the root's usage (listing the commands), or that command's. Added
  // last, so that it is listed last.
  CLI::App* AddHelp();

  // Runs the command the parsed command line chose and returns the exit code.
  int Run() const;

 private:
  CLI::App* root_;
  GlobalOptions global_;
  std::map<const CLI::App*, std::function<int()>> runners_;
};

// A failure already told to the user (`inspect` and `ingest` report each file): the command
// exits 1 without another message.
absl::Status ReportedFailure();

// An inclusive range of a clip's frames, counted from 0 at its own rate: --from F, --to T.
struct FrameRangeFlags {
  std::optional<int> from;
  std::optional<int> to;
};
// Adds --from and --to to `command`; `what` is what they cut ("the query", "the clip").
void AddFrameRangeFlags(CLI::App* command, const std::string& what, FrameRangeFlags* range);

// The --seeds flag of `search` and `propagate` (search_command.cc): its names, and the seed
// selection one names.
inline const std::vector<std::string> kSeedNames = {"frames", "places", "windows", "shapes"};
v1::SeedSelection SeedSelectionNamed(const std::string& name);

// The commands, each in its own file (clip_commands.cc has `skeletons` too).
void AddInspect(Commands& commands);                       // inspect_command.cc
void AddConvert(Commands& commands);                       // convert_command.cc
void AddProject(Commands& commands);                       // project_command.cc
void AddSpaceBuild(Commands& commands, CLI::App* space);   // space_command.cc
void AddRemoteSpace(Commands& commands, CLI::App* space);  // remote_space_command.cc
void AddIngest(Commands& commands);                        // ingest_command.cc
void AddClipCommands(Commands& commands);                  // clip_commands.cc: clips, clip, export
void AddSearch(Commands& commands);                        // search_command.cc
void AddLabelCommands(Commands& commands);                 // label_commands.cc: label, labels
void AddJobCommands(Commands& commands);                   // job_commands.cc: propagate, jobs, job
void AddInfo(Commands& commands);                          // info_command.cc
void AddBackup(Commands& commands);                        // backup_command.cc
void AddClusterCommands(Commands& commands);               // cluster_commands.cc: cluster
// op_commands.cc: `op` and its reconstruct, interpolate, blend; the rest of `op` in
// op_edit_commands.cc (fill-gap, scale, translate, smooth) and op_detect_command.cc (detect).
void AddOpCommands(Commands& commands);
void AddOpEditCommands(Commands& commands, CLI::App* op);
void AddOpDetect(Commands& commands, CLI::App* op);

}  // namespace motiondb::cli

#endif  // MOTIONDB_CLIENT_COMMANDS_H_
