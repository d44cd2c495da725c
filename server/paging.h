// page_size as the API defines it for every list call (SPEC §7, AIP-158 style).
#ifndef MOTIONDB_SERVER_PAGING_H_
#define MOTIONDB_SERVER_PAGING_H_

#include "absl/status/statusor.h"

namespace motiondb::server {

// 0 (unset) means 100; larger than 1000 is read as 1000; negative is INVALID_ARGUMENT.
absl::StatusOr<int> ResolvePageSize(int requested);

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_PAGING_H_
