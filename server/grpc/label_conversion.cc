#include "server/grpc/label_conversion.h"

#include <optional>
#include <string>

#include "server/grpc/internal/field_conversion.h"
#include "util/status_macros.h"

namespace motiondb::server {
namespace {

// A filter's origin: unspecified is any.
absl::StatusOr<std::optional<storage::LabelOrigin>> FromProto(v1::LabelOrigin origin) {
  switch (origin) {
    case v1::LABEL_ORIGIN_UNSPECIFIED:
      return std::nullopt;
    case v1::LABEL_ORIGIN_MANUAL:
      return storage::LabelOrigin::kManual;
    case v1::LABEL_ORIGIN_PROPAGATED:
      return storage::LabelOrigin::kPropagated;
    default:
      return UnknownValue("origin", origin);
  }
}

// ListLabelsResponse and FindLabelsResponse: a page of labels.
template <typename Response>
void PageToProto(const storage::LabelPage& page, Response* response) {
  for (const storage::LabelRecord& record : page.labels) ToProto(record, response->add_labels());
  response->set_next_page_token(page.next_page_token);
}

}  // namespace

std::vector<NewLabel> FromProto(const v1::AddLabelsRequest& request) {
  std::vector<NewLabel> labels;
  labels.reserve(request.labels_size());
  for (const v1::NewLabel& label : request.labels()) {
    labels.push_back({.clip_id = label.clip_id(),
                      .clip_name = label.clip_name(),
                      .first_frame = Optional(label.has_first_frame(), label.first_frame()),
                      .last_frame = Optional(label.has_last_frame(), label.last_frame()),
                      .start_s = Optional(label.has_start_s(), label.start_s()),
                      .end_s = Optional(label.has_end_s(), label.end_s()),
                      .descriptor = label.descriptor_name(),
                      .value = Optional(label.has_value(), label.value())});
  }
  return labels;
}

absl::StatusOr<storage::LabelFilter> FromProto(const v1::ListLabelsRequest& request) {
  storage::LabelFilter filter{.clip_id = request.clip_id(),
                              .descriptor = request.descriptor_name()};
  MOTIONDB_ASSIGN_OR_RETURN(filter.origin, FromProto(request.origin()));
  filter.min_value = Optional(request.has_min_value(), request.min_value());
  return filter;
}

absl::StatusOr<LabelDeletion> FromProto(const v1::DeleteLabelsRequest& request) {
  LabelDeletion deletion;
  deletion.label_ids.assign(request.label_ids().begin(), request.label_ids().end());
  deletion.filter.clip_id = request.clip_id();
  deletion.filter.descriptor = request.descriptor_name();
  MOTIONDB_ASSIGN_OR_RETURN(deletion.filter.origin, FromProto(request.origin()));
  return deletion;
}

storage::LabelQuery FromProto(const v1::FindLabelsRequest& request) {
  return {request.descriptor_name(), request.min_value(),
          std::vector<std::string>(request.tags().begin(), request.tags().end())};
}

void ToProto(const storage::LabelRecord& record, v1::Label* label) {
  label->set_label_id(record.label_id);
  label->set_clip_id(record.clip_id);
  label->set_clip_name(record.clip_name);
  label->set_first_frame(static_cast<int32_t>(record.first_frame));
  label->set_last_frame(static_cast<int32_t>(record.last_frame));
  label->set_start_s(record.first_frame * record.frame_time);
  label->set_end_s(record.last_frame * record.frame_time);
  label->set_descriptor_name(record.descriptor);
  label->set_value(record.value);
  label->set_origin(record.origin == storage::LabelOrigin::kManual ? v1::LABEL_ORIGIN_MANUAL
                                                                   : v1::LABEL_ORIGIN_PROPAGATED);
  label->set_source_label_id(record.source_label_id);
  label->set_space(record.space_name);
  label->set_score(record.score);
  label->set_job_id(record.job_id);
  label->set_created_unix_ms(record.created_unix_ms);
}

void ToProto(const storage::LabelPage& page, v1::ListLabelsResponse* response) {
  PageToProto(page, response);
}

void ToProto(const storage::LabelPage& page, v1::FindLabelsResponse* response) {
  PageToProto(page, response);
}

void ToProto(const ClipTimeline& timeline, v1::GetClipLabelsResponse* response) {
  const storage::ClipRecord& clip = timeline.clip;
  response->set_clip_id(clip.clip_id);
  response->set_clip_name(clip.name);
  response->set_frame_count(static_cast<int32_t>(clip.frame_count));
  response->set_fps(clip.frame_time > 0 ? 1.0 / clip.frame_time : 0.0);
  for (const storage::LabelRecord& record : timeline.labels) {
    ToProto(record, response->add_labels());
  }
  response->set_next_page_token(timeline.next_page_token);
}

void ToProto(const storage::AddedLabels& added, v1::AddLabelsResponse* response) {
  for (const storage::LabelRecord& label : added.labels) ToProto(label, response->add_labels());
  for (const size_t item : added.skipped) response->add_skipped(static_cast<int32_t>(item));
}

void ToProto(int64_t deleted, v1::DeleteLabelsResponse* response) {
  response->set_deleted(deleted);
}

}  // namespace motiondb::server
