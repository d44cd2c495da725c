#include "server/grpc/clip_conversion.h"

#include <string>
#include <utility>

#include "absl/strings/str_join.h"
#include "server/edit/provenance.h"
#include "server/grpc/internal/field_conversion.h"
#include "util/byte_coding.h"
#include "util/name_text.h"
#include "util/status_macros.h"

namespace motiondb::server {
namespace {

absl::StatusOr<OnConflict> FromProto(v1::OnConflict on_conflict) {
  switch (on_conflict) {
    case v1::ON_CONFLICT_UNSPECIFIED:
      return OnConflict::kSkipIdentical;
    case v1::ON_CONFLICT_ERROR:
      return OnConflict::kError;
    case v1::ON_CONFLICT_SKIP:
      return OnConflict::kSkip;
    case v1::ON_CONFLICT_REPLACE:
      return OnConflict::kReplace;
    default:
      return UnknownValue("on_conflict", on_conflict);
  }
}

v1::IngestResult ToProto(IngestResult result) {
  switch (result) {
    case IngestResult::kStored:
      return v1::INGEST_RESULT_STORED;
    case IngestResult::kSkipped:
      return v1::INGEST_RESULT_SKIPPED;
    case IngestResult::kReplaced:
      return v1::INGEST_RESULT_REPLACED;
  }
  return v1::INGEST_RESULT_UNSPECIFIED;
}

// IngestClipRequest and the first IngestClipStreamRequest carry the same fields.
template <typename Message>
absl::StatusOr<IngestRequest> IngestRequestOf(const Message& message) {
  IngestRequest request;
  request.file_name = message.file_name();
  request.name = message.name();
  request.tags.assign(message.tags().begin(), message.tags().end());
  MOTIONDB_ASSIGN_OR_RETURN(request.on_conflict, FromProto(message.on_conflict()));
  return request;
}

// INVALID_ARGUMENT "FIELD: 'Tail' is not a slot (Hips, Spine, ...)".
absl::StatusOr<HumanoidSlot> SlotFromProto(const std::string& field, const std::string& name) {
  const std::optional<HumanoidSlot> slot = ParseHumanoidSlot(name);
  if (slot) return *slot;
  std::vector<std::string> names;
  for (const HumanoidSlot known : AllHumanoidSlots()) names.emplace_back(HumanoidSlotName(known));
  return absl::InvalidArgumentError(absl::StrCat(field, ": '", ValidUtf8(name.substr(0, 128)),
                                                 "' is not a slot (", absl::StrJoin(names, ", "),
                                                 ")"));
}

void ToProto(const storage::SkeletonSummary& summary, v1::Skeleton* skeleton) {
  skeleton->set_skeleton_id(summary.skeleton_id);
  skeleton->set_name(ValidUtf8(SkeletonName(summary)));
  skeleton->set_joint_count(summary.joint_count);
  skeleton->set_clip_count(summary.clip_count);
  skeleton->set_root_joint(ValidUtf8(summary.root_joint));
}

}  // namespace

ClipSelection FromProto(const v1::ClipRange& range) {
  return {range.clip_id(), Optional(range.has_first_frame(), range.first_frame()),
          Optional(range.has_last_frame(), range.last_frame())};
}

absl::StatusOr<IngestRequest> FromProto(const v1::IngestClipRequest& request) {
  return IngestRequestOf(request);
}

absl::StatusOr<IngestRequest> FromProto(const v1::IngestClipStreamRequest& first) {
  return IngestRequestOf(first);
}

storage::ClipUpdate FromProto(const v1::UpdateClipRequest& request) {
  storage::ClipUpdate update;
  if (request.has_name()) update.name = request.name();
  update.add_tags.assign(request.add_tags().begin(), request.add_tags().end());
  update.remove_tags.assign(request.remove_tags().begin(), request.remove_tags().end());
  return update;
}

ClipListRequest FromProto(const v1::ListClipsRequest& request) {
  return {.page = {request.page_size(), request.page_token()},
          .tag = request.tag(),
          .name_contains = request.name_contains(),
          .sort = request.sort(),
          .skeleton_id = request.skeleton_id(),
          .descriptor = request.descriptor_name()};
}

PosesRequest FromProto(const v1::GetClipPosesRequest& request) {
  return {FromProto(request.clip()), Optional(request.has_max_rate(), request.max_rate())};
}

void ToProto(const storage::ClipRecord& record, v1::Clip* clip) {
  const double fps = record.frame_time > 0 ? 1.0 / record.frame_time : 0.0;
  clip->set_clip_id(record.clip_id);
  clip->set_name(record.name);
  clip->set_source_file(record.source_file);
  for (const std::string& tag : record.tags) clip->add_tags(tag);
  clip->set_skeleton_id(record.skeleton_id);
  clip->set_created_unix_ms(record.created_unix_ms);
  clip->set_frame_count(static_cast<int32_t>(record.frame_count));
  clip->set_fps(fps);
  clip->set_duration_s(fps > 0 ? record.frame_count / fps : 0.0);
  clip->set_joint_count(record.joint_count);
  clip->set_content_hash(record.content_hash);
  if (const std::optional<Provenance> provenance = ParseProvenance(record.provenance)) {
    v1::Provenance* out = clip->mutable_provenance();
    out->set_operator_(provenance->op);
    out->set_space(provenance->space);
    for (const SourceRange& source : provenance->sources) {
      v1::ClipRange* range = out->add_sources();
      range->set_clip_id(source.clip_id);
      range->set_first_frame(source.frames.first);
      range->set_last_frame(source.frames.last);
    }
    out->set_parameters_json(provenance->parameters_json);
  }
  if (!record.source_facts.format.empty()) {
    v1::FileFacts* source = clip->mutable_source();
    source->set_format(record.source_facts.format);
    source->set_unit_m(record.source_facts.unit_m);
    source->set_up_axis(record.source_facts.up_axis);
  }
}

// Outside the anonymous namespace, whose ToProto would hide the record's.
static void TakeToProto(const IngestOutcome& outcome, v1::IngestClipResponse* response) {
  ToProto(outcome.clip, response->mutable_clip());
  response->set_take(outcome.take);
  for (const std::string& warning : outcome.warnings) response->add_warnings(warning);
  for (const std::string& space : outcome.spaces) response->add_projected_spaces(space);
  response->set_result(ToProto(outcome.result));
  response->set_replaced_clip_id(outcome.replaced_clip_id);
  for (const storage::ClipRecord& duplicate : outcome.duplicates) {
    v1::ClipRef* same = response->add_duplicate_of();
    same->set_clip_id(duplicate.clip_id);
    same->set_name(duplicate.name);
  }
}

void ToProto(const IngestedFile& file, v1::IngestClipResponse* response) {
  for (size_t i = 0; i < file.clips.size(); ++i) {
    TakeToProto(file.clips[i], i == 0 ? response : response->add_more_takes());
  }
  v1::FileFacts* facts = response->mutable_file();
  facts->set_format(std::string(MotionFileFormatName(file.format)));
  facts->set_unit_m(file.unit_m);
  if (file.up_axis != 0) facts->set_up_axis(std::string(1, file.up_axis));
  facts->set_generator(file.generator);
}

absl::StatusOr<ExportFormat> ExportFormatFromProto(const std::string& format) {
  if (format.empty() || format == "bvh") return ExportFormat::kBvh;
  if (format == "gltf") return ExportFormat::kGltf;
  if (format == "glb") return ExportFormat::kGlb;
  return absl::InvalidArgumentError(
      absl::StrCat("format: '", format, "' is none of bvh, gltf, glb"));
}

void ToProto(ExportedFile&& exported, v1::ExportClipResponse* response) {
  response->set_bvh(std::move(exported.bytes));
  response->set_file_name(exported.file_name);
  response->set_first_frame(exported.frames.first);
  response->set_last_frame(exported.frames.last);
}

void ToProto(const storage::ClipPage& page, v1::ListClipsResponse* response) {
  for (const storage::ClipRecord& record : page.clips) ToProto(record, response->add_clips());
  response->set_next_page_token(page.next_page_token);
  response->set_total_size(page.total_size);
}

void ToProto(const ClipPoses& poses, v1::ClipPoses* response) {
  response->set_clip_id(poses.clip_id);
  for (const std::string& name : poses.joint_names) response->add_joint_names(ValidUtf8(name));
  for (const int parent : poses.parents) response->add_parents(parent);
  response->set_sample_rate(poses.sample_rate);
  response->set_frames(static_cast<int32_t>(poses.positions.rows()));
  response->set_first_frame(poses.frames.first);
  response->set_last_frame(poses.frames.last);
  AppendFloat32s(poses.positions.data(), poses.positions.size(), response->mutable_positions());
}

void ToProto(const storage::ClipLayout& layout, v1::Clip* clip) {
  ToProto(layout.record, clip);
  for (const Joint& joint : layout.skeleton->joints()) clip->add_joint_names(ValidUtf8(joint.name));
}

absl::StatusOr<storage::SlotOverrideChange> FromProto(const v1::MapSkeletonRequest& request) {
  storage::SlotOverrideChange change;
  for (int i = 0; i < request.set_size(); ++i) {
    MOTIONDB_ASSIGN_OR_RETURN(
        const HumanoidSlot slot,
        SlotFromProto(absl::StrCat("set[", i, "].slot"), request.set(i).slot()));
    change.set.push_back({slot, request.set(i).joint()});
  }
  for (int i = 0; i < request.clear_size(); ++i) {
    MOTIONDB_ASSIGN_OR_RETURN(const HumanoidSlot slot,
                              SlotFromProto(absl::StrCat("clear[", i, "]"), request.clear(i)));
    change.clear.push_back(slot);
  }
  return change;
}

void ToProto(const SkeletonMapView& view, v1::SkeletonDetail* detail) {
  ToProto(view.record.summary, detail->mutable_skeleton());
  const Skeleton& skeleton = *view.record.skeleton;
  const auto name = [&](int joint) { return ValidUtf8(skeleton.joint(joint).name); };
  for (int j = 0; j < skeleton.joint_count(); ++j) {
    v1::SkeletonJoint* joint = detail->add_joints();
    joint->set_name(name(j));
    joint->set_parent(skeleton.joint(j).parent);
  }
  v1::HumanoidMap* map = detail->mutable_humanoid_map();
  for (const HumanoidSlot slot : AllHumanoidSlots()) {
    const int joint = view.map.joint(slot);
    if (joint < 0) continue;
    v1::HumanoidSlot* shown = map->add_slots();
    shown->set_slot(std::string(HumanoidSlotName(slot)));
    shown->set_joint(joint);
    shown->set_joint_name(name(joint));
    shown->set_overridden(view.overridden[static_cast<int>(slot)]);
    shown->set_required(IsRequiredSlot(slot));
  }
  for (const HumanoidSlot slot : view.map.missing) {
    map->add_missing_slots(std::string(HumanoidSlotName(slot)));
  }
  map->set_complete(view.map.complete());
  for (const auto& [left, right] : view.map.mirror_pairs) {
    v1::JointPair* pair = map->add_mirror_pairs();
    pair->set_left(left);
    pair->set_right(right);
    pair->set_left_name(name(left));
    pair->set_right_name(name(right));
  }
}

void ToProto(const std::vector<storage::SkeletonSummary>& skeletons,
             v1::ListSkeletonsResponse* response) {
  for (const storage::SkeletonSummary& skeleton : skeletons) {
    ToProto(skeleton, response->add_skeletons());
  }
}

}  // namespace motiondb::server
