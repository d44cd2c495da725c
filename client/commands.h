// The motiondb CLI's subcommands. Each takes the arguments after its name and returns the
// process exit code, printing results to stdout and errors to stderr.
#ifndef MOTIONDB_CLIENT_COMMANDS_H_
#define MOTIONDB_CLIENT_COMMANDS_H_

#include <string>
#include <vector>

namespace motiondb::cli {

// Offline commands.
int RunInspect(const std::vector<std::string>& args);
int RunConvert(const std::vector<std::string>& args);
int RunSpace(const std::vector<std::string>& args);
int RunProject(const std::vector<std::string>& args);

// Server commands (client/server_connection.h: --server, --token, --tls-ca, --timeout).
int RunIngest(const std::vector<std::string>& args);
int RunClips(const std::vector<std::string>& args);
int RunClip(const std::vector<std::string>& args);
int RunExport(const std::vector<std::string>& args);
int RunRemoteSpace(const std::vector<std::string>& args);  // space create|list|show|delete
int RunSearch(const std::vector<std::string>& args);
int RunInfo(const std::vector<std::string>& args);

}  // namespace motiondb::cli

#endif  // MOTIONDB_CLIENT_COMMANDS_H_
