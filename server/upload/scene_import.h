// An FBX or glTF upload read in a child process, motiondb-scene-import (server/scene_import/):
// assimp parses what a client sent, and a file that crashes it, or makes it allocate without
// end, must end that process rather than the server. The child writes each take as BVH, which
// is parsed here with the server's own reader and limits.
//
// The child is limited to UploadLimits::max_import_bytes of address space and
// max_import_time, and killed once `should_stop` says stop. Thread-safe: each call has its own
// process.
#ifndef MOTIONDB_SERVER_UPLOAD_SCENE_IMPORT_H_
#define MOTIONDB_SERVER_UPLOAD_SCENE_IMPORT_H_

#include <functional>
#include <string>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "core/scene/scene_format.h"
#include "server/upload/upload.h"

namespace motiondb::server {

// The file's takes. INVALID_ARGUMENT for a file that cannot be read (the child's reason, or
// the signal that ended it), RESOURCE_EXHAUSTED when it needs more memory or output than the
// limits allow, DEADLINE_EXCEEDED after max_import_time, CANCELLED once `should_stop` says
// stop, UNAVAILABLE when the importer cannot be started.
absl::StatusOr<UploadedFile> ImportScene(absl::string_view bytes, MotionFileFormat format,
                                         const UploadLimits& limits,
                                         const std::function<bool()>& should_stop = {});

// The importer a server runs: `configured` when given, else motiondb-scene-import beside the
// running program, else the one this build made.
std::string SceneImporterPath(const std::string& configured);

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_UPLOAD_SCENE_IMPORT_H_
