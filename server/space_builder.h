// Building a space from the database (SpaceService.CreateSpace): resolve the skeleton and the
// training ranges, learn the space, measure its reconstruction error, and project every clip of
// the skeleton into it. Writes nothing: server/catalog.h stores the result.
#ifndef MOTIONDB_SERVER_SPACE_BUILDER_H_
#define MOTIONDB_SERVER_SPACE_BUILDER_H_

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "core/space/learned_metric.h"
#include "core/space/motion_space.h"
#include "server/frame_conversion.h"
#include "server/index_registry.h"
#include "storage/database.h"

namespace motiondb::server {

struct SpaceRequest {
  std::string name;
  // The skeleton; optional when `training` is given or the database holds one skeleton.
  std::optional<int64_t> skeleton_id;
  // Set instead of skeleton_id: a space over several skeletons, in canonical bone directions
  // (core/space/canonical_pose.h), holding the clips of each; `training` may then be of any of
  // them. Each must map completely, with its stored overrides.
  std::vector<int64_t> skeleton_ids;
  // Empty: every clip of the skeleton, whole.
  std::vector<ClipSelection> training;
  SpaceOptions options;
  // Set: the space's search coordinates are in a metric learned from the database's manual
  // labels (server/learned_metric_fit.h).
  std::optional<LearnedMetricOptions> learned_metric;
};

struct BuiltSpace {
  storage::SpaceRecord record;  // without space_id; the report as JSON
  std::shared_ptr<const MotionSpace> space;
  std::vector<IndexedClip> clips;  // every clip of the skeleton (or skeletons), projected
};

// Letters, digits, '.', '_' and '-', 1 to 128 of them: safe in URLs, file names and logs.
absl::Status ValidateSpaceName(const std::string& name);

// `should_stop` is polled between clips; when it returns true the build ends with CANCELLED.
absl::StatusOr<BuiltSpace> BuildSpace(storage::Database& database, const SpaceRequest& request,
                                      const std::function<bool()>& should_stop);

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_SPACE_BUILDER_H_
