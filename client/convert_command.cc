// motiondb convert IN.bvh OUT.bvh [--fps R] [--from F --to T]
#include <iostream>
#include <memory>

#include "absl/strings/str_format.h"
#include "client/commands.h"
#include "core/bvh/bvh_reader.h"
#include "core/bvh/bvh_writer.h"
#include "core/motion/resample.h"
#include "util/cli_conventions.h"
#include "util/status_macros.h"
#include "util/status_prefix.h"

namespace motiondb::cli {
namespace {

struct ConvertFlags {
  std::string in, out;
  std::optional<double> fps;
  FrameRangeFlags range;
};

absl::Status Convert(const ConvertFlags& flags) {
  MOTIONDB_ASSIGN_OR_RETURN(BvhReadResult read, ReadBvhFile(flags.in));
  for (const std::string& warning : read.warnings) {
    std::cerr << "motiondb convert: warning: " << flags.in << ": " << warning << "\n";
  }
  Clip clip = std::move(read.clip);
  if (flags.range.from || flags.range.to) {
    const FrameRange range{flags.range.from.value_or(0),
                           flags.range.to.value_or(clip.frame_count() - 1)};
    MOTIONDB_ASSIGN_OR_RETURN(clip, Prefixed(flags.in, clip.Slice(range)));
  }
  if (flags.fps) {
    MOTIONDB_ASSIGN_OR_RETURN(clip, Resample(clip, *flags.fps));
  }
  MOTIONDB_RETURN_IF_ERROR(WriteBvhFile(flags.out, clip));
  absl::PrintF("wrote %s: %d frames at %.4f fps (%.3f s)\n", flags.out, clip.frame_count(),
               clip.fps(), clip.duration_s());
  return absl::OkStatus();
}

}  // namespace

void AddConvert(Commands& commands) {
  auto flags = std::make_shared<ConvertFlags>();
  CLI::App* convert =
      commands.AddOffline(commands.root(), "convert", "resample and/or cut a BVH file",
                          /*json=*/false, [flags] { return Convert(*flags); });
  convert->add_option("IN.bvh", flags->in, "the BVH file to read")
      ->required()
      ->check(ExistingFile());
  convert->add_option("OUT.bvh", flags->out, "the BVH file to write")->required();
  convert->add_option("--fps", flags->fps, "resample to R frames per second (slerp, lerp)")
      ->type_name("R")
      ->default_str("the input's")
      ->check(NumberAbove(0));
  AddFrameRangeFlags(convert, "the input", &flags->range);
}

}  // namespace motiondb::cli
