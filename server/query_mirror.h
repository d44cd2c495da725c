// A query's left/right mirror image as search coordinates (SearchRequest.mirror): in a space
// over one skeleton the clip mirrored joint by joint (core/motion/clip_mirror.h) about the
// skeleton's symmetric pose, then projected; in a space over several skeletons its canonical
// bone directions mirrored (MirrorCanonicalPoses), which needs no symmetric pose.
#ifndef MOTIONDB_SERVER_QUERY_MIRROR_H_
#define MOTIONDB_SERVER_QUERY_MIRROR_H_

#include "absl/status/statusor.h"
#include "core/motion/clip.h"
#include "core/motion/matrix.h"
#include "server/index_registry.h"
#include "storage/database.h"

namespace motiondb::server {

// `clip`'s mirror's search coordinates in `snapshot`'s space, every frame at the space rate.
// FAILED_PRECONDITION, saying why, when its skeleton's map cannot mirror it (or, over several
// skeletons, lacks a slot the bones need).
absl::StatusOr<RowMatrixXf> MirroredCoordinates(storage::Database& database,
                                                const SpaceSnapshot& snapshot, const Clip& clip);

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_QUERY_MIRROR_H_
