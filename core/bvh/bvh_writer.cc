#include "core/bvh/bvh_writer.h"

#include <algorithm>
#include <charconv>
#include <functional>
#include <numbers>
#include <utility>
#include <vector>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "util/decimal_text.h"
#include "util/file_io.h"
#include "util/parallel_for.h"
#include "util/status_macros.h"

namespace motiondb {
namespace {

constexpr double kRadiansToDegrees = 180.0 / std::numbers::pi;
// Room for the frame time's text: std::to_chars' shortest form of a double is at most 24.
constexpr int kFrameTimeRoom = 32;

// Numbers have 12 significant digits (WriteDecimal12): far below the 1e-6 round-trip tolerance,
// and short rows.
void AppendVector(std::string& out, const Eigen::Vector3d& v) {
  char buffer[kMaxDecimal12Chars];
  for (int axis = 0; axis < 3; ++axis) {
    out += ' ';
    out.append(buffer, WriteDecimal12(buffer, v[axis]));
  }
}

// The longest text of a row: each value and a separator, the line end.
size_t RowRoom(int channels) {
  return static_cast<size_t>(channels) * (kMaxDecimal12Chars + 1) + 1;
}

// Room for the text of `frames` rows: about 15 characters a value, sign and separator included
// ("-32.9847707373 "), and the longest text of a row, in which a row is written before it is cut
// to what it took.
size_t RowsRoom(int64_t frames, int channels) {
  return static_cast<size_t>(frames) * channels * 16 + RowRoom(channels);
}

class HierarchyWriter {
 public:
  HierarchyWriter(const Skeleton& skeleton, std::string& out) : skeleton_(skeleton), out_(out) {
    children_.resize(skeleton.joint_count());
    for (int j = 1; j < skeleton.joint_count(); ++j) {
      children_[skeleton.joint(j).parent].push_back(j);
    }
  }

  // Writes the hierarchy and returns the joints in the order their channels appear in a row.
  std::vector<int> Write() {
    out_ += "HIERARCHY\n";
    WriteJoint(0, 0);
    return std::move(order_);
  }

 private:
  void WriteJoint(int index, int depth) {
    const Joint& joint = skeleton_.joint(index);
    const std::string indent(depth, '\t');
    absl::StrAppend(&out_, indent, index == 0 ? "ROOT " : "JOINT ", joint.name, "\n", indent, "{\n",
                    indent, "\tOFFSET");
    AppendVector(out_, joint.offset);
    absl::StrAppend(&out_, "\n", indent, "\tCHANNELS ", joint.channels.size());
    for (Channel c : joint.channels) absl::StrAppend(&out_, " ", ChannelName(c));
    out_ += '\n';
    order_.push_back(index);
    for (int child : children_[index]) WriteJoint(child, depth + 1);
    if (joint.end_site) {
      absl::StrAppend(&out_, indent, "\tEnd Site\n", indent, "\t{\n", indent, "\t\tOFFSET");
      AppendVector(out_, *joint.end_site);
      absl::StrAppend(&out_, "\n", indent, "\t}\n");
    }
    absl::StrAppend(&out_, indent, "}\n");
  }

  const Skeleton& skeleton_;
  std::string& out_;
  std::vector<std::vector<int>> children_;
  std::vector<int> order_;
};

// Frames are written in blocks of this many, so that the angles held between decomposition and
// text stay small whatever the clip's length (31 joints: 3 MB).
constexpr int kBlockFrames = 4096;
// A thread is started for at least this many frames (about 0.5 ms of work at 31 joints).
constexpr int kFramesPerThread = 128;

// The MOTION rows, of one clip's frames handed over in one or several batches. The Euler
// decomposition (three atan2 a joint) and the numbers' text, most of an export's time, run on
// several threads; only the choice of each joint's triple nearest the previous frame's, which
// keeps the angles continuous, runs in frame order, across batches too.
class MotionWriter {
 public:
  MotionWriter(const Skeleton& skeleton, std::vector<int> order, int threads)
      : skeleton_(skeleton),
        order_(std::move(order)),
        threads_(threads),
        previous_(skeleton_.joint_count(), Eigen::Vector3d::Zero()) {
    for (int j = 0; j < skeleton_.joint_count(); ++j) {
      if (skeleton_.has_rotation(j)) rotating_.push_back(j);
    }
  }

