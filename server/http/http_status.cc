#include "server/http/http_status.h"

namespace motiondb::server {

int HttpStatusOf(grpc::StatusCode code) {
  switch (code) {
    case grpc::StatusCode::OK:
      return 200;
    case grpc::StatusCode::CANCELLED:
      return 499;  // nginx's "client closed request", as grpc-gateway answers
    case grpc::StatusCode::INVALID_ARGUMENT:
    case grpc::StatusCode::FAILED_PRECONDITION:
    case grpc::StatusCode::OUT_OF_RANGE:
      return 400;
    case grpc::StatusCode::DEADLINE_EXCEEDED:
      return 504;
    case grpc::StatusCode::NOT_FOUND:
      return 404;
    case grpc::StatusCode::ALREADY_EXISTS:
    case grpc::StatusCode::ABORTED:
      return 409;
    case grpc::StatusCode::PERMISSION_DENIED:
      return 403;
    case grpc::StatusCode::UNAUTHENTICATED:
      return 401;
    case grpc::StatusCode::RESOURCE_EXHAUSTED:
      return 429;
    case grpc::StatusCode::UNIMPLEMENTED:
      return 501;
    case grpc::StatusCode::UNAVAILABLE:
      return 503;
    default:  // UNKNOWN, INTERNAL, DATA_LOSS
      return 500;
  }
}

grpc::StatusCode CodeOfHttpStatus(int status) {
  if (status == 404) return grpc::StatusCode::NOT_FOUND;
  if (status == 413 || status == 429 || status == 431) return grpc::StatusCode::RESOURCE_EXHAUSTED;
  if (status == 401) return grpc::StatusCode::UNAUTHENTICATED;
  if (status == 403 || status == 421) return grpc::StatusCode::PERMISSION_DENIED;
  if (status == 408) return grpc::StatusCode::DEADLINE_EXCEEDED;
  if (status == 503) return grpc::StatusCode::UNAVAILABLE;
  if (status >= 400 && status < 500) return grpc::StatusCode::INVALID_ARGUMENT;
  return grpc::StatusCode::UNKNOWN;
}

}  // namespace motiondb::server
