// EditService.Reconstruct (thesis 3.3.4): a stored clip's range rebuilt from the first n
// dimensions of a space, with its representational error per joint and overall, and on request
// the overall error against every n.
#ifndef MOTIONDB_SERVER_EDIT_RECONSTRUCT_H_
#define MOTIONDB_SERVER_EDIT_RECONSTRUCT_H_

#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/statusor.h"
#include "core/ops/reconstruction.h"
#include "server/edit/context.h"

namespace motiondb::server {

struct ReconstructRequest {
  std::string space;
  ClipSelection clip;
  ReconstructOptions options{};
  EditOutput output{};
};

struct JointReconstructionError {
  std::string joint;
  AngleError error;
};

struct ReconstructOutcome {
  EditResult result;
  int dims = 0;
  std::vector<JointReconstructionError> joints{};  // in skeleton order
  AngleError overall;
  std::vector<ReconstructionError> curve{};  // with options.error_curve: n = 1, 2, ...
};

// NOT_FOUND for an unknown space or clip; INVALID_ARGUMENT naming clip or dims; nothing is
// stored on error.
absl::StatusOr<ReconstructOutcome> Reconstruct(const EditContext& context,
                                               const ReconstructRequest& request,
                                               const std::function<bool()>& should_stop);

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_EDIT_RECONSTRUCT_H_