  // `frames` of `clip`, a clip of the writer's skeleton (its offsets and channels), after the
  // frames appended before. False when `should_stop` said stop before a block (a block takes
  // about 10 ms at 21 joints, 30 at 101 on two threads).
  bool Append(const Clip& clip, FrameRange frames, std::string& out,
              const std::function<bool()>& should_stop) {
    for (int first = frames.first; first <= frames.last; first += kBlockFrames) {
      if (should_stop && should_stop()) return false;
      AppendBlock(clip, {first, std::min(frames.last, first + kBlockFrames - 1)}, out);
    }
    return true;
  }

 private:
  void AppendBlock(const Clip& clip, FrameRange block, std::string& out) {
    first_ = block.first;
    const int pieces = PieceCount(block.size(), kFramesPerThread, threads_);
    const auto frames = [&](int64_t begin, int64_t end) {
      return FrameRange{block.first + static_cast<int>(begin),
                        block.first + static_cast<int>(end) - 1};
    };
    angles_.resize(static_cast<size_t>(block.size()) * skeleton_.joint_count());
    ForEachPiece(block.size(), pieces,
                 [&](int, int64_t begin, int64_t end) { Decompose(clip, frames(begin, end)); });
    MakeContinuous(block);
    // The first piece goes straight into `out` (reserved for the whole answer), the others into
    // texts of their own appended after.
    std::vector<std::string> texts(pieces);
    ForEachPiece(block.size(), pieces, [&](int piece, int64_t begin, int64_t end) {
      if (piece > 0) texts[piece].reserve(RowsRoom(end - begin, skeleton_.channel_count()));
      WriteRows(clip, frames(begin, end), piece == 0 ? out : texts[piece]);
    });
    for (int piece = 1; piece < pieces; ++piece) out += texts[piece];
  }

  // Where a frame's joint's angles sit in angles_.
  size_t Slot(int frame, int joint) const {
    return static_cast<size_t>(frame - first_) * skeleton_.joint_count() + joint;
  }
  Eigen::Vector3d& Angles(int frame, int joint) { return angles_[Slot(frame, joint)]; }
  const Eigen::Vector3d& Angles(int frame, int joint) const { return angles_[Slot(frame, joint)]; }

  void Decompose(const Clip& clip, FrameRange frames) {
    for (int f = frames.first; f <= frames.last; ++f) {
      for (int j : rotating_) {
        Angles(f, j) = EulerAngles(clip.rotation(f, j), skeleton_.rotation_order(j));
      }
    }
  }

  void MakeContinuous(FrameRange frames) {
    for (int f = frames.first; f <= frames.last; ++f) {
      for (int j : rotating_) {
        Eigen::Vector3d& angles = Angles(f, j);
        previous_[j] = angles = NearestEulerTriple(angles, previous_[j]);
      }
    }
  }

  // A row is written in place: room for its longest text first, cut to what it took after.
  void WriteRows(const Clip& clip, FrameRange frames, std::string& out) const {
    const size_t row_room = RowRoom(skeleton_.channel_count());
    for (int f = frames.first; f <= frames.last; ++f) {
      const size_t row_start = out.size();
      out.resize(row_start + row_room);
      char* const row = out.data() + row_start;
      char* p = row;
      for (int j : order_) {
        const Joint& joint = skeleton_.joint(j);
        const Eigen::Vector3d angles = skeleton_.has_rotation(j)
                                           ? Eigen::Vector3d(Angles(f, j) * kRadiansToDegrees)
                                           : Eigen::Vector3d::Zero();
        int rotation_index = 0;
        for (Channel c : joint.channels) {
          const int axis = static_cast<int>(c) % 3;
          const double value = c >= Channel::kXrotation
                                   ? angles[rotation_index++]
                                   : clip.positions()(f, 3 * skeleton_.position_slot(j) + axis);
          if (p != row) *p++ = ' ';
          p = WriteDecimal12(p, value);
        }
      }
      *p++ = '\n';
      out.resize(p - out.data());
    }
  }

