// motiondb search --space NAME (--clip ID [--from F --to T] | --bvh FILE) [parameters] [--json]
#include <iostream>

#include <nlohmann/json.hpp>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "client/commands.h"
#include "client/server_connection.h"
#include "motiondb/v1/search_service.grpc.pb.h"
#include "util/file_io.h"
#include "util/status_macros.h"

namespace motiondb::cli {
namespace {

constexpr char kUsage[] =
    "motiondb search --space NAME (--clip ID [--from F --to T] | --bvh FILE [--from F --to T])\n"
    "    [--neighbours K] [--ann-dims N] [--dtw-dims N] [--epsilon E] [--slope S]\n"
    "    [--char-frame F] [--neutral mean|boundary|origin] [--max N] [--exact] [--no-refine]\n"
    "    [--path] [--in-clip ID]... [--tag T]... [--json] [--server ADDR] [--token T]";

// Larger than any query a studio will send; the server has its own limit.
constexpr int64_t kMaxQueryBytes = int64_t{1} << 30;

absl::StatusOr<v1::SearchRequest> BuildRequest(const CommandLine& line) {
  v1::SearchRequest request;
  const std::optional<std::string> space = line.value("space");
  if (!space) return absl::InvalidArgumentError("--space NAME is required");
  request.set_space(*space);
  MOTIONDB_ASSIGN_OR_RETURN(const std::optional<int> from, line.integer("from"));
  MOTIONDB_ASSIGN_OR_RETURN(const std::optional<int> to, line.integer("to"));
  const std::optional<std::string> clip = line.value("clip"), bvh = line.value("bvh");
  if (clip.has_value() == bvh.has_value()) {
    return absl::InvalidArgumentError("give exactly one of --clip ID and --bvh FILE");
  }
  if (clip) {
    MOTIONDB_ASSIGN_OR_RETURN(const std::optional<int> id, line.integer("clip"));
    request.mutable_clip()->set_clip_id(*id);
    if (from) request.mutable_clip()->set_first_frame(*from);
    if (to) request.mutable_clip()->set_last_frame(*to);
  } else {
    MOTIONDB_ASSIGN_OR_RETURN(*request.mutable_bvh()->mutable_bvh(),
                              ReadFileBytes(*bvh, kMaxQueryBytes));
    if (from) request.mutable_bvh()->set_first_frame(*from);
    if (to) request.mutable_bvh()->set_last_frame(*to);
  }
  for (auto [name, set] :
       std::initializer_list<std::pair<const char*, void (v1::SearchRequest::*)(int32_t)>>{
           {"neighbours", &v1::SearchRequest::set_neighbours},
           {"ann-dims", &v1::SearchRequest::set_ann_dims},
           {"dtw-dims", &v1::SearchRequest::set_dtw_dims},
           {"slope", &v1::SearchRequest::set_slope_limit},
           {"char-frame", &v1::SearchRequest::set_characteristic_frame},
           {"max", &v1::SearchRequest::set_max_results}}) {
    MOTIONDB_ASSIGN_OR_RETURN(const std::optional<int> value, line.integer(name));
    if (value) (request.*set)(*value);
  }
  MOTIONDB_ASSIGN_OR_RETURN(const std::optional<double> epsilon, line.number("epsilon"));
  if (epsilon) request.set_epsilon(static_cast<float>(*epsilon));
  if (const std::optional<std::string> neutral = line.value("neutral")) {
    if (*neutral == "mean") {
      request.set_neutral(v1::NEUTRAL_POSE_QUERY_MEAN);
    } else if (*neutral == "boundary") {
      request.set_neutral(v1::NEUTRAL_POSE_BOUNDARY_MEAN);
    } else if (*neutral == "origin") {
      request.set_neutral(v1::NEUTRAL_POSE_ORIGIN);
    } else {
      return absl::InvalidArgumentError("--neutral must be mean, boundary or origin");
    }
  }
  for (const std::string& tag : line.values("tag")) request.add_tags(tag);
  for (const std::string& id : line.values("in-clip")) {
    int64_t value = 0;
    if (!absl::SimpleAtoi(id, &value)) {
      return absl::InvalidArgumentError(
          absl::StrCat("--in-clip expects a clip id, got '", id, "'"));
    }
    request.add_clip_ids(value);
  }
  request.set_exact(line.flag("exact"));
  request.set_return_path(line.flag("path"));
  if (line.flag("no-refine")) request.set_refine(false);
  return request;
}

nlohmann::json ResponseJson(const v1::SearchResponse& response) {
  nlohmann::json results = nlohmann::json::array();
  for (const v1::SearchResult& r : response.results()) {
    nlohmann::json item = {
        {"clip_id", r.clip_id()}, {"clip_name", r.clip_name()},     {"start_s", r.start_s()},
        {"end_s", r.end_s()},     {"start_frame", r.start_frame()}, {"end_frame", r.end_frame()},
        {"score", r.score()},     {"seed_frame", r.seed_frame()}};
    if (r.path_size() > 0) item["path"] = std::vector<int>(r.path().begin(), r.path().end());
    results.push_back(std::move(item));
  }
  const v1::SearchTimings& t = response.timings();
  const v1::SearchCounts& c = response.counts();
  return {{"results", results},
          {"characteristic_frame", response.characteristic_frame()},
          {"timings",
           {{"characteristic_ms", t.characteristic_ms()},
            {"seeds_ms", t.seeds_ms()},
            {"clusters_ms", t.clusters_ms()},
            {"warps_ms", t.warps_ms()},
            {"refine_ms", t.refine_ms()},
            {"ranking_ms", t.ranking_ms()},
            {"total_ms", t.total_ms()},
            {"request_ms", t.request_ms()}}},
          {"counts",
           {{"seeds", c.seeds()},
            {"clusters", c.clusters()},
            {"warps", c.warps()},
            {"cells", c.cells()},
            {"query_frames", c.query_frames()},
            {"library_frames", c.library_frames()}}}};
}

absl::Status Search(const CommandLine& line, const ServerConnection& connection) {
  if (!line.positionals().empty()) return absl::InvalidArgumentError("unexpected arguments");
  MOTIONDB_ASSIGN_OR_RETURN(const v1::SearchRequest request, BuildRequest(line));
  const auto stub = v1::SearchService::NewStub(connection.channel());
  v1::SearchResponse response;
  MOTIONDB_RETURN_IF_ERROR(Call(connection, [&](grpc::ClientContext* context) {
    return stub->Search(context, request, &response);
  }));
  if (line.flag("json")) {
    std::cout << ResponseJson(response).dump() << "\n";
    return absl::OkStatus();
  }
  absl::PrintF("%4s  %-40s %9s %9s %13s %10s\n", "RANK", "CLIP", "START (s)", "END (s)", "FRAMES",
               "SCORE");
  int rank = 0;
  for (const v1::SearchResult& r : response.results()) {
    absl::PrintF("%4d  %-40s %9.3f %9.3f %6d-%-6d %10.5f\n", ++rank, r.clip_name(), r.start_s(),
                 r.end_s(), r.start_frame(), r.end_frame(), r.score());
  }
  const v1::SearchTimings& t = response.timings();
  absl::PrintF(
      "%d results in %.2f ms (seeds %.2f, clusters %.2f, warps %.2f, refine %.2f ms; %d seeds, "
      "%d clusters, %d warps)\n",
      response.results_size(), t.request_ms(), t.seeds_ms(), t.clusters_ms(), t.warps_ms(),
      t.refine_ms(), response.counts().seeds(), response.counts().clusters(),
      response.counts().warps());
  return absl::OkStatus();
}

}  // namespace

int RunSearch(const std::vector<std::string>& args) {
  return RunServerCommand(
      "search", kUsage, args,
      {"space", "clip", "bvh", "from", "to", "neighbours", "ann-dims", "dtw-dims", "epsilon",
       "slope", "char-frame", "neutral", "max", "tag", "in-clip"},
      {"exact", "path", "no-refine", "json"}, Search);
}

}  // namespace motiondb::cli
