#include "server/clip_ingest.h"

#include <utility>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "util/status_macros.h"

namespace motiondb::server {
namespace {

// The extensions a file name loses to make a clip's name.
constexpr absl::string_view kMotionExtensions[] = {".bvh", ".fbx", ".glb", ".gltf"};

// What a file said of itself, kept with each of its clips; nothing for a BVH.
storage::SourceFacts FactsOf(const UploadedFile& file) {
  storage::SourceFacts facts;
  if (file.format == MotionFileFormat::kBvh) return facts;
  facts.format = std::string(MotionFileFormatName(file.format));
  facts.unit_m = file.unit_m;
  if (file.up_axis != 0) facts.up_axis = std::string(1, file.up_axis);
  return facts;
}

absl::StatusOr<IngestOutcome> IngestTake(Catalog& catalog, const IngestRequest& request,
                                         std::string name, UploadedTake take,
                                         const storage::SourceFacts& facts,
                                         std::vector<std::string> warnings,
                                         const std::function<bool()>& should_stop) {
  storage::ClipRecord record;
  record.name = std::move(name);
  record.source_file = request.file_name;
  record.tags = request.tags;
  record.source_facts = facts;
  MOTIONDB_ASSIGN_OR_RETURN(
      IngestedClip ingested,
      catalog.IngestClip(record, take.clip,
                         {.on_conflict = request.on_conflict,
                          .clip_id = request.routed ? request.routed->clip_id : 0},
                         should_stop));
  IngestOutcome outcome;
  outcome.clip = std::move(ingested.record);
  outcome.result = ingested.result;
  outcome.replaced_clip_id = ingested.replaced_clip_id;
  outcome.warnings = std::move(warnings);
  // Said in the warnings too, which clients print, since the fields are easy to overlook.
  for (const storage::ClipRecord& duplicate : ingested.duplicates) {
    outcome.warnings.push_back(
        absl::StrCat("identical content to clip ", duplicate.clip_id, " '", duplicate.name, "'"));
  }
  outcome.duplicates = std::move(ingested.duplicates);
  outcome.spaces = std::move(ingested.spaces);
  outcome.take = std::move(take.name);
  return outcome;
}

}  // namespace

absl::StatusOr<std::string> ClipName(const IngestRequest& request) {
  if (request.file_name.empty()) return absl::InvalidArgumentError("file_name is required");
  if (!request.name.empty()) return request.name;
  absl::string_view base = request.file_name;
  if (const size_t slash = base.find_last_of("/\\"); slash != absl::string_view::npos) {
    base.remove_prefix(slash + 1);
  }
  for (absl::string_view extension : kMotionExtensions) {
    if (absl::EndsWithIgnoreCase(base, extension)) base.remove_suffix(extension.size());
  }
  if (base.empty()) {
    return absl::InvalidArgumentError(
        absl::StrCat("file_name '", request.file_name, "' leaves no clip name; give `name`"));
  }
  return std::string(base);
}

absl::StatusOr<IngestedFile> IngestUpload(Catalog& catalog, const IngestRequest& request,
                                          absl::string_view bytes, const UploadLimits& limits,
                                          const std::function<bool()>& should_stop) {
  // The name is checked before the file is parsed, as a stream checks it before it is read.
  MOTIONDB_RETURN_IF_ERROR(ClipName(request).status());
  MOTIONDB_ASSIGN_OR_RETURN(UploadedFile file,
                            ReadUpload(bytes, request.file_name, limits, should_stop));
  return IngestParsedUpload(catalog, request, std::move(file), should_stop);
}

std::string TakeClipName(const std::string& name, const UploadedFile& file, size_t take) {
  return file.takes.size() > 1 ? absl::StrCat(name, "/", file.takes[take].name) : name;
}

absl::Status TakeFailure(const absl::Status& status, const std::string& take_name,
                         const std::vector<std::string>& stored) {
  if (stored.empty()) return status;
  return absl::Status(status.code(), absl::StrCat("take '", take_name, "': ", status.message(),
                                                  " (the takes before it were stored: ",
                                                  absl::StrJoin(stored, ", "), ")"));
}

absl::StatusOr<IngestedFile> IngestParsedUpload(Catalog& catalog, const IngestRequest& request,
                                                UploadedFile file,
                                                const std::function<bool()>& should_stop) {
  MOTIONDB_ASSIGN_OR_RETURN(const std::string name, ClipName(request));
  IngestedFile ingested;
  ingested.format = file.format;
  ingested.unit_m = file.unit_m;
  ingested.up_axis = file.up_axis;
  ingested.generator = std::move(file.generator);
  const storage::SourceFacts facts = FactsOf(file);
  if (request.routed && (request.routed->take < 0 ||
                         static_cast<size_t>(request.routed->take) >= file.takes.size())) {
    return absl::InvalidArgumentError(absl::StrCat("take ", request.routed->take, ": '",
                                                   request.file_name, "' has ", file.takes.size(),
                                                   " takes"));
  }
  std::vector<std::string> stored;
  for (size_t t = 0; t < file.takes.size(); ++t) {
    if (request.routed && static_cast<size_t>(request.routed->take) != t) continue;
    const std::string take_name = TakeClipName(name, file, t);
    UploadedTake& take = file.takes[t];
    // The file's warnings go with its first clip (a routed file's, with its first take).
    const bool first = ingested.clips.empty() && (!request.routed || t == 0);
    absl::StatusOr<IngestOutcome> outcome =
        IngestTake(catalog, request, take_name, std::move(take), facts,
                   first ? std::move(file.warnings) : std::vector<std::string>(), should_stop);
    if (!outcome.ok()) return TakeFailure(outcome.status(), take_name, stored);
    stored.push_back(take_name);
    ingested.clips.push_back(*std::move(outcome));
  }
  return ingested;
}

}  // namespace motiondb::server
