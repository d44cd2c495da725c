// motiondb project FILE.bvh --space SPACE.mcs [--dims 3] [--csv]
#include <iostream>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "client/commands.h"
#include "core/bvh/bvh_reader.h"
#include "core/space/motion_space.h"
#include "core/space/space_serialization.h"
#include "util/command_line.h"
#include "util/status_macros.h"
#include "util/status_prefix.h"

namespace motiondb::cli {
namespace {

constexpr char kUsage[] =
    "usage: motiondb project FILE.bvh --space SPACE.mcs [--dims 3] [--csv]\n"
    "  prints the clip's motion curve: one line per frame at the space's rate, the frame, its\n"
    "  time in seconds, then its first --dims coordinates\n";

absl::Status Project(const CommandLine& line) {
  if (line.positionals().size() != 1) {
    return absl::InvalidArgumentError("expected one BVH file");
  }
  const std::string& path = line.positionals()[0];
  const std::optional<std::string> space_path = line.value("space");
  if (!space_path) return absl::InvalidArgumentError("no --space file given");
  MOTIONDB_ASSIGN_OR_RETURN(const std::optional<int> dims_option, line.integer("dims"));
  const int dims = dims_option.value_or(3);
  MOTIONDB_ASSIGN_OR_RETURN(const MotionSpace space, ReadSpaceFile(*space_path));
  if (dims < 1 || dims > space.dims()) {
    return absl::InvalidArgumentError(
        absl::StrCat("--dims must be in 1..", space.dims(), " for ", *space_path, ", got ", dims));
  }
  MOTIONDB_ASSIGN_OR_RETURN(const BvhReadResult read, ReadBvhFile(path));
  for (const std::string& warning : read.warnings) {
    std::cerr << "motiondb project: warning: " << path << ": " << warning << "\n";
  }
  absl::StatusOr<RowMatrixXd> curve =
      Prefixed(absl::StrCat(path, " in ", *space_path), space.ProjectClip(read.clip, dims));
  if (!curve.ok()) return curve.status();
  const bool csv = line.flag("csv");
  if (csv) {
    std::string header = "frame,time_s";
    for (int i = 0; i < dims; ++i) absl::StrAppend(&header, ",c", i);
    absl::PrintF("%s\n", header);
  } else {
    absl::PrintF("# %s in %s: %d frames at %g Hz, first %d of %d dimensions\n", path, *space_path,
                 curve->rows(), space.sample_rate(), dims, space.dims());
  }
  const char* separator = csv ? "," : " ";
  std::string row;
  for (Eigen::Index f = 0; f < curve->rows(); ++f) {
    row = absl::StrFormat("%d%s%.6f", f, separator, f / space.sample_rate());
    for (int i = 0; i < dims; ++i) absl::StrAppendFormat(&row, "%s%.9g", separator, (*curve)(f, i));
    absl::PrintF("%s\n", row);
  }
  return absl::OkStatus();
}

}  // namespace

int RunProject(const std::vector<std::string>& args) {
  const absl::StatusOr<CommandLine> line = CommandLine::Parse(args, {"space", "dims"}, {"csv"});
  if (!line.ok()) {
    std::cerr << "motiondb project: " << line.status().message() << "\n" << kUsage;
    return 2;
  }
  const absl::Status status = Project(*line);
  if (!status.ok()) {
    std::cerr << "motiondb project: " << status.message() << "\n";
    return 1;
  }
  return 0;
}

}  // namespace motiondb::cli