  const Skeleton& skeleton_;
  const std::vector<int> order_;  // the joints in the order of a row's channels
  const int threads_;
  std::vector<int> rotating_;  // the joints with rotation channels
  // The current block's angles (frame - first_, joint), radians; continuous once made so.
  std::vector<Eigen::Vector3d> angles_;
  int first_ = 0;
  // Each joint's angles in the frame before the block.
  std::vector<Eigen::Vector3d> previous_;
};

// "MOTION", the frame count and the frame time, after the hierarchy.
void AppendMotionHeader(int64_t frames, double frame_time, std::string& out) {
  absl::StrAppend(&out, "MOTION\nFrames: ", frames, "\nFrame Time: ");
  char buffer[kFrameTimeRoom];
  out.append(buffer, std::to_chars(buffer, buffer + sizeof(buffer), frame_time).ptr);
  out += '\n';
}

}  // namespace

struct BvhStreamWriter::State {
  State(std::shared_ptr<const Skeleton> shared, int threads)
      : skeleton(std::move(shared)),
        rows(*skeleton, HierarchyWriter(*skeleton, hierarchy).Write(), threads) {}

  std::shared_ptr<const Skeleton> skeleton;
  std::string hierarchy;  // written as the rows' joint order is found
  MotionWriter rows;
};

BvhStreamWriter::BvhStreamWriter(std::shared_ptr<const Skeleton> skeleton, int threads)
    : state_(std::make_unique<State>(std::move(skeleton), threads)) {}

BvhStreamWriter::~BvhStreamWriter() = default;

std::string BvhStreamWriter::Header(int64_t frames, double frame_time) const {
  std::string header = state_->hierarchy;
  AppendMotionHeader(frames, frame_time, header);
  return header;
}

absl::Status BvhStreamWriter::AppendRows(const Clip& batch, std::optional<FrameRange> frames,
                                         std::string& out,
                                         const std::function<bool()>& should_stop) {
  const Skeleton& skeleton = *state_->skeleton;
  if (batch.skeleton().joint_count() != skeleton.joint_count() ||
      batch.skeleton().channel_count() != skeleton.channel_count()) {
    return absl::InvalidArgumentError(
        absl::StrCat("the frames' skeleton (", batch.skeleton().joint_count(), " joints, ",
                     batch.skeleton().channel_count(), " channels) is not the writer's (",
                     skeleton.joint_count(), " joints, ", skeleton.channel_count(), " channels)"));
  }
  const FrameRange range = frames.value_or(FrameRange{0, batch.frame_count() - 1});
  MOTIONDB_RETURN_IF_ERROR(CheckFrameRange(range, batch.frame_count()));
  if (!state_->rows.Append(batch, range, out, should_stop)) {
    return absl::CancelledError("writing the BVH was stopped by its caller");
  }
  return absl::OkStatus();
}

int64_t BvhRowBound(const Skeleton& skeleton) {
  // Each value at its longest, a space between values, the line end.
  const int64_t channels = skeleton.channel_count();
  return channels * kLongestDecimal12Text + std::max<int64_t>(channels, 1);
}

int64_t BvhTextBound(const Skeleton& skeleton, int64_t frames) {
  std::string hierarchy;
  HierarchyWriter(skeleton, hierarchy).Write();
  const int64_t motion_header =
      absl::StrCat("MOTION\nFrames: ", frames, "\nFrame Time: \n").size() + kFrameTimeRoom;
  return static_cast<int64_t>(hierarchy.size()) + motion_header + frames * BvhRowBound(skeleton);
}

absl::StatusOr<std::string> WriteBvh(const Clip& clip, std::optional<FrameRange> range, int threads,
                                     const std::function<bool()>& should_stop) {
  const FrameRange frames = range.value_or(FrameRange{0, clip.frame_count() - 1});
  MOTIONDB_RETURN_IF_ERROR(CheckFrameRange(frames, clip.frame_count()));
  BvhStreamWriter writer(clip.shared_skeleton(), threads);
  std::string out = writer.Header(frames.size(), clip.frame_time());
  out.reserve(out.size() + RowsRoom(frames.size(), clip.skeleton().channel_count()));
  MOTIONDB_RETURN_IF_ERROR(writer.AppendRows(clip, frames, out, should_stop));
  return out;
}

absl::Status WriteBvhFile(const std::string& path, const Clip& clip,
                          std::optional<FrameRange> range) {
  MOTIONDB_ASSIGN_OR_RETURN(const std::string text, WriteBvh(clip, range));
  return WriteFileAtomically(path, text);
}

}  // namespace motiondb
