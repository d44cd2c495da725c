#include "server/http/api_routes.h"

#include "absl/strings/str_cat.h"

namespace motiondb::server {
namespace {

constexpr char kClipService[] = "motiondb.v1.ClipService.";
constexpr char kSpaceService[] = "motiondb.v1.SpaceService.";
constexpr char kLabelService[] = "motiondb.v1.LabelService.";
constexpr char kJobService[] = "motiondb.v1.JobService.";

ApiRoute Get(std::string path, std::string rpc,
             std::vector<std::pair<std::string, std::string>> fields = {}) {
  return {"GET", std::move(path), std::move(rpc), std::move(fields)};
}

ApiRoute Post(std::string path, std::string rpc,
              std::vector<std::pair<std::string, std::string>> fields = {}) {
  return {"POST", std::move(path), std::move(rpc), std::move(fields), /*json_body=*/true};
}

// A route answered with a file rather than JSON, chunked as its streaming call sends it.
ApiRoute AsFile(ApiRoute route) {
  route.bvh_file = true;
  return route;
}

std::vector<ApiRoute> MakeRoutes() {
  // A clip range's bounds as short query parameters.
  const std::pair<std::string, std::string> from{"from", "clip.first_frame"};
  const std::pair<std::string, std::string> to{"to", "clip.last_frame"};
  return {
      Get("/v1/info", "motiondb.v1.ServerService.GetServerInfo"),
      Get("/v1/clips", absl::StrCat(kClipService, "ListClips")),
      Get("/v1/clips/{id}", absl::StrCat(kClipService, "GetClip"), {{"id", "clip_id"}}),
      AsFile(Get("/v1/clips/{id}/bvh", absl::StrCat(kClipService, "ExportClipStream"),
                 {{"id", "clip.clip_id"}, from, to})),
      // ?format=gltf|glb (or bvh): the same export in another format.
      AsFile(Get("/v1/clips/{id}/file", absl::StrCat(kClipService, "ExportClipStream"),
                 {{"id", "clip.clip_id"}, from, to})),
      Get("/v1/clips/{id}/poses", absl::StrCat(kClipService, "GetClipPoses"),
          {{"id", "clip.clip_id"}, from, to}),
      Get("/v1/clips/{id}/labels", absl::StrCat(kLabelService, "GetClipLabels"),
          {{"id", "clip_id"}}),
      Post("/v1/clips", absl::StrCat(kClipService, "IngestClip")),
      {"DELETE", "/v1/clips/{id}", absl::StrCat(kClipService, "DeleteClip"), {{"id", "clip_id"}}},
      Get("/v1/skeletons", absl::StrCat(kClipService, "ListSkeletons")),
      Get("/v1/skeletons/{id}", absl::StrCat(kClipService, "GetSkeleton"), {{"id", "skeleton_id"}}),
      Post("/v1/skeletons/{id}:map", absl::StrCat(kClipService, "MapSkeleton"),
           {{"id", "skeleton_id"}}),
      Get("/v1/spaces", absl::StrCat(kSpaceService, "ListSpaces")),
      Get("/v1/spaces/{name}", absl::StrCat(kSpaceService, "GetSpace"), {{"name", "name"}}),
      Get("/v1/spaces/{name}/curve", absl::StrCat(kSpaceService, "GetCurve"),
          {{"name", "space"}, {"clip", "clip.clip_id"}, from, to}),
      Post("/v1/search", "motiondb.v1.SearchService.Search"),
      Get("/v1/labels", absl::StrCat(kLabelService, "ListLabels")),
      Post("/v1/labels", absl::StrCat(kLabelService, "AddLabels")),
      Get("/v1/labels:find", absl::StrCat(kLabelService, "FindLabels")),
      Post("/v1/labels:delete", absl::StrCat(kLabelService, "DeleteLabels")),
      Get("/v1/jobs", absl::StrCat(kJobService, "ListJobs")),
      Post("/v1/jobs", absl::StrCat(kJobService, "StartPropagation")),
      Get("/v1/jobs/{id}", absl::StrCat(kJobService, "GetJob"), {{"id", "job_id"}}),
      Post("/v1/jobs/{id}:cancel", absl::StrCat(kJobService, "CancelJob"), {{"id", "job_id"}}),
  };
}

}  // namespace

std::vector<std::string> ApiRoute::PathNames() const {
  std::vector<std::string> names;
  for (size_t open = path.find('{'); open != std::string::npos; open = path.find('{', open)) {
    const size_t close = path.find('}', open);
    names.push_back(path.substr(open + 1, close - open - 1));
    open = close;
  }
  return names;
}

std::string ApiRoute::PathRegex() const {
  std::string regex;
  for (size_t i = 0; i < path.size(); ++i) {
    if (path[i] == '{') {
      regex += "([^/:]+)";
      i = path.find('}', i);
    } else {
      regex += path[i];  // paths hold only letters, '/' and ':', none special in a regex
    }
  }
  return regex;
}

const std::vector<ApiRoute>& ApiRoutes() {
  static const std::vector<ApiRoute>* const routes = new std::vector<ApiRoute>(MakeRoutes());
  return *routes;
}

}  // namespace motiondb::server
