// A stored clip, a range of it or one frame of it, as the command line writes them: "12" (clip
// 12, whole), "12:40-300" (frames 40 to 300, inclusive, at the clip's own rate) and "12:40"
// (frame 40 alone). `space create --train` and the `op` commands read them.
#ifndef MOTIONDB_CLIENT_CLIP_RANGE_ARG_H_
#define MOTIONDB_CLIENT_CLIP_RANGE_ARG_H_

#include <string>

#include <CLI/CLI.hpp>

#include "absl/status/statusor.h"
#include "motiondb/v1/common.pb.h"

namespace motiondb::cli {

// INVALID_ARGUMENT saying what was expected for anything else.
absl::StatusOr<v1::ClipRange> ParseClipRange(const std::string& spec);

// A CLI11 check that a value is such a clip range (a usage error otherwise).
CLI::Validator ClipRangeCheck();

}  // namespace motiondb::cli

#endif  // MOTIONDB_CLIENT_CLIP_RANGE_ARG_H_
