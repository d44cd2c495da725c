// The operators (core/ops) name their own parameters in their errors ("overlap_frames = 40 ...",
// "warp.slope_limit", "b: ..."); an EditService caller knows only its request's fields
// ("overlap_s", "slope_limit", "second"). Each operation lists once, beside where it maps its
// request onto the operators' options, which request field each operator parameter comes from,
// and its errors are told in the request's words here.
#ifndef MOTIONDB_SERVER_EDIT_INTERNAL_REQUEST_FIELDS_H_
#define MOTIONDB_SERVER_EDIT_INTERNAL_REQUEST_FIELDS_H_

#include <string>
#include <utility>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"

namespace motiondb::server {

// {operator parameter, request field}: {"warp.dims", "warp_dims"}, {"plane", "poses"}.
using RequestFields = std::vector<std::pair<std::string, std::string>>;

// `status` with the field its message begins with ("field: ..." or "field = ...") renamed by
// `fields`: a parameter matches the whole leading field or its head before a '.' or '['
// ("plane" in "plane[2].x = nan ..." gives "poses[2].x = nan ..."). Code and payloads kept;
// other statuses, OK included, unchanged.
absl::Status InRequestFields(const absl::Status& status, const RequestFields& fields);

template <typename T>
absl::StatusOr<T> InRequestFields(absl::StatusOr<T> result, const RequestFields& fields) {
  if (result.ok()) return result;
  return InRequestFields(result.status(), fields);
}

// A request's duration in seconds that an operator takes as frames at the space's `rate`, checked
// before it is converted so that a refusal is told in the field's own unit: OK when `seconds` is
// more than 0 (or 0 too, with `zero_allowed`) and at most `max_frames` frames at `rate`; else
// INVALID_ARGUMENT, "gap_s = 4000 is out of range; expected more than 0, at most 3333.33
// seconds (100000 frames at the space's 30 fps)".
absl::Status CheckDuration(absl::string_view field, double seconds, bool zero_allowed,
                           int max_frames, double rate);

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_EDIT_INTERNAL_REQUEST_FIELDS_H_
