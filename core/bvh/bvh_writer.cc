#include "core/bvh/bvh_writer.h"

#include <charconv>
#include <numbers>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "util/decimal_text.h"
#include "util/file_io.h"
#include "util/status_macros.h"

namespace motiondb {
namespace {

constexpr double kRadiansToDegrees = 180.0 / std::numbers::pi;

// Numbers have 12 significant digits (WriteDecimal12): far below the 1e-6 round-trip tolerance,
// and short rows.
void AppendVector(std::string& out, const Eigen::Vector3d& v) {
  char buffer[kMaxDecimal12Chars];
  for (int axis = 0; axis < 3; ++axis) {
    out += ' ';
    out.append(buffer, WriteDecimal12(buffer, v[axis]));
  }
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

}  // namespace

absl::StatusOr<std::string> WriteBvh(const Clip& clip, std::optional<FrameRange> range) {
  const FrameRange frames = range.value_or(FrameRange{0, clip.frame_count() - 1});
  MOTIONDB_RETURN_IF_ERROR(CheckFrameRange(frames, clip.frame_count()));
  const Skeleton& skeleton = clip.skeleton();

  std::string out;
  // About 15 characters a value, sign and separator included: "-32.9847707373 ".
  out.reserve(4096 + static_cast<size_t>(frames.size()) * skeleton.channel_count() * 16);
  const std::vector<int> order = HierarchyWriter(skeleton, out).Write();
  absl::StrAppend(&out, "MOTION\nFrames: ", frames.size(), "\nFrame Time: ");
  char buffer[32];
  out.append(buffer, std::to_chars(buffer, buffer + sizeof(buffer), clip.frame_time()).ptr);
  out += '\n';

  // Each joint's previous Euler angles, so that the decomposition stays continuous.
  std::vector<Eigen::Vector3d> previous(skeleton.joint_count(), Eigen::Vector3d::Zero());
  // A row is written in place: room for its longest text (each value and a separator, the line
  // end) first, cut to what it took after.
  const size_t row_room =
      static_cast<size_t>(skeleton.channel_count()) * (kMaxDecimal12Chars + 1) + 1;
  for (int f = frames.first; f <= frames.last; ++f) {
    const size_t row_start = out.size();
    out.resize(row_start + row_room);
    char* const row = out.data() + row_start;
    char* p = row;
    for (int j : order) {
      const Joint& joint = skeleton.joint(j);
      Eigen::Vector3d angles = Eigen::Vector3d::Zero();
      if (skeleton.has_rotation(j)) {
        previous[j] =
            QuaternionToEuler(clip.rotation(f, j), skeleton.rotation_order(j), previous[j]);
        angles = previous[j] * kRadiansToDegrees;
      }
      int rotation_index = 0;
      for (Channel c : joint.channels) {
        const int axis = static_cast<int>(c) % 3;
        const double value = c >= Channel::kXrotation
                                 ? angles[rotation_index++]
                                 : clip.positions()(f, 3 * skeleton.position_slot(j) + axis);
        if (p != row) *p++ = ' ';
        p = WriteDecimal12(p, value);
      }
    }
    *p++ = '\n';
    out.resize(p - out.data());
  }
  return out;
}

absl::Status WriteBvhFile(const std::string& path, const Clip& clip,
                          std::optional<FrameRange> range) {
  MOTIONDB_ASSIGN_OR_RETURN(const std::string text, WriteBvh(clip, range));
  return WriteFileAtomically(path, text);
}

}  // namespace motiondb
