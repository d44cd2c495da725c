// What the `motiondb op` commands (EditService, issue 16) share: the space, where the result
// goes (-o FILE, --store NAME, --tag T), the scope of an edit (the gate of thesis fig. 5.2 and
// chosen dimensions), joint limits and selective blending (5.7), the parsing of their values,
// and the report of a result.
#ifndef MOTIONDB_CLIENT_OP_FLAGS_H_
#define MOTIONDB_CLIENT_OP_FLAGS_H_

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "absl/status/statusor.h"
#include "client/server_connection.h"
#include "motiondb/v1/edit_service.pb.h"

namespace motiondb::cli {

// The help of a clip argument and of a pose argument or option.
inline constexpr char kOpClipHelp[] =
    "the clip: ID, ID:FROM-TO or ID:FRAME (frames at its own rate)";
inline constexpr char kOpPoseHelp[] = "a pose: ID:FRAME, or ID:FROM-TO for the mean of a range";

// A required clip range argument NAME (ID, ID:FROM-TO or ID:FRAME) into `spec`.
void AddClipArgument(CLI::App* command, const std::string& name, std::string* spec,
                     const std::string& help);

struct OpOutputFlags {
  std::string space;
  std::string out;  // -o: the BVH file; "-" for standard output; empty: not written
  std::string store;
  std::vector<std::string> tags;
};

// --space (required), -o/--out, --store and --tag.
void AddOpOutputFlags(CLI::App* command, OpOutputFlags* flags);
void SetOutput(const OpOutputFlags& flags, v1::EditOutput* output);

struct ScopeFlags {
  std::vector<double> gate;  // T0,T1 seconds from the clip's frame 0
  double lead_in = 0.0;
  double lead_out = 0.0;
  std::vector<int> dims;
  std::vector<std::string> freeze;         // joints
  std::vector<std::string> joint_weights;  // JOINT=W
  std::vector<std::string> max_angles;     // JOINT=RAD
  std::optional<double> limit_margin;
};

// --gate T0,T1, --lead-in S, --lead-out S, --only-dims D,..., --freeze J, --joint-weight J=W,
// --max-angle J=RAD, --limit-from-source MARGIN.
void AddScopeFlags(CLI::App* command, ScopeFlags* flags);
absl::Status SetScope(const ScopeFlags& flags, v1::EditScope* scope,
                      v1::JointConstraints* constraints);

// The command-line words for the server's field names: the output's and scope's flags, `more`
// (e.g. {"dims", "--dims"}), and for each of `ranges` (a field and the argument that set it,
// {"clip", "12:40-300"}) its frames told as "12:40-300: frame 999" (and an indexed field,
// "poses[0]", as the argument); with `scope`, each of its dimensions as --only-dims.
FlagNames OpFlagNames(FlagNames more, const FlagNames& ranges, const ScopeFlags* scope = nullptr);

// "X,Y" as two numbers; INVALID_ARGUMENT naming `what` otherwise.
absl::StatusOr<std::pair<double, double>> ParsePoint(const std::string& text,
                                                     const std::string& what);

// Writes the BVH where -o says, then prints the result: with --json one object (the result's
// frames, fps, file and stored clip, and `extra`'s keys), else a line for the file, one for the
// stored clip, and `print` for the rest.
absl::Status ReportResult(const v1::EditResult& result, const OpOutputFlags& flags, bool json,
                          nlohmann::json extra, const std::function<void()>& print);

}  // namespace motiondb::cli

#endif  // MOTIONDB_CLIENT_OP_FLAGS_H_
