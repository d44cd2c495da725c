// motiondb: the command-line client (client/commands.h).
#include <CLI/CLI.hpp>

#include "client/commands.h"
#include "util/cli_conventions.h"

int main(int argc, char** argv) {
  CLI::App app(
      "motiondb: query-by-example motion search. Offline commands work on BVH files and space\n"
      "files; server commands talk to motiondb-server over gRPC.",
      "motiondb");
  app.footer(
      "Frame numbers count from 0 at the clip's own rate; ranges are inclusive. The token is\n"
      "--token, else --token-file's contents, else $MOTIONDB_TOKEN, else the contents of the\n"
      "file $MOTIONDB_TOKEN_FILE (a file's surrounding whitespace ignored).\n"
      "Run 'motiondb help COMMAND' or 'motiondb COMMAND --help' for a command's flags.");
  motiondb::cli::Commands commands(&app, MOTIONDB_VERSION);
  motiondb::cli::AddInspect(commands);
  motiondb::cli::AddConvert(commands);
  motiondb::cli::AddProject(commands);
  motiondb::cli::AddIngest(commands);
  motiondb::cli::AddClipCommands(commands);
  CLI::App* space =
      commands.AddGroup(&app, "space", "spaces: build (offline), create, list, show, delete");
  motiondb::cli::AddSpaceBuild(commands, space);
  motiondb::cli::AddRemoteSpace(commands, space);
  motiondb::cli::AddSearch(commands);
  motiondb::cli::AddLabelCommands(commands);
  motiondb::cli::AddJobCommands(commands);
  motiondb::cli::AddInfo(commands);
  motiondb::cli::AddBackup(commands);
  motiondb::cli::AddClusterCommands(commands);
  motiondb::cli::AddOpCommands(commands);
  commands.AddHelp();
  if (const std::optional<int> exit_code = motiondb::cli::ParseCommandLine(app, argc, argv)) {
    return *exit_code;
  }
  return commands.Run();
}
