#include "core/gltf/gltf_writer.h"

#include <tiny_gltf.h>

#include <cstring>
#include <sstream>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "util/status_macros.h"

namespace motiondb {
namespace {

// JSON a joint costs at most: its node, skin entry, two channels and samplers, two accessors
// and buffer views (measured about 600 bytes with a short name; the rest is room).
constexpr int64_t kJsonBytesPerJoint = 1024;
constexpr int64_t kJsonFixedBytes = 4096;

// Appends `values` to the buffer as a view and an accessor of `type` floats; returns the
// accessor's index.
int AddFloats(tinygltf::Model& model, const std::vector<float>& values, int type, size_t count,
              std::vector<double> min = {}, std::vector<double> max = {}) {
  std::vector<unsigned char>& data = model.buffers[0].data;
  tinygltf::BufferView view;
  view.buffer = 0;
  view.byteOffset = data.size();
  view.byteLength = values.size() * sizeof(float);
  const size_t at = data.size();
  data.resize(at + view.byteLength);
  std::memcpy(data.data() + at, values.data(), view.byteLength);
  model.bufferViews.push_back(view);
  tinygltf::Accessor accessor;
  accessor.bufferView = static_cast<int>(model.bufferViews.size()) - 1;
  accessor.byteOffset = 0;
  accessor.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT;
  accessor.type = type;
  accessor.count = count;
  accessor.minValues = std::move(min);
  accessor.maxValues = std::move(max);
  model.accessors.push_back(std::move(accessor));
  return static_cast<int>(model.accessors.size()) - 1;
}

void AddChannel(tinygltf::Animation& animation, int input, int output, int node, const char* path) {
  tinygltf::AnimationSampler sampler;
  sampler.input = input;
  sampler.output = output;
  sampler.interpolation = "LINEAR";
  animation.samplers.push_back(std::move(sampler));
  tinygltf::AnimationChannel channel;
  channel.sampler = static_cast<int>(animation.samplers.size()) - 1;
  channel.target_node = node;
  channel.target_path = path;
  animation.channels.push_back(std::move(channel));
}

}  // namespace

int64_t GltfBound(const Skeleton& skeleton, int64_t frames, int64_t name_bytes) {
  const int64_t floats_a_frame =
      1 + 4 * int64_t{skeleton.joint_count()} + 3 * int64_t{skeleton.position_joint_count()};
  const int64_t binary = frames * floats_a_frame * 4 + 64 * int64_t{skeleton.joint_count()};
  int64_t names = 2 * name_bytes;
  for (const Joint& joint : skeleton.joints()) names += 4 * static_cast<int64_t>(joint.name.size());
  // A .gltf holds the buffer as base64: 4 bytes for 3.
  return binary / 3 * 4 + 4 + kJsonFixedBytes + kJsonBytesPerJoint * skeleton.joint_count() + names;
}

absl::StatusOr<std::string> WriteGltf(const Clip& clip, const GltfWriteOptions& options) {
  const FrameRange range = options.range.value_or(FrameRange{0, clip.frame_count() - 1});
  MOTIONDB_RETURN_IF_ERROR(CheckFrameRange(range, clip.frame_count()));
  const Skeleton& skeleton = clip.skeleton();
  const int joints = skeleton.joint_count();
  const size_t frames = static_cast<size_t>(range.size());
  const std::string name = options.name.empty() ? "motion" : options.name;

  tinygltf::Model model;
  model.asset.version = "2.0";
  model.asset.generator = "motiondb";
  model.buffers.resize(1);
  model.nodes.resize(joints);
  for (int j = 0; j < joints; ++j) {
    const Joint& joint = skeleton.joint(j);
    tinygltf::Node& node = model.nodes[j];
    node.name = joint.name;
    node.translation = {joint.offset.x(), joint.offset.y(), joint.offset.z()};
    if (joint.parent >= 0) model.nodes[joint.parent].children.push_back(j);
  }
  // End sites as leaves, so that a viewer draws the last bone of each chain.
  for (int j = 0; j < joints; ++j) {
    const Joint& joint = skeleton.joint(j);
    if (!joint.end_site) continue;
    tinygltf::Node end;
    end.name = joint.name + "_end";
    end.translation = {joint.end_site->x(), joint.end_site->y(), joint.end_site->z()};
    model.nodes.push_back(std::move(end));
    model.nodes[j].children.push_back(static_cast<int>(model.nodes.size()) - 1);
  }
  tinygltf::Scene scene;
  scene.name = name;
  scene.nodes = {0};
  model.scenes.push_back(std::move(scene));
  model.defaultScene = 0;

  // The rest pose the skin binds to: every joint at its offset, unturned.
  std::vector<Eigen::Vector3d> rest(joints);
  std::vector<float> inverse_binds;
  tinygltf::Skin skin;
  skin.name = name;
  skin.skeleton = 0;
  for (int j = 0; j < joints; ++j) {
    const int parent = skeleton.joint(j).parent;
    rest[j] = (parent < 0 ? Eigen::Vector3d::Zero() : rest[parent]) + skeleton.joint(j).offset;
    // Column-major 4x4: identity with the translation -rest.
    const float m[16] = {1,
                         0,
                         0,
                         0,
                         0,
                         1,
                         0,
                         0,
                         0,
                         0,
                         1,
                         0,
                         static_cast<float>(-rest[j].x()),
                         static_cast<float>(-rest[j].y()),
                         static_cast<float>(-rest[j].z()),
                         1};
    inverse_binds.insert(inverse_binds.end(), m, m + 16);
    skin.joints.push_back(j);
  }
  skin.inverseBindMatrices = AddFloats(model, inverse_binds, TINYGLTF_TYPE_MAT4, joints);
  model.skins.push_back(std::move(skin));

  tinygltf::Animation animation;
  animation.name = name;
  std::vector<float> times(frames);
  for (size_t f = 0; f < frames; ++f) times[f] = static_cast<float>(f * clip.frame_time());
  const int input =
      AddFloats(model, times, TINYGLTF_TYPE_SCALAR, frames, {times.front()}, {times.back()});
  std::vector<float> values;
  for (int j = 0; j < joints; ++j) {
    values.clear();
    for (size_t f = 0; f < frames; ++f) {
      const Quat q = clip.rotation(range.first + static_cast<int>(f), j);
      values.insert(values.end(), {static_cast<float>(q.x()), static_cast<float>(q.y()),
                                   static_cast<float>(q.z()), static_cast<float>(q.w())});
    }
    AddChannel(animation, input, AddFloats(model, values, TINYGLTF_TYPE_VEC4, frames), j,
               "rotation");
    const int slot = skeleton.position_slot(j);
    if (slot < 0) continue;
    values.clear();
    for (size_t f = 0; f < frames; ++f) {
      const auto position =
          clip.positions().block<1, 3>(range.first + static_cast<int>(f), 3 * slot);
      values.insert(values.end(),
                    {static_cast<float>(position.x()), static_cast<float>(position.y()),
                     static_cast<float>(position.z())});
    }
    AddChannel(animation, input, AddFloats(model, values, TINYGLTF_TYPE_VEC3, frames), j,
               "translation");
  }
  model.animations.push_back(std::move(animation));
  model.buffers[0].name = name;

  std::ostringstream out;
  tinygltf::TinyGLTF writer;
  if (!writer.WriteGltfSceneToStream(&model, out, /*prettyPrint=*/false, options.binary)) {
    return absl::InternalError("tinygltf could not write the file");
  }
  return std::move(out).str();
}

}  // namespace motiondb
