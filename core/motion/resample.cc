#include "core/motion/resample.h"

#include <algorithm>
#include <atomic>
#include <cmath>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "util/parallel_for.h"
#include "util/stop_poll.h"

namespace motiondb {
namespace {

// Output larger than this many frames is refused (a day at 1 kHz).
constexpr double kMaxOutputFrames = 86'400'000;

// A thread is started for at least this many output frames (about 0.4 ms of slerps at 31
// joints).
constexpr int kFramesPerThread = 256;
// Joint frames (slerps) between two polls of a stop function: about a millisecond's.
constexpr int64_t kJointFramesPerStopPoll = int64_t{1} << 15;

// A sample within 1% of a frame past the end takes the last frame: files write the frame time
// rounded (0.0333333 for 1/30 s), and the last frame should not be lost to that rounding.
double SampleCount(int frame_count, double frame_time, double target_fps) {
  return std::floor((frame_count - 1) * frame_time * target_fps + 0.01) + 1;
}

}  // namespace

int64_t ResampledFrameCount(int frame_count, double frame_time, double target_fps) {
  return static_cast<int64_t>(SampleCount(frame_count, frame_time, target_fps));
}

absl::StatusOr<Clip> Resample(const Clip& clip, double target_fps, int threads,
                              const std::function<bool()>& should_stop) {
  if (!std::isfinite(target_fps) || target_fps <= 0.0 || target_fps > kMaxResampleRate) {
    return absl::InvalidArgumentError(absl::StrCat("target rate must be in (0, ", kMaxResampleRate,
                                                   "] frames per second, got ", target_fps));
  }
  const int n = clip.frame_count();
  const double samples = SampleCount(n, clip.frame_time(), target_fps);
  if (samples > kMaxOutputFrames) {
    return absl::ResourceExhaustedError(
        absl::StrCat("resampling would produce ", samples, " frames"));
  }
  const int count = static_cast<int>(samples);
  const int joints = clip.skeleton().joint_count();
  const RowMatrixXd& positions = clip.positions();
  RowMatrixXd out_rotations(count, clip.rotations().cols());
  RowMatrixXd out_positions(count, positions.cols());
  const int pieces = PieceCount(count, kFramesPerThread, threads);
  std::atomic<bool> stopped{false};
  ForEachPiece(count, pieces, [&](int, int64_t begin, int64_t end) {
    StopPoll stop(should_stop, kJointFramesPerStopPoll);
    for (int k = static_cast<int>(begin); k < end; ++k) {
      if (stop.Done(joints)) {
        stopped = true;
        return;
      }
      double u = std::min(k / target_fps / clip.frame_time(), n - 1.0);
      if (std::abs(u - std::round(u)) < 1e-9) u = std::round(u);  // land exactly on source frames
      const int i = std::min(static_cast<int>(u), n - 1);
      const int next = std::min(i + 1, n - 1);
      const double t = u - i;
      for (int j = 0; j < joints; ++j) {
        const Quat q =
            t == 0.0 ? clip.rotation(i, j) : Slerp(clip.rotation(i, j), clip.rotation(next, j), t);
        out_rotations.block<1, 4>(k, 4 * j) << q.w(), q.x(), q.y(), q.z();
      }
      out_positions.row(k) = (1.0 - t) * positions.row(i) + t * positions.row(next);
    }
  });
  if (stopped) return absl::CancelledError("resampling was stopped by its caller");
  return Clip::Create(clip.shared_skeleton(), 1.0 / target_fps, std::move(out_rotations),
                      std::move(out_positions));
}

}  // namespace motiondb
