#include "server/grpc/clip_service.h"

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "core/bvh/bvh_reader.h"
#include "core/bvh/bvh_writer.h"
#include "server/frame_conversion.h"
#include "server/grpc/status_conversion.h"
#include "server/paging.h"
#include "util/status_macros.h"

namespace motiondb::server {
namespace {

// The clip's name: `name` when given, else the file name without folders and `.bvh`. Lengths
// and characters of names and tags are the database's to check.
absl::StatusOr<std::string> ClipName(const std::string& file_name, const std::string& name) {
  if (file_name.empty()) return absl::InvalidArgumentError("file_name is required");
  if (!name.empty()) return name;
  absl::string_view base = file_name;
  if (const size_t slash = base.find_last_of("/\\"); slash != absl::string_view::npos) {
    base.remove_prefix(slash + 1);
  }
  if (absl::EndsWithIgnoreCase(base, ".bvh")) base.remove_suffix(4);
  if (base.empty()) {
    return absl::InvalidArgumentError(
        absl::StrCat("file_name '", file_name, "' leaves no clip name; give `name`"));
  }
  return std::string(base);
}

absl::Status TooLarge(int64_t bytes, int64_t limit) {
  return absl::ResourceExhaustedError(absl::StrCat("the BVH file is ", bytes,
                                                   " bytes or more; this server accepts at most ",
                                                   limit, " (--max-bvh-mb)"));
}

void FillClip(const storage::ClipRecord& record, const ClipFacts& facts, v1::Clip* clip) {
  clip->set_clip_id(record.clip_id);
  clip->set_name(record.name);
  clip->set_source_file(record.source_file);
  for (const std::string& tag : record.tags) clip->add_tags(tag);
  clip->set_skeleton_id(record.skeleton_id);
  clip->set_created_unix_ms(record.created_unix_ms);
  clip->set_frame_count(facts.frame_count);
  clip->set_fps(facts.fps);
  clip->set_duration_s(facts.fps > 0 ? facts.frame_count / facts.fps : 0.0);
  clip->set_joint_count(facts.joint_count);
}

}  // namespace

absl::Status ClipServiceImpl::Ingest(const std::string& file_name, const std::string& name,
                                     const std::vector<std::string>& tags, absl::string_view bvh,
                                     v1::IngestClipResponse* response) {
  storage::ClipRecord record;
  MOTIONDB_ASSIGN_OR_RETURN(record.name, ClipName(file_name, name));
  record.source_file = file_name;
  record.tags = tags;
  if (static_cast<int64_t>(bvh.size()) > options_.max_bvh_bytes) {
    return TooLarge(static_cast<int64_t>(bvh.size()), options_.max_bvh_bytes);
  }
  BvhReadOptions read_options;
  read_options.max_bytes = options_.max_bvh_bytes;
  absl::StatusOr<BvhReadResult> read = ReadBvh(bvh, read_options);
  if (!read.ok()) {
    // "walk.bvh: line 19: expected ..." keeps the reader's line number.
    return absl::Status(read.status().code(),
                        absl::StrCat(file_name, ": ", read.status().message()));
  }
  MOTIONDB_ASSIGN_OR_RETURN(const IngestedClip ingested, library_.IngestClip(record, read->clip));
  MOTIONDB_ASSIGN_OR_RETURN(const storage::ClipRecord stored,
                            database_.GetClipRecord(ingested.clip_id));
  FillClip(stored, ClipFacts::Of(read->clip), response->mutable_clip());
  for (const std::string& warning : read->warnings) response->add_warnings(warning);
  for (const std::string& space : ingested.spaces) response->add_projected_spaces(space);
  return absl::OkStatus();
}

grpc::Status ClipServiceImpl::IngestClip(grpc::ServerContext* /*context*/,
                                         const v1::IngestClipRequest* request,
                                         v1::IngestClipResponse* response) {
  const std::vector<std::string> tags(request->tags().begin(), request->tags().end());
  return ToGrpcStatus(
      Ingest(request->file_name(), request->name(), tags, request->bvh(), response));
}

absl::Status ClipServiceImpl::ReadStream(grpc::ServerReader<v1::IngestClipStreamRequest>* reader,
                                         v1::IngestClipResponse* response) {
  v1::IngestClipStreamRequest message;
  if (!reader->Read(&message)) {
    return absl::InvalidArgumentError("the stream is empty: the first message needs file_name");
  }
  const std::string file_name = message.file_name();
  const std::string name = message.name();
  const std::vector<std::string> tags(message.tags().begin(), message.tags().end());
  // Refused before the upload is read: a stream without a file name would be read in vain.
  MOTIONDB_RETURN_IF_ERROR(ClipName(file_name, name).status());
  std::string bvh;
  do {
    // Checked as chunks arrive, so an oversize upload is refused before it is all buffered.
    if (static_cast<int64_t>(bvh.size() + message.chunk().size()) > options_.max_bvh_bytes) {
      return TooLarge(static_cast<int64_t>(bvh.size() + message.chunk().size()),
                      options_.max_bvh_bytes);
    }
    bvh += message.chunk();
  } while (reader->Read(&message));
  return Ingest(file_name, name, tags, bvh, response);
}

grpc::Status ClipServiceImpl::IngestClipStream(
    grpc::ServerContext* /*context*/, grpc::ServerReader<v1::IngestClipStreamRequest>* reader,
    v1::IngestClipResponse* response) {
  return ToGrpcStatus(ReadStream(reader, response));
}

absl::Status ClipServiceImpl::List(const v1::ListClipsRequest& request,
                                   v1::ListClipsResponse* response) {
  storage::Page page;
  MOTIONDB_ASSIGN_OR_RETURN(page.page_size, ResolvePageSize(request.page_size()));
  page.page_token = request.page_token();
  MOTIONDB_ASSIGN_OR_RETURN(const storage::ClipPage clips,
                            database_.ListClips(page, request.tag()));
  for (const storage::ClipRecord& record : clips.clips) {
    absl::StatusOr<ClipFacts> facts = facts_.Get(record.clip_id);
    if (absl::IsNotFound(facts.status())) continue;  // deleted since the page was read
    if (!facts.ok()) return facts.status();
    FillClip(record, *facts, response->add_clips());
  }
  response->set_next_page_token(clips.next_page_token);
  return absl::OkStatus();
}

grpc::Status ClipServiceImpl::ListClips(grpc::ServerContext* /*context*/,
                                        const v1::ListClipsRequest* request,
                                        v1::ListClipsResponse* response) {
  return ToGrpcStatus(List(*request, response));
}

absl::Status ClipServiceImpl::Get(int64_t clip_id, v1::Clip* response) {
  MOTIONDB_ASSIGN_OR_RETURN(const storage::StoredClip stored, database_.GetClip(clip_id));
  const ClipFacts facts = ClipFacts::Of(stored.clip);
  facts_.Put(clip_id, facts);
  FillClip(stored.record, facts, response);
  for (const Joint& joint : stored.clip.skeleton().joints()) response->add_joint_names(joint.name);
  return absl::OkStatus();
}

grpc::Status ClipServiceImpl::GetClip(grpc::ServerContext* /*context*/,
                                      const v1::GetClipRequest* request, v1::Clip* response) {
  return ToGrpcStatus(Get(request->clip_id(), response));
}

grpc::Status ClipServiceImpl::DeleteClip(grpc::ServerContext* /*context*/,
                                         const v1::DeleteClipRequest* request,
                                         v1::DeleteClipResponse* /*response*/) {
  return ToGrpcStatus(library_.DeleteClip(request->clip_id()));
}

absl::Status ClipServiceImpl::Export(const v1::ClipRange& range, v1::ExportClipResponse* response) {
  MOTIONDB_ASSIGN_OR_RETURN(const storage::StoredClip stored, database_.GetClip(range.clip_id()));
  MOTIONDB_ASSIGN_OR_RETURN(const FrameRange frames,
                            ResolveFrameRange(range, stored.clip.frame_count(), "clip"));
  MOTIONDB_ASSIGN_OR_RETURN(*response->mutable_bvh(), WriteBvh(stored.clip, frames));
  const bool whole = frames.first == 0 && frames.last == stored.clip.frame_count() - 1;
  response->set_file_name(
      whole ? absl::StrCat(stored.record.name, ".bvh")
            : absl::StrCat(stored.record.name, "_", frames.first, "-", frames.last, ".bvh"));
  response->set_first_frame(frames.first);
  response->set_last_frame(frames.last);
  return absl::OkStatus();
}

grpc::Status ClipServiceImpl::ExportClip(grpc::ServerContext* /*context*/,
                                         const v1::ExportClipRequest* request,
                                         v1::ExportClipResponse* response) {
  return ToGrpcStatus(Export(request->clip(), response));
}

}  // namespace motiondb::server
