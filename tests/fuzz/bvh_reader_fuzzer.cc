// libFuzzer target for the BVH reader, run as a round-trip property test rather than only a crash
// test: whatever ReadBvh accepts must survive WriteBvh and a second ReadBvh unchanged (same frame
// and joint counts, every rotation within 1e-6 rad). A violation traps, so libFuzzer saves the
// input exactly as it does for a crash.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>

#include "absl/status/statusor.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/string_view.h"
#include "core/bvh/bvh_reader.h"
#include "core/bvh/bvh_writer.h"
#include "core/motion/clip.h"
#include "core/motion/rotation.h"

namespace {

// The round-trip tolerance the writer promises (12 significant digits in degrees).
constexpr double kMaxAngleError = 1e-6;

// Prints why the property failed before trapping: the trap's stack says where, not what.
[[noreturn]] void Fail(const char* what, absl::string_view detail) {
  std::fprintf(stderr, "bvh_reader_fuzzer: %s: %.*s\n", what, static_cast<int>(detail.size()),
               detail.data());
  __builtin_trap();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  // Small limits keep each execution fast and memory-bounded, so the fuzzer spends its time on
  // parser paths rather than on huge allocations; the frame and joint limits are low enough for
  // 64 KiB inputs (scripts/fuzz.sh's -max_len) to reach and exercise them.
  motiondb::BvhReadOptions options;
  options.max_bytes = int64_t{1} << 20;
  options.max_frames = 10'000;
  options.max_joints = 200;

  const absl::string_view text(reinterpret_cast<const char*>(data), size);
  const absl::StatusOr<motiondb::BvhReadResult> first = motiondb::ReadBvh(text, options);
  if (!first.ok()) return 0;  // rejecting malformed input is correct; crashing on it is not
  const motiondb::Clip& clip = first->clip;

  const absl::StatusOr<std::string> written = motiondb::WriteBvh(clip);
  if (!written.ok()) Fail("WriteBvh failed on a clip ReadBvh accepted", written.status().message());

  // The writer may spell numbers longer than the input did (up to 12 significant digits), so the
  // re-read gets no byte limit; the frame and joint limits stay, as the counts must not change.
  motiondb::BvhReadOptions reread_options = options;
  reread_options.max_bytes = motiondb::BvhReadOptions{}.max_bytes;
  const absl::StatusOr<motiondb::BvhReadResult> second =
      motiondb::ReadBvh(*written, reread_options);
  if (!second.ok()) Fail("ReadBvh rejected WriteBvh's output", second.status().message());
  const motiondb::Clip& again = second->clip;

  if (again.frame_count() != clip.frame_count()) {
    Fail("frame count changed in the round trip",
         absl::StrCat(clip.frame_count(), " -> ", again.frame_count()));
  }
  if (again.skeleton().joint_count() != clip.skeleton().joint_count()) {
    Fail("joint count changed in the round trip",
         absl::StrCat(clip.skeleton().joint_count(), " -> ", again.skeleton().joint_count()));
  }
  for (int f = 0; f < clip.frame_count(); ++f) {
    for (int j = 0; j < clip.skeleton().joint_count(); ++j) {
      const double angle = motiondb::AngleBetween(clip.rotation(f, j), again.rotation(f, j));
      // !(<=) rather than > so that a NaN angle fails too.
      if (!(angle <= kMaxAngleError)) {
        Fail("a rotation changed by more than 1e-6 rad",
             absl::StrCat("frame ", f, ", joint '", clip.skeleton().joint(j).name, "': ", angle,
                          " rad"));
      }
    }
  }
  return 0;
}
