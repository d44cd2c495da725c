// An answer as proto3 JSON, written in one pass with its size bounded. The HTTP face's answers
// are the gRPC answers (within --max-answer-mb), but their JSON is larger than their encoding: a
// double's 8 bytes take up to 24 characters, bytes a third more as base64, and a field at its
// default, which the encoding omits, is a name and a value. protobuf's own printer
// (MessageToJsonString) builds a tree of every value before it writes any (measured: 2.9 GB and
// 28 s for a 27 MiB search answer of 10 M path frames). This writer holds only its text, and
// stops as soon as the text passes the limit.
#ifndef MOTIONDB_SERVER_HTTP_JSON_ANSWER_H_
#define MOTIONDB_SERVER_HTTP_JSON_ANSWER_H_

#include <cstddef>
#include <string>

#include <google/protobuf/message.h>

#include "absl/status/statusor.h"

namespace motiondb::server {

// `message` as MessageToJsonString writes it with preserve_proto_field_names and
// always_print_primitive_fields (the same values: every field by its .proto name, scalars,
// lists and maps at their defaults too, messages and optional fields when set, int64 as strings,
// bytes as base64, enums by name, NaN and infinities as strings), but for text that is not UTF-8,
// whose bad bytes become U+FFFD rather than failing the answer. RESOURCE_EXHAUSTED once the text
// would pass `max_bytes`.
absl::StatusOr<std::string> AnswerJson(const google::protobuf::Message& message, size_t max_bytes);

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_HTTP_JSON_ANSWER_H_
