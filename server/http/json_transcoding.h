// Where the HTTP face converts requests from JSON or query parameters: protobuf's own proto3
// JSON mapping (field names as in the .proto files, int64 as strings, bytes as base64, enums by
// name; input also in lowerCamelCase). Answers go out through server/http/json_answer.h.
#ifndef MOTIONDB_SERVER_HTTP_JSON_TRANSCODING_H_
#define MOTIONDB_SERVER_HTTP_JSON_TRANSCODING_H_

#include <string>

#include <google/protobuf/message.h>
#include <grpcpp/support/status.h>

#include "absl/status/status.h"
#include "absl/strings/string_view.h"

namespace motiondb::server {

// Merges a request body into `message`; an empty or blank body sets nothing. INVALID_ARGUMENT
// ("request body: ...", protobuf's reason) for malformed JSON, unknown fields and values of the
// wrong type.
absl::Status MergeJson(absl::string_view json, google::protobuf::Message* message);

// Sets the field `path` names ("clip.clip_id": fields of nested messages joined by dots, each
// by its .proto name, its lowerCamelCase or its JSON name) from a path or query parameter's text:
// numbers in decimal, bools true/false (or 1/0), enums by name or number, bytes in base64. A
// repeated field gains the value. INVALID_ARGUMENT naming the parameter for an unknown field or a
// value its type cannot hold.
absl::Status SetField(absl::string_view path, absl::string_view text,
                      google::protobuf::Message* message);

// The field `path` names (as SetField takes it) by its fields' .proto names ("clip.clipId" ->
// "clip.clip_id"); "" when it names none.
std::string FieldName(absl::string_view path, const google::protobuf::Descriptor& type);

// The error body: {"code": <gRPC code number>, "message": "..."}.
std::string ErrorJson(grpc::StatusCode code, absl::string_view message);

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_HTTP_JSON_TRANSCODING_H_
