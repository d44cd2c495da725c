#include "server/clip_ingest.h"

#include <utility>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "util/status_macros.h"

namespace motiondb::server {

absl::StatusOr<std::string> ClipName(const IngestRequest& request) {
  if (request.file_name.empty()) return absl::InvalidArgumentError("file_name is required");
  if (!request.name.empty()) return request.name;
  absl::string_view base = request.file_name;
  if (const size_t slash = base.find_last_of("/\\"); slash != absl::string_view::npos) {
    base.remove_prefix(slash + 1);
  }
  if (absl::EndsWithIgnoreCase(base, ".bvh")) base.remove_suffix(4);
  if (base.empty()) {
    return absl::InvalidArgumentError(
        absl::StrCat("file_name '", request.file_name, "' leaves no clip name; give `name`"));
  }
  return std::string(base);
}

absl::StatusOr<IngestOutcome> IngestUpload(Catalog& catalog, const IngestRequest& request,
                                           absl::string_view bvh, const UploadLimits& limits,
                                           const std::function<bool()>& should_stop) {
  // The name is checked before the file is parsed, as a stream checks it before it is read.
  MOTIONDB_RETURN_IF_ERROR(ClipName(request).status());
  MOTIONDB_ASSIGN_OR_RETURN(BvhReadResult read,
                            ReadUpload(bvh, request.file_name, limits, should_stop));
  return IngestParsedUpload(catalog, request, std::move(read), should_stop);
}

absl::StatusOr<IngestOutcome> IngestParsedUpload(Catalog& catalog, const IngestRequest& request,
                                                 BvhReadResult read,
                                                 const std::function<bool()>& should_stop) {
  storage::ClipRecord record;
  MOTIONDB_ASSIGN_OR_RETURN(record.name, ClipName(request));
  record.source_file = request.file_name;
  record.tags = request.tags;
  MOTIONDB_ASSIGN_OR_RETURN(
      IngestedClip ingested,
      catalog.IngestClip(record, read.clip, request.on_conflict, should_stop));
  IngestOutcome outcome;
  outcome.clip = std::move(ingested.record);
  outcome.result = ingested.result;
  outcome.replaced_clip_id = ingested.replaced_clip_id;
  outcome.warnings = std::move(read.warnings);
  // Said in the warnings too, which clients print, since the fields are easy to overlook.
  for (const storage::ClipRecord& duplicate : ingested.duplicates) {
    outcome.warnings.push_back(
        absl::StrCat("identical content to clip ", duplicate.clip_id, " '", duplicate.name, "'"));
  }
  outcome.duplicates = std::move(ingested.duplicates);
  outcome.spaces = std::move(ingested.spaces);
  return outcome;
}

}  // namespace motiondb::server
