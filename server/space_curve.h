// A clip's motion curve in a space (SpaceService.GetCurve): its projection onto the first dims,
// as the thesis plots it (3.3.3), read from the resident index rather than recomputed.
#ifndef MOTIONDB_SERVER_SPACE_CURVE_H_
#define MOTIONDB_SERVER_SPACE_CURVE_H_

#include <functional>
#include <optional>
#include <string>

#include "absl/status/statusor.h"
#include "core/motion/clip.h"
#include "core/motion/matrix.h"
#include "server/answer_limit.h"
#include "server/frame_conversion.h"
#include "server/index_registry.h"
#include "storage/database.h"

namespace motiondb::server {

struct CurveRequest {
  std::string space;
  ClipSelection clip;
  // Dimensions of the curve; unset: 3, or all of a smaller space's.
  std::optional<int> dims;
};

struct Curve {
  RowMatrixXf coordinates;  // frames at the space rate x dims, in the space's own units
  double sample_rate = 0;
  FrameRange frames;  // the range asked for, at the clip's rate
};

// NOT_FOUND for an unknown space or clip; INVALID_ARGUMENT naming the field for dims outside
// the space or a range outside the clip; RESOURCE_EXHAUSTED, before the curve is made, when it
// could exceed `answers`; the lookup's other codes (space_lookup.h); CANCELLED once
// `should_stop` says stop.
absl::StatusOr<Curve> ReadCurve(const IndexRegistry& registry, storage::Database& database,
                                const CurveRequest& request, const AnswerLimit& answers,
                                const std::function<bool()>& should_stop = {});

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_SPACE_CURVE_H_
