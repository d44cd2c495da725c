// The operators (core/ops) name their own parameters in their errors ("overlap_frames = 40 ...",
// "warp.slope_limit", "b: ..."); an EditService caller knows only its request's fields
// ("overlap_s", "slope_limit", "second"). Each operation lists once, beside where it maps its
// request onto the operators' options, which request field each operator parameter comes from,
// and its errors are told in the request's words here.
#ifndef MOTIONDB_SERVER_EDIT_FIELDS_H_
#define MOTIONDB_SERVER_EDIT_FIELDS_H_

#include <string>
#include <utility>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"

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

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_EDIT_FIELDS_H_
