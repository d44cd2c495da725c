// motiondb project FILE.bvh --space SPACE.mcs [--dims 3] [--csv]
#include <iostream>
#include <memory>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "client/commands.h"
#include "core/bvh/bvh_reader.h"
#include "core/space/motion_space.h"
#include "core/space/space_serialization.h"
#include "util/cli_conventions.h"
#include "util/status_macros.h"
#include "util/status_prefix.h"

namespace motiondb::cli {
namespace {

struct ProjectFlags {
  std::string bvh, space;
  int dims = 3;
  bool csv = false;
};

absl::Status Project(const ProjectFlags& flags) {
  const std::string& path = flags.bvh;
  const std::string& space_path = flags.space;
  const int dims = flags.dims;
  MOTIONDB_ASSIGN_OR_RETURN(const MotionSpace space, ReadSpaceFile(space_path));
  if (dims < 1 || dims > space.dims()) {
    return absl::InvalidArgumentError(
        absl::StrCat("--dims must be in 1..", space.dims(), " for ", space_path, ", got ", dims));
  }
  MOTIONDB_ASSIGN_OR_RETURN(const BvhReadResult read, ReadBvhFile(path));
  for (const std::string& warning : read.warnings) {
    std::cerr << "motiondb project: warning: " << path << ": " << warning << "\n";
  }
  absl::StatusOr<RowMatrixXd> curve =
      Prefixed(absl::StrCat(path, " in ", space_path), space.ProjectClip(read.clip, dims));
  if (!curve.ok()) return curve.status();
  const bool csv = flags.csv;
  if (csv) {
    std::string header = "frame,time_s";
    for (int i = 0; i < dims; ++i) absl::StrAppend(&header, ",c", i);
    absl::PrintF("%s\n", header);
  } else {
    absl::PrintF("# %s in %s: %d frames at %g Hz, first %d of %d dimensions\n", path, space_path,
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

void AddProject(Commands& commands) {
  auto flags = std::make_shared<ProjectFlags>();
  CLI::App* project =
      commands.AddOffline(commands.root(), "project", "print a clip's motion curve in a space file",
                          /*json=*/false, [flags] { return Project(*flags); });
  project->add_option("FILE.bvh", flags->bvh, "the clip")->required()->check(ExistingFile());
  project->add_option("--space", flags->space, "the space file ('motiondb space build')")
      ->type_name("SPACE.mcs")
      ->required()
      ->check(ExistingFile());
  project->footer(
      "One line per frame at the space's rate: the frame, its time in seconds, then its first\n"
      "--dims coordinates.");
  project->add_option("--dims", flags->dims, "coordinates per frame (at most the space's)")
      ->type_name("N")
      ->capture_default_str()
      ->check(WholeAtLeast(1));
  project->add_flag("--csv", flags->csv, "comma-separated, with a header row");
}

}  // namespace motiondb::cli
