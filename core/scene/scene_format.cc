#include "core/scene/scene_format.h"

#include "absl/strings/ascii.h"
#include "absl/strings/match.h"

namespace motiondb {

absl::string_view MotionFileFormatName(MotionFileFormat format) {
  switch (format) {
    case MotionFileFormat::kBvh:
      return "bvh";
    case MotionFileFormat::kFbx:
      return "fbx";
    case MotionFileFormat::kGltf:
      return "gltf";
    case MotionFileFormat::kGlb:
      return "glb";
  }
  return "?";
}

std::optional<MotionFileFormat> DetectMotionFileFormat(absl::string_view head) {
  if (absl::StartsWith(head, "Kaydara FBX Binary")) return MotionFileFormat::kFbx;
  if (absl::StartsWith(head, "glTF")) return MotionFileFormat::kGlb;
  // Text formats may start with a byte-order mark and white space.
  if (absl::StartsWith(head, "\xEF\xBB\xBF")) head.remove_prefix(3);
  head = absl::StripLeadingAsciiWhitespace(head);
  if (absl::StartsWith(head, "HIERARCHY")) return MotionFileFormat::kBvh;
  // An ASCII FBX opens with its "; FBX 7.4.0 project file" comment or its header block.
  if (absl::StartsWith(head, "; FBX") || absl::StartsWith(head, "FBXHeaderExtension")) {
    return MotionFileFormat::kFbx;
  }
  // A .gltf is a JSON object; its "asset" member, which glTF requires, need not come first, so
  // any JSON object is taken for glTF and the reader says what is missing.
  if (absl::StartsWith(head, "{")) return MotionFileFormat::kGltf;
  return std::nullopt;
}

}  // namespace motiondb
