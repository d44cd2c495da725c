// The JSON API's routes (docs/api.md, "HTTP"): each an HTTP method and path over one
// gRPC method of the motiondb.v1 services, and the request fields its path and query
// parameters fill.
#ifndef MOTIONDB_SERVER_HTTP_API_ROUTES_H_
#define MOTIONDB_SERVER_HTTP_API_ROUTES_H_

#include <string>
#include <utility>
#include <vector>

namespace motiondb::server {

struct ApiRoute {
  std::string http_method;  // "GET", "POST" or "DELETE"
  // "/v1/clips/{id}/bvh": each {name} is one path segment (no '/' or ':').
  std::string path;
  std::string rpc;  // the gRPC method's full name, "motiondb.v1.ClipService.ExportClip"
  // Path placeholders and query parameter aliases, and the request field each fills
  // ("id" -> "clip.clip_id"). Any other query parameter names a field itself ("clip.clip_id").
  std::vector<std::pair<std::string, std::string>> fields;
  bool json_body = false;  // the request message is the body's JSON (POST)
  // The answer is ExportClipStream's file, chunked as it arrives (server/http/chunked_file.h),
  // not JSON.
  bool bvh_file = false;

  // "GET /v1/clips/{id}": the route as metrics and errors name it.
  std::string Name() const { return http_method + " " + path; }
  // The placeholders in order ("id").
  std::vector<std::string> PathNames() const;
  // A regular expression matching the path, one group a placeholder.
  std::string PathRegex() const;
};

// Every route, in docs/api.md's order.
const std::vector<ApiRoute>& ApiRoutes();

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_HTTP_API_ROUTES_H_
