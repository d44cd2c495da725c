#include "core/scene/scene_reader.h"

#include <assimp/config.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <assimp/Importer.hpp>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <utility>

#include "absl/container/flat_hash_map.h"
#include "absl/container/flat_hash_set.h"
#include "absl/strings/ascii.h"
#include "absl/strings/str_cat.h"
#include "util/status_macros.h"

namespace motiondb {
namespace {

// A uniform scale of a node further from 1 than this is a unit change; one whose axes differ
// more than this cannot be kept in a clip (which has no scale) and is warned about.
constexpr double kScaleTolerance = 1e-4;

struct NodeTransform {
  Eigen::Vector3d translation;
  Quat rotation;
  Eigen::Vector3d scale;
};

Eigen::Vector3d ToVector(const aiVector3D& v) { return {v.x, v.y, v.z}; }

Quat ToQuat(const aiQuaternion& q) { return Quat(q.w, q.x, q.y, q.z).normalized(); }

NodeTransform Decompose(const aiMatrix4x4& matrix) {
  aiVector3D scale;
  aiQuaternion rotation;
  aiVector3D translation;
  matrix.Decompose(scale, rotation, translation);
  return {ToVector(translation), ToQuat(rotation), ToVector(scale)};
}

bool IsUniform(const Eigen::Vector3d& scale) {
  return std::abs(scale.x() - scale.y()) <= kScaleTolerance * std::abs(scale.x()) &&
         std::abs(scale.x() - scale.z()) <= kScaleTolerance * std::abs(scale.x());
}

// A number the file's metadata holds as int, float or double; nullopt when absent.
std::optional<double> MetadataNumber(const aiScene& scene, const char* key) {
  const aiMetadata* metadata = scene.mMetaData;
  if (metadata == nullptr) return std::nullopt;
  for (unsigned i = 0; i < metadata->mNumProperties; ++i) {
    if (metadata->mKeys[i] != aiString(key)) continue;
    const aiMetadataEntry& entry = metadata->mValues[i];
    switch (entry.mType) {
      case AI_INT32:
        return *static_cast<const int32_t*>(entry.mData);
      case AI_FLOAT:
        return *static_cast<const float*>(entry.mData);
      case AI_DOUBLE:
        return *static_cast<const double*>(entry.mData);
      default:
        return std::nullopt;
    }
  }
  return std::nullopt;
}

std::string MetadataText(const aiScene& scene, const char* key) {
  aiString value;
  if (scene.mMetaData != nullptr && scene.mMetaData->Get(key, value)) return value.C_Str();
  return "";
}

// The file's up axis and the rotation that turns it to +Y. FBX says it in its global settings
// (0 = X, 1 = Y, 2 = Z, with a sign); glTF is Y up by definition.
std::pair<char, Quat> UpAxis(const aiScene& scene, MotionFileFormat format) {
  if (format != MotionFileFormat::kFbx) return {'Y', Quat::Identity()};
  const int axis = static_cast<int>(MetadataNumber(scene, "UpAxis").value_or(1));
  const double sign = MetadataNumber(scene, "UpAxisSign").value_or(1) < 0 ? -1.0 : 1.0;
  if (axis < 0 || axis > 2) return {'Y', Quat::Identity()};
  Eigen::Vector3d up = Eigen::Vector3d::Zero();
  up[axis] = sign;
  return {static_cast<char>('X' + axis), Quat::FromTwoVectors(up, Eigen::Vector3d::UnitY())};
}

// Every take's channels, by the name of the node each keys. Built once: a file may key tens of
// thousands of nodes.
using ChannelIndex = absl::flat_hash_map<std::string, std::vector<const aiNodeAnim*>>;

ChannelIndex IndexChannels(const aiScene& scene) {
  ChannelIndex channels;
  for (unsigned a = 0; a < scene.mNumAnimations; ++a) {
    const aiAnimation& animation = *scene.mAnimations[a];
    for (unsigned c = 0; c < animation.mNumChannels; ++c) {
      const aiNodeAnim* channel = animation.mChannels[c];
      channels[channel->mNodeName.C_Str()].push_back(channel);
    }
  }
  return channels;
}

const std::vector<const aiNodeAnim*>& ChannelsOf(const ChannelIndex& channels, const aiNode& node) {
  static const std::vector<const aiNodeAnim*> kNone;
  const auto found = channels.find(node.mName.C_Str());
  return found == channels.end() ? kNone : found->second;
}

// Calls `visit` on `node` and every node below it, parents first.
template <typename Visit>
void VisitNodes(const aiNode& node, const Visit& visit) {
  visit(node);
  for (unsigned c = 0; c < node.mNumChildren; ++c) VisitNodes(*node.mChildren[c], visit);
}

int Depth(const aiNode* node) {
  int depth = 0;
  for (; node->mParent != nullptr; node = node->mParent) ++depth;
  return depth;
}

const aiNode* LowestCommonAncestor(const aiNode* a, const aiNode* b) {
  int depth_a = Depth(a);
  int depth_b = Depth(b);
  for (; depth_a > depth_b; --depth_a) a = a->mParent;
  for (; depth_b > depth_a; --depth_b) b = b->mParent;
  while (a != b) {
    a = a->mParent;
    b = b->mParent;
  }
  return a;
}

// A joint of the skeleton being built, in the order parents precede children.
struct SkeletonNode {
  const aiNode* node;
  int parent;
};

// Appends `node` and those of its descendants on the way to an animated node; true when it
// appended anything.
bool CollectJoints(const aiNode* node, int parent, const ChannelIndex& animated,
                   std::vector<SkeletonNode>& joints) {
  const size_t index = joints.size();
  joints.push_back({node, parent});
  bool keep = animated.contains(node->mName.C_Str());
  for (unsigned c = 0; c < node->mNumChildren; ++c) {
    keep |= CollectJoints(node->mChildren[c], static_cast<int>(index), animated, joints);
  }
  if (!keep) joints.resize(index);
  return keep;
}

// A BVH token: names with white space in them get underscores.
std::string JointName(const aiNode& node, int index) {
  std::string name = node.mName.C_Str();
  for (char& c : name) {
    if (absl::ascii_isspace(static_cast<unsigned char>(c)) || c == '{' || c == '}') c = '_';
  }
  return name.empty() ? absl::StrCat("joint_", index) : name;
}

// The still skeleton: its joints' transforms from the file and what the clips' channels are
// reckoned against.
struct RestSkeleton {
  std::vector<SkeletonNode> nodes;
  std::vector<NodeTransform> local;        // each node's own transform, as the file has it
  std::vector<double> world_scale;         // each joint's uniform scale in the world
  std::vector<bool> translation_animated;  // a joint whose translation moves in some take
  Eigen::Vector3d above_translation;       // the root's parent in the Y-up world
  Quat above_rotation;
  double above_scale = 1.0;
};

// The clip's channel for the joint's rotation, and when the joint is the root or its
// translation moves, its position.
std::vector<Joint> BvhJoints(const RestSkeleton& rest) {
  std::vector<Joint> joints;
  absl::flat_hash_set<std::string> names;
  for (size_t j = 0; j < rest.nodes.size(); ++j) {
    Joint joint;
    joint.name = JointName(*rest.nodes[j].node, static_cast<int>(j));
    while (!names.insert(joint.name).second) joint.name += "_";
    joint.parent = rest.nodes[j].parent;
    if (joint.parent >= 0) {
      const int parent = joint.parent;
      joint.offset = rest.world_scale[parent] * rest.local[j].translation;
    }
    if (j == 0 || rest.translation_animated[j]) {
      joint.channels = {Channel::kXposition, Channel::kYposition, Channel::kZposition};
    }
    joint.channels.insert(joint.channels.end(),
                          {Channel::kZrotation, Channel::kXrotation, Channel::kYrotation});
    joints.push_back(std::move(joint));
  }
  // A still leaf below a joint is where that joint ends.
  absl::flat_hash_set<const aiNode*> joint_nodes;
  for (const SkeletonNode& n : rest.nodes) joint_nodes.insert(n.node);
  for (size_t j = 0; j < rest.nodes.size(); ++j) {
    const aiNode& node = *rest.nodes[j].node;
    for (unsigned c = 0; c < node.mNumChildren; ++c) {
      const aiNode& child = *node.mChildren[c];
      if (child.mNumChildren != 0 || child.mNumMeshes != 0) continue;
      if (joint_nodes.contains(&child) || joints[j].end_site) continue;
      joints[j].end_site = rest.world_scale[j] * Decompose(child.mTransformation).translation;
    }
  }
  return joints;
}

// One channel of a take sampled at a time: its keys, and where the last lookup stopped.
template <typename Key>
class KeyCursor {
 public:
  KeyCursor(const Key* keys, unsigned count) : keys_(keys), count_(count) {}
  bool empty() const { return count_ == 0; }
  // The keys bracketing `time` (equal at the ends) and the fraction between them; times only
  // grow from call to call.
  std::pair<const Key*, std::pair<const Key*, double>> At(double time) {
    while (at_ + 1 < count_ && keys_[at_ + 1].mTime <= time) ++at_;
    const Key* first = &keys_[at_];
    if (at_ + 1 >= count_ || time <= first->mTime) return {first, {first, 0.0}};
    const Key* second = &keys_[at_ + 1];
    return {first, {second, (time - first->mTime) / (second->mTime - first->mTime)}};
  }

