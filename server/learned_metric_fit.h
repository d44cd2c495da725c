// A space's learned metric (core/space/learned_metric.h) fitted on the database's manual labels,
// for SpaceService.CreateSpace's learned_metric: every manual label of at least
// kMinExampleValue on a clip of the space's skeleton is an example (its range of the clip's
// search coordinates in the space as trained), and the examples of one descriptor on two clips
// are the pairs whose differences the metric shrinks: what changes between takes, performers
// and styles of one action. Reads; writes nothing.
#ifndef MOTIONDB_SERVER_LEARNED_METRIC_FIT_H_
#define MOTIONDB_SERVER_LEARNED_METRIC_FIT_H_

#include <cstdint>
#include <functional>
#include <vector>

#include "absl/status/statusor.h"
#include "core/motion/matrix.h"
#include "core/space/learned_metric.h"
#include "core/space/motion_space.h"
#include "storage/database.h"

namespace motiondb::server {

// A manual label's value from which it is an example: a lower value says the action is not
// there, or hardly.
inline constexpr double kMinExampleValue = 0.5;

struct FittedMetric {
  RowMatrixXd transform;  // space.dims() square
  int64_t examples = 0;   // labelled ranges fitted on
  int64_t descriptors = 0;
};

// `clip_ids`: the clips of the space's skeleton. FAILED_PRECONDITION, saying what is missing,
// when no descriptor labels two of them. `should_stop` is polled between clips (CANCELLED).
absl::StatusOr<FittedMetric> FitMetricOnLabels(storage::Database& database,
                                               const MotionSpace& space,
                                               const std::vector<int64_t>& clip_ids,
                                               const LearnedMetricOptions& options,
                                               const std::function<bool()>& should_stop);

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_LEARNED_METRIC_FIT_H_
