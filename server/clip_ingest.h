// Ingesting an uploaded motion file (ClipService.IngestClip and IngestClipStream): the clips'
// names, the parse, and the catalogue writes that store and index them, a clip a take.
#ifndef MOTIONDB_SERVER_CLIP_INGEST_H_
#define MOTIONDB_SERVER_CLIP_INGEST_H_

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "server/catalog.h"
#include "server/upload/upload.h"
#include "storage/database.h"

namespace motiondb::server {

struct IngestRequest {
  // The uploaded file's name, as the client knows it (required; errors begin with it).
  std::string file_name;
  // The clip's name, which may be a relative path ("session1/take_001"); empty: the file name
  // without folders and its extension (".bvh", ".fbx", ".glb", ".gltf"). A file of several
  // takes stores each as this name, '/', and the take's name.
  std::string name;
  std::vector<std::string> tags;
  // When a clip of that name exists.
  OnConflict on_conflict = OnConflict::kSkipIdentical;
  // A cluster shard's part of an ingest its router spread over the shards: only the take of this
  // index (in the file's order) is stored, under this id. Unset: every take, the database's ids.
  struct Routed {
    int take = 0;
    int64_t clip_id = 0;
  };
  std::optional<Routed> routed;
};

struct IngestOutcome {
  storage::ClipRecord clip;  // as stored, with its id and skeleton; when skipped, the existing
  IngestResult result = IngestResult::kStored;
  int64_t replaced_clip_id = 0;                 // kReplaced: the deleted clip's id
  std::vector<storage::ClipRecord> duplicates;  // other clips of identical content
  // The reader's (e.g. a Frames: header that disagrees), then one line a duplicate.
  std::vector<std::string> warnings;
  std::vector<std::string> spaces;  // projected into
  std::string take;                 // the file's animation it holds; empty for a BVH
};

// A file's clips, one a take in the file's order, and what the file said of itself.
struct IngestedFile {
  std::vector<IngestOutcome> clips;
  MotionFileFormat format = MotionFileFormat::kBvh;
  double unit_m = 0;  // UploadedFile's
  char up_axis = 0;
  std::string generator;
};

// The clip's name for `request`; INVALID_ARGUMENT without a file name, or when the file name
// leaves no name. Lengths and characters of names and tags are the database's to check.
absl::StatusOr<std::string> ClipName(const IngestRequest& request);

// The name of the clip holding take `take` of `file` for a request whose clip name is `name`:
// `name` for a file of one take, "name/TAKE" for one of several.
std::string TakeClipName(const std::string& name, const UploadedFile& file, size_t take);
// A take's failure to be stored, after those named in `stored` were: the error, naming the take
// and the takes stored before it.
absl::Status TakeFailure(const absl::Status& status, const std::string& take_name,
                         const std::vector<std::string>& stored);

// Parses, stores and indexes one uploaded file, a clip a take, or skips them. `should_stop` is
// asked while the file is parsed (ReadUpload) and before the catalogue commits each take
// (Catalog::IngestClip). Every take is parsed before the first is stored; a take that fails
// to store leaves the takes before it stored, and its error names them.
absl::StatusOr<IngestedFile> IngestUpload(Catalog& catalog, const IngestRequest& request,
                                          absl::string_view bytes, const UploadLimits& limits,
                                          const std::function<bool()>& should_stop = {});

// The same for a file parsed as it arrived (StreamedUpload).
absl::StatusOr<IngestedFile> IngestParsedUpload(Catalog& catalog, const IngestRequest& request,
                                                UploadedFile file,
                                                const std::function<bool()>& should_stop = {});

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_CLIP_INGEST_H_
