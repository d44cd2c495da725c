// motiondb convert IN.bvh OUT.bvh [--fps R] [--from F --to T]
#include <iostream>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "client/commands.h"
#include "core/bvh/bvh_reader.h"
#include "core/bvh/bvh_writer.h"
#include "core/motion/resample.h"
#include "util/command_line.h"
#include "util/status_macros.h"
#include "util/status_prefix.h"

namespace motiondb::cli {
namespace {

constexpr char kUsage[] =
    "usage: motiondb convert IN.bvh OUT.bvh [--fps R] [--from F --to T]\n"
    "  --from/--to  keep frames F..T (inclusive, counted from 0 at the input's rate)\n"
    "  --fps        resample to R frames per second (slerp rotations, lerp positions)\n";

absl::Status Convert(const CommandLine& line) {
  if (line.positionals().size() != 2) {
    return absl::InvalidArgumentError("expected an input and an output file");
  }
  const std::string& in = line.positionals()[0];
  const std::string& out = line.positionals()[1];
  MOTIONDB_ASSIGN_OR_RETURN(const std::optional<double> fps, line.number("fps"));
  MOTIONDB_ASSIGN_OR_RETURN(const std::optional<int> from, line.integer("from"));
  MOTIONDB_ASSIGN_OR_RETURN(const std::optional<int> to, line.integer("to"));
  MOTIONDB_ASSIGN_OR_RETURN(BvhReadResult read, ReadBvhFile(in));
  for (const std::string& warning : read.warnings) {
    std::cerr << "motiondb convert: warning: " << in << ": " << warning << "\n";
  }
  Clip clip = std::move(read.clip);
  if (from || to) {
    const FrameRange range{from.value_or(0), to.value_or(clip.frame_count() - 1)};
    MOTIONDB_ASSIGN_OR_RETURN(clip, Prefixed(in, clip.Slice(range)));
  }
  if (fps) {
    MOTIONDB_ASSIGN_OR_RETURN(clip, Resample(clip, *fps));
  }
  MOTIONDB_RETURN_IF_ERROR(WriteBvhFile(out, clip));
  absl::PrintF("wrote %s: %d frames at %.4f fps (%.3f s)\n", out, clip.frame_count(), clip.fps(),
               clip.duration_s());
  return absl::OkStatus();
}

}  // namespace

int RunConvert(const std::vector<std::string>& args) {
  const absl::StatusOr<CommandLine> line = CommandLine::Parse(args, {"fps", "from", "to"}, {});
  const absl::Status status = line.ok() ? Convert(*line) : line.status();
  if (!status.ok()) {
    std::cerr << "motiondb convert: " << status.message() << "\n";
    if (absl::IsInvalidArgument(status) && !line.ok()) std::cerr << kUsage;
    return 1;
  }
  return 0;
}

}  // namespace motiondb::cli
