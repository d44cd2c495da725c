// What every service's conversion (server/grpc/*_conversion.cc) needs of a message's fields:
// proto3's `optional` presence as std::optional, and the refusal of an enum value the server
// does not know (a newer client's, or a number sent raw), naming the field.
#ifndef MOTIONDB_SERVER_GRPC_INTERNAL_FIELD_CONVERSION_H_
#define MOTIONDB_SERVER_GRPC_INTERNAL_FIELD_CONVERSION_H_

#include <optional>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/string_view.h"

namespace motiondb::server {

template <typename T>
std::optional<T> Optional(bool has, T value) {
  return has ? std::optional<T>(value) : std::nullopt;
}

// INVALID_ARGUMENT "FIELD: unknown value N".
inline absl::Status UnknownValue(absl::string_view field, int value) {
  return absl::InvalidArgumentError(absl::StrCat(field, ": unknown value ", value));
}

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_GRPC_INTERNAL_FIELD_CONVERSION_H_