 private:
  const Key* keys_;
  unsigned count_;
  unsigned at_ = 0;
};

// The take's frame times, in ticks: from its first key to its last. FBX stores a frame rate, which
// assimp gives as the ticks a second with a key on every tick it keys; glTF stores none, so its
// keys' usual spacing is taken for the frame.
struct TakeTiming {
  double first_tick = 0;
  double ticks_per_frame = 1;
  int64_t frame_count = 1;
  double frame_time = 1.0 / 30;
};

absl::StatusOr<TakeTiming> Timing(const aiAnimation& animation, MotionFileFormat format) {
  std::vector<double> times;
  for (unsigned c = 0; c < animation.mNumChannels; ++c) {
    const aiNodeAnim& channel = *animation.mChannels[c];
    for (unsigned k = 0; k < channel.mNumRotationKeys; ++k) {
      times.push_back(channel.mRotationKeys[k].mTime);
    }
    for (unsigned k = 0; k < channel.mNumPositionKeys; ++k) {
      times.push_back(channel.mPositionKeys[k].mTime);
    }
  }
  const double ticks_per_second = animation.mTicksPerSecond > 0 ? animation.mTicksPerSecond : 25;
  if (times.empty() ||
      !std::all_of(times.begin(), times.end(), [](double t) { return std::isfinite(t); })) {
    return absl::InvalidArgumentError(
        absl::StrCat("animation '", animation.mName.C_Str(), "' has no keys or a key at no time"));
  }
  std::sort(times.begin(), times.end());
  TakeTiming timing;
  timing.first_tick = times.front();
  const double span = times.back() - times.front();
  if (format == MotionFileFormat::kFbx) {
    timing.ticks_per_frame = 1;
  } else {
    // Distinct key times; a file keyed at every frame has them evenly spaced, and the frame is
    // their mean spacing (exact at every key, where 32-bit times make single gaps uneven).
    std::vector<double> distinct = {times.front()};
    for (const double t : times) {
      if (t - distinct.back() > 1e-6 * std::max(1.0, span)) distinct.push_back(t);
    }
    std::vector<double> gaps;
    for (size_t i = 1; i < distinct.size(); ++i) gaps.push_back(distinct[i] - distinct[i - 1]);
    if (gaps.empty()) {
      timing.ticks_per_frame = ticks_per_second / 30;
    } else {
      const double mean = span / static_cast<double>(gaps.size());
      const bool even = std::all_of(gaps.begin(), gaps.end(),
                                    [&](double gap) { return std::abs(gap - mean) < 1e-2 * mean; });
      std::nth_element(gaps.begin(), gaps.begin() + gaps.size() / 2, gaps.end());
      timing.ticks_per_frame = even ? mean : gaps[gaps.size() / 2];
    }
  }
  timing.frame_time = timing.ticks_per_frame / ticks_per_second;
  const double frames = std::round(span / timing.ticks_per_frame) + 1;
  if (!(frames < 1e9) || !(timing.frame_time > 0) || !std::isfinite(timing.frame_time)) {
    return absl::InvalidArgumentError(absl::StrCat("animation '", animation.mName.C_Str(),
                                                   "' spans ", span, " ticks, ", frames,
                                                   " frames: not a take"));
  }
  timing.frame_count = static_cast<int64_t>(frames);
  return timing;
}

absl::StatusOr<Clip> SampleTake(const aiAnimation& animation, const RestSkeleton& rest,
                                const std::shared_ptr<const Skeleton>& skeleton,
                                const TakeTiming& timing, const SceneReadOptions& options,
                                std::vector<std::string>& warnings) {
  const int joints = skeleton->joint_count();
  const int64_t columns = 4 * joints + 3 * skeleton->position_joint_count();
  if (timing.frame_count * columns * 8 > options.max_clip_bytes) {
    return absl::ResourceExhaustedError(absl::StrCat(
        "animation '", animation.mName.C_Str(), "' makes a clip of ", timing.frame_count,
        " frames x ", joints, " joints, over the limit of ", options.max_clip_bytes, " bytes"));
  }
  absl::flat_hash_map<std::string, const aiNodeAnim*> channels;
  for (unsigned c = 0; c < animation.mNumChannels; ++c) {
    channels[animation.mChannels[c]->mNodeName.C_Str()] = animation.mChannels[c];
  }
  struct JointCursors {
    std::optional<KeyCursor<aiQuatKey>> rotation;
    std::optional<KeyCursor<aiVectorKey>> position;
  };
  std::vector<JointCursors> cursors(joints);
  bool scale_animated = false;
  for (int j = 0; j < joints; ++j) {
    const auto found = channels.find(rest.nodes[j].node->mName.C_Str());
    if (found == channels.end()) continue;
    const aiNodeAnim& channel = *found->second;
    if (channel.mNumRotationKeys > 0) {
      cursors[j].rotation.emplace(channel.mRotationKeys, channel.mNumRotationKeys);
    }
    if (channel.mNumPositionKeys > 0) {
      cursors[j].position.emplace(channel.mPositionKeys, channel.mNumPositionKeys);
    }
    for (unsigned k = 0; k < channel.mNumScalingKeys; ++k) {
      const Eigen::Vector3d scale = ToVector(channel.mScalingKeys[k].mValue);
      if (!scale.isApprox(rest.local[j].scale, kScaleTolerance)) scale_animated = true;
    }
  }
  if (scale_animated) {
    warnings.push_back(absl::StrCat("animation '", animation.mName.C_Str(),
                                    "' scales joints; a clip has no scale, it was left out"));
  }

  RowMatrixXd rotations(timing.frame_count, 4 * joints);
  RowMatrixXd positions(timing.frame_count, 3 * skeleton->position_joint_count());
  for (int64_t f = 0; f < timing.frame_count; ++f) {
    const double tick = timing.first_tick + static_cast<double>(f) * timing.ticks_per_frame;
    for (int j = 0; j < joints; ++j) {
      Quat local = rest.local[j].rotation;
      if (cursors[j].rotation) {
        const auto [a, b] = cursors[j].rotation->At(tick);
        local = Slerp(ToQuat(a->mValue), ToQuat(b.first->mValue), b.second);
      }
      Eigen::Vector3d translation = rest.local[j].translation;
      if (cursors[j].position) {
        const auto [a, b] = cursors[j].position->At(tick);
        translation = (1 - b.second) * ToVector(a->mValue) + b.second * ToVector(b.first->mValue);
      }
      const int parent = rest.nodes[j].parent;
      // The root's rotation carries what lies above it (and the turn to Y up).
      const Quat relative = parent < 0 ? (rest.above_rotation * local).normalized() : local;
      if (!relative.coeffs().allFinite()) {
        return absl::InvalidArgumentError(absl::StrCat("animation '", animation.mName.C_Str(),
                                                       "' gives joint '", skeleton->joint(j).name,
                                                       "' no rotation at tick ", tick));
      }
      rotations.block<1, 4>(f, 4 * j) << relative.w(), relative.x(), relative.y(), relative.z();
      const int slot = skeleton->position_slot(j);
      if (slot < 0) continue;
      Eigen::Vector3d position;
      if (parent < 0) {
        position = rest.above_translation + rest.above_rotation * (rest.above_scale * translation);
      } else {
        position = rest.world_scale[parent] * translation;
      }
      if (!position.allFinite()) {
        return absl::InvalidArgumentError(absl::StrCat("animation '", animation.mName.C_Str(),
                                                       "' gives joint '", skeleton->joint(j).name,
                                                       "' no position at tick ", tick));
      }
      positions.block<1, 3>(f, 3 * slot) = position.transpose();
    }
  }
  return Clip::Create(skeleton, timing.frame_time, std::move(rotations), std::move(positions));
}

// Whether a joint's translation keys leave its rest translation in some take.
bool TranslationMoves(const std::vector<const aiNodeAnim*>& channels, const Eigen::Vector3d& rest) {
  const double tolerance = 1e-6 * std::max(1.0, rest.norm());
  for (const aiNodeAnim* channel : channels) {
    for (unsigned k = 0; k < channel->mNumPositionKeys; ++k) {
      if ((ToVector(channel->mPositionKeys[k].mValue) - rest).norm() > tolerance) return true;
    }
  }
  return false;
}

absl::StatusOr<RestSkeleton> FindSkeleton(const aiScene& scene, const Quat& to_y_up,
                                          std::vector<std::string>& warnings) {
  const ChannelIndex animated = IndexChannels(scene);
  const aiNode* root = nullptr;
  VisitNodes(*scene.mRootNode, [&](const aiNode& node) {
    if (!animated.contains(node.mName.C_Str())) return;
    root = root == nullptr ? &node : LowestCommonAncestor(root, &node);
  });
  if (root == nullptr) {
    return absl::InvalidArgumentError(
        "no skeletal animation: the file's animations move no node of its scene");
  }
  RestSkeleton rest;
  CollectJoints(root, -1, animated, rest.nodes);
  if (rest.nodes.size() < 2) {
    return absl::InvalidArgumentError(
        absl::StrCat("no skeletal animation: the file animates one node ('", root->mName.C_Str(),
                     "'), not a hierarchy of joints"));
  }
  // A still scene root over several moving trees: several characters, read as one skeleton.
  if (root == scene.mRootNode && !animated.contains(root->mName.C_Str())) {
    int moving_children = 0;
    for (unsigned c = 0; c < root->mNumChildren; ++c) {
      std::vector<SkeletonNode> below;
      moving_children += CollectJoints(root->mChildren[c], -1, animated, below) ? 1 : 0;
    }
    if (moving_children > 1) {
      warnings.push_back(absl::StrCat("the file's animations move ", moving_children,
                                      " separate hierarchies; they were read as one skeleton"));
    }
  }
  // Everything above the root, from the scene's root down, turned Y up.
  aiMatrix4x4 above;
  for (const aiNode* node = root->mParent; node != nullptr; node = node->mParent) {
    above = node->mTransformation * above;
  }
  const NodeTransform above_parts = Decompose(above);
  if (!IsUniform(above_parts.scale)) {
    warnings.push_back(
        "the nodes above the skeleton scale its axes unequally; their mean was kept");
  }
  rest.above_scale = above_parts.scale.mean();
  rest.above_rotation = to_y_up * above_parts.rotation;
  rest.above_translation = to_y_up * above_parts.translation;
  bool unequal = false;
  for (size_t j = 0; j < rest.nodes.size(); ++j) {
    rest.local.push_back(Decompose(rest.nodes[j].node->mTransformation));
    const int parent = rest.nodes[j].parent;
    unequal |= !IsUniform(rest.local[j].scale);
    const double parent_scale = parent < 0 ? rest.above_scale : rest.world_scale[parent];
    rest.world_scale.push_back(parent_scale * rest.local[j].scale.mean());
    rest.translation_animated.push_back(
        parent >= 0 &&
        TranslationMoves(ChannelsOf(animated, *rest.nodes[j].node), rest.local[j].translation));
  }
  if (unequal) warnings.push_back("joints scale their axes unequally; their mean was kept");
  return rest;
}

std::string TakeName(const aiAnimation& animation, int index) {
  std::string name = animation.mName.C_Str();
  // A clip's name is a path: a take's name is one segment of it.
  for (char& c : name) {
    if (c == '/' || c == '\\' || static_cast<unsigned char>(c) < 0x20) c = '_';
  }
  if (name.empty() || name == "." || name == "..") name = absl::StrCat("take_", index + 1);
  return name;
}

}  // namespace

absl::StatusOr<SceneReadResult> ReadScene(absl::string_view bytes, MotionFileFormat format,
                                          const SceneReadOptions& options) {
  if (format == MotionFileFormat::kBvh) {
    return absl::InvalidArgumentError("a BVH file is read by the BVH reader");
  }
  Assimp::Importer importer;
  // Pivots kept as helper nodes would stand between a joint and its parent.
  importer.SetPropertyBool(AI_CONFIG_IMPORT_FBX_PRESERVE_PIVOTS, false);
  const std::string hint(MotionFileFormatName(format));
  const aiScene* scene = importer.ReadFileFromMemory(bytes.data(), bytes.size(), 0, hint.c_str());
  if (scene == nullptr || scene->mRootNode == nullptr) {
    const std::string error = scene == nullptr ? importer.GetErrorString() : "it has no scene";
    // A file sent alone cannot bring the files it names.
    const bool names_other_files = error.find("referenced file") != std::string::npos;
    return absl::InvalidArgumentError(absl::StrCat(
        "not a readable ", absl::AsciiStrToUpper(hint), " file: ", error,
        names_other_files ? " (send a .glb, or a .gltf with its buffers embedded)" : ""));
  }
  if (scene->mNumAnimations == 0) {
    return absl::InvalidArgumentError(absl::StrCat(
        "no skeletal animation: the file has ", scene->mNumMeshes, " mesh(es) and no animation"));
  }
  if (static_cast<int>(scene->mNumAnimations) > options.max_takes) {
    return absl::InvalidArgumentError(absl::StrCat("the file has ", scene->mNumAnimations,
                                                   " animations; at most ", options.max_takes,
                                                   " are read"));
  }
  SceneReadResult result;
  result.facts.format = format;
  result.facts.generator = MetadataText(*scene, "SourceAsset_Generator");
  Quat to_y_up;
  std::tie(result.facts.up_axis, to_y_up) = UpAxis(*scene, format);
  // FBX counts in centimetres times its unit scale factor; glTF in metres.
  result.facts.unit_m = format == MotionFileFormat::kFbx
                            ? MetadataNumber(*scene, "UnitScaleFactor").value_or(1) / 100
                            : 1.0;
  MOTIONDB_ASSIGN_OR_RETURN(RestSkeleton rest, FindSkeleton(*scene, to_y_up, result.warnings));
  MOTIONDB_ASSIGN_OR_RETURN(Skeleton skeleton, Skeleton::Create(BvhJoints(rest)));
  const auto shared = std::make_shared<const Skeleton>(std::move(skeleton));
  absl::flat_hash_set<std::string> take_names;
  for (unsigned a = 0; a < scene->mNumAnimations; ++a) {
    const aiAnimation& animation = *scene->mAnimations[a];
    MOTIONDB_ASSIGN_OR_RETURN(TakeTiming timing, Timing(animation, format));
    MOTIONDB_ASSIGN_OR_RETURN(
        Clip clip, SampleTake(animation, rest, shared, timing, options, result.warnings));
    std::string name = TakeName(animation, static_cast<int>(a));
    while (!take_names.insert(name).second) name += "_";
    result.takes.push_back({std::move(name), std::move(clip)});
  }
  return result;
}

}  // namespace motiondb
