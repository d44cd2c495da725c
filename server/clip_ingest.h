// Ingesting an uploaded BVH file (ClipService.IngestClip and IngestClipStream): the clip's name,
// the parse, and the catalogue write that stores and indexes it.
#ifndef MOTIONDB_SERVER_CLIP_INGEST_H_
#define MOTIONDB_SERVER_CLIP_INGEST_H_

#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "server/catalog.h"
#include "server/upload.h"
#include "storage/database.h"

namespace motiondb::server {

struct IngestRequest {
  // The uploaded file's name, as the client knows it (required; errors begin with it).
  std::string file_name;
  // The clip's name; empty: the file name without folders and ".bvh".
  std::string name;
  std::vector<std::string> tags;
};

struct IngestOutcome {
  storage::ClipRecord clip;           // as stored, with its id and skeleton
  std::vector<std::string> warnings;  // the reader's, e.g. a Frames: header that disagrees
  std::vector<std::string> spaces;    // projected into
};

// The clip's name for `request`; INVALID_ARGUMENT without a file name, or when the file name
// leaves no name. Lengths and characters of names and tags are the database's to check.
absl::StatusOr<std::string> ClipName(const IngestRequest& request);

// Parses, stores and indexes one uploaded file.
absl::StatusOr<IngestOutcome> IngestUpload(Catalog& catalog, const IngestRequest& request,
                                           absl::string_view bvh, const UploadLimits& limits);

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_CLIP_INGEST_H_
