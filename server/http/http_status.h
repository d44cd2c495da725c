// The one place where gRPC status codes become HTTP statuses, as grpc-gateway maps them
// (runtime/errors.go HTTPStatusFromCode), and back for the refusals the HTTP library makes
// itself (no route, a body too large).
#ifndef MOTIONDB_SERVER_HTTP_HTTP_STATUS_H_
#define MOTIONDB_SERVER_HTTP_HTTP_STATUS_H_

#include <grpcpp/support/status.h>

namespace motiondb::server {

// OK 200, INVALID_ARGUMENT 400, NOT_FOUND 404, ... (the contract's table).
int HttpStatusOf(grpc::StatusCode code);

// The code an error body carries for an HTTP error the library produced without a call: 404
// NOT_FOUND, 413 RESOURCE_EXHAUSTED, other 4xx INVALID_ARGUMENT, else UNKNOWN.
grpc::StatusCode CodeOfHttpStatus(int status);

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_HTTP_HTTP_STATUS_H_
