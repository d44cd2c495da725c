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


}  // namespace motiondb::cli

#endif  // MOTIONDB_CLIENT_COMMANDS_H_
