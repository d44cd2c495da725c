// Early-return helpers for absl::Status / absl::StatusOr (Abseil 20220623 ships none publicly).
#ifndef MOTIONDB_UTIL_STATUS_MACROS_H_
#define MOTIONDB_UTIL_STATUS_MACROS_H_

#include "absl/status/status.h"
#include "absl/status/statusor.h"

#define MOTIONDB_CONCAT_INNER_(a, b) a##b
#define MOTIONDB_CONCAT_(a, b) MOTIONDB_CONCAT_INNER_(a, b)

#define MOTIONDB_RETURN_IF_ERROR(expr)                   \
  do {                                                   \
    ::absl::Status motiondb_status_ = (expr);            \
    if (!motiondb_status_.ok()) return motiondb_status_; \
  } while (0)

#define MOTIONDB_ASSIGN_OR_RETURN_IMPL_(tmp, lhs, rexpr) \
  auto tmp = (rexpr);                                    \
  if (!tmp.ok()) return std::move(tmp).status();         \
  lhs = std::move(*tmp)

#define MOTIONDB_ASSIGN_OR_RETURN(lhs, rexpr) \
  MOTIONDB_ASSIGN_OR_RETURN_IMPL_(MOTIONDB_CONCAT_(motiondb_statusor_, __LINE__), lhs, rexpr)

#endif  // MOTIONDB_UTIL_STATUS_MACROS_H_
