// motiondb search --space NAME (--clip ID [--from F --to T] | --bvh FILE) [parameters] [--json]
#include <iostream>
#include <memory>

#include <nlohmann/json.hpp>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "client/commands.h"
#include "client/server_connection.h"
#include "motiondb/v1/search_service.grpc.pb.h"
#include "util/cli_conventions.h"
#include "util/file_io.h"
#include "util/status_macros.h"

namespace motiondb::cli {
namespace {

// Larger than any query a studio will send; the server has its own limit.
constexpr int64_t kMaxQueryBytes = int64_t{1} << 30;

struct SearchFlags {
  std::string space;
  std::optional<int64_t> clip;
  std::string bvh;
  FrameRangeFlags range;
  std::optional<int> places, neighbours, ann_dims, dtw_dims, slope, max, char_frame, threads;
  std::optional<int> points, shape_windows, shape_clips, shape_lengths;
  std::vector<int> char_frames;
  std::optional<double> max_point_gap, second_anchor;
  std::string seeds = "frames";
  std::optional<double> epsilon;
  std::string neutral = "mean";
  bool exact = false, path = false, no_refine = false, explain = false, mirror = false;
  bool exclude_query = true;  // a --clip query's own range is not a result
  std::vector<int64_t> in_clips;
  std::vector<std::string> tags;
};

// The whole-number search parameters: their flags, the request fields they set (whose names the
// server's errors use) and the defaults the server fills in when they are unset (thesis Table
// 6.2, as proto/motiondb/v1/search_service.proto documents them).
struct Parameter {
  const char* flag;
  const char* field;
  const char* value_name;
  const char* default_value;
  const char* description;
  std::optional<int> SearchFlags::*value;
  void (v1::SearchRequest::*set)(int32_t);
  int least = 1;  // the smallest value the flag takes
};
constexpr Parameter kParameters[] = {
    {"--places", "places", "N", "128", "--seeds places: distinct places, one warp each",
     &SearchFlags::places, &v1::SearchRequest::set_places},
    {"--neighbours", "neighbours", "K", "0",
     "--seeds frames|windows: seeds, clustered (0: frames by the library's size, 1000 up to "
     "10 h; windows 500)",
     &SearchFlags::neighbours, &v1::SearchRequest::set_neighbours, 0},
    {"--ann-dims", "ann_dims", "N", "5", "dimensions of the seed search", &SearchFlags::ann_dims,
     &v1::SearchRequest::set_ann_dims},
    {"--dtw-dims", "dtw_dims", "N", "5", "dimensions of the time warp's pose distance",
     &SearchFlags::dtw_dims, &v1::SearchRequest::set_dtw_dims},
    {"--slope", "slope_limit", "S", "2", "the warp runs at most S times faster or slower",
     &SearchFlags::slope, &v1::SearchRequest::set_slope_limit},
    {"--max", "max_results", "N", "20", "results returned", &SearchFlags::max,
     &v1::SearchRequest::set_max_results},
    {"--points", "characteristic_points", "K", "1",
     "characteristic points found, one in each K-th of the query, each anchoring its part "
     "(0: one per action of the query)",
     &SearchFlags::points, &v1::SearchRequest::set_characteristic_points, 0},
    {"--shape-windows", "shape_windows", "N", "200",
     "--seeds shapes: windows nearest the query's shape asked at each length",
     &SearchFlags::shape_windows, &v1::SearchRequest::set_shape_windows},
    {"--shape-clips", "shape_clips", "N", "300",
     "--seeds shapes: distinct clips, nearest first, whose windows the warp re-ranks",
     &SearchFlags::shape_clips, &v1::SearchRequest::set_shape_clips},
    {"--shape-lengths", "shape_lengths_either_side", "N", "2",
     "--seeds shapes: window lengths (sqrt(2) apart) searched either side of the query's",
     &SearchFlags::shape_lengths, &v1::SearchRequest::set_shape_lengths_either_side, 0},
};

// The flags that set SearchRequest's fields, for the server's errors.
FlagNames SearchFlagNames(const SearchFlags& flags) {
  FlagNames names = {{"clip.first_frame", "--from"},
                     {"clip.last_frame", "--to"},
                     {"bvh.first_frame", "--from"},
                     {"bvh.last_frame", "--to"},
                     {"bvh", "--bvh " + flags.bvh},
                     {"characteristic_frame", "--char-frame"},
                     {"epsilon", "--epsilon"},
                     {"neutral", "--neutral"},
                     {"exact_threads", "--threads"},
                     {"threads", "--threads"},
                     {"characteristic_frames", "--char-frames"},
                     {"max_point_gap_s", "--max-point-gap"},
                     {"second_anchor_scatter", "--second-anchor"}};
  for (const Parameter& parameter : kParameters) names.push_back({parameter.field, parameter.flag});
  return names;
}

absl::StatusOr<v1::SearchRequest> BuildRequest(const SearchFlags& flags) {
  v1::SearchRequest request;
  request.set_space(flags.space);
  const FrameRangeFlags& range = flags.range;
  if (flags.clip) {
    request.mutable_clip()->set_clip_id(*flags.clip);
    if (range.from) request.mutable_clip()->set_first_frame(*range.from);
    if (range.to) request.mutable_clip()->set_last_frame(*range.to);
  } else {
    MOTIONDB_ASSIGN_OR_RETURN(*request.mutable_bvh()->mutable_bvh(),
                              ReadFileBytes(flags.bvh, kMaxQueryBytes));
    if (range.from) request.mutable_bvh()->set_first_frame(*range.from);
    if (range.to) request.mutable_bvh()->set_last_frame(*range.to);
  }
  for (const Parameter& parameter : kParameters) {
    if (const std::optional<int>& value = flags.*parameter.value) (request.*parameter.set)(*value);
  }
  if (flags.char_frame) request.set_characteristic_frame(*flags.char_frame);
  for (const int frame : flags.char_frames) request.add_characteristic_frames(frame);
  if (flags.max_point_gap) request.set_max_point_gap_s(*flags.max_point_gap);
  if (flags.second_anchor) request.set_second_anchor_scatter(*flags.second_anchor);
  if (flags.threads && flags.exact) request.set_exact_threads(*flags.threads);
  if (flags.threads && !flags.exact) request.set_threads(*flags.threads);
  request.set_seed_selection(SeedSelectionNamed(flags.seeds));
  if (flags.epsilon) request.set_epsilon(static_cast<float>(*flags.epsilon));
  request.set_neutral(flags.neutral == "boundary" ? v1::NEUTRAL_POSE_BOUNDARY_MEAN
                      : flags.neutral == "origin" ? v1::NEUTRAL_POSE_ORIGIN
                                                  : v1::NEUTRAL_POSE_QUERY_MEAN);
  for (const std::string& tag : flags.tags) request.add_tags(tag);
  for (const int64_t id : flags.in_clips) request.add_clip_ids(id);
  request.set_exact(flags.exact);
  request.set_return_path(flags.path);
  request.set_explain(flags.explain);
  request.set_mirror(flags.mirror);
  if (flags.no_refine) request.set_refine(false);
  if (flags.clip) request.set_exclude_query(flags.exclude_query);
  return request;
}

nlohmann::json ExplanationJson(const v1::SearchExplanation& explanation) {
  nlohmann::json joints = nlohmann::json::array();
  for (const v1::JointShare& joint : explanation.joints()) {
    joints.push_back({{"name", joint.name()}, {"share", joint.share()}, {"score", joint.score()}});
  }
  return {{"joints", std::move(joints)},
          {"full_score", explanation.full_score()},
          {"mean_speed", explanation.mean_speed()},
          {"max_speed", explanation.max_speed()}};
}

// The explanation's first three joints and the speeds, on one line under a result.
void PrintExplanation(const v1::SearchExplanation& explanation) {
  std::string joints;
  for (int i = 0; i < 3 && i < explanation.joints_size(); ++i) {
    absl::StrAppend(&joints, i > 0 ? ", " : "", explanation.joints(i).name(), " ",
                    absl::StrFormat("%.0f%%", 100 * explanation.joints(i).share()));
  }
  absl::PrintF("       why: %s; speed x%.2f (at most x%.2f)\n", joints, explanation.mean_speed(),
               explanation.max_speed());
}

nlohmann::json ResponseJson(const v1::SearchResponse& response) {
  nlohmann::json results = nlohmann::json::array();
  for (const v1::SearchResult& r : response.results()) {
    nlohmann::json item = {
        {"clip_id", r.clip_id()}, {"clip_name", r.clip_name()},     {"start_s", r.start_s()},
        {"end_s", r.end_s()},     {"start_frame", r.start_frame()}, {"end_frame", r.end_frame()},
        {"score", r.score()},     {"seed_frame", r.seed_frame()},   {"mirrored", r.mirrored()}};
    if (r.path_size() > 0) item["path"] = std::vector<int>(r.path().begin(), r.path().end());
    if (r.has_explanation()) item["explanation"] = ExplanationJson(r.explanation());
    results.push_back(std::move(item));
  }
  const v1::SearchTimings& t = response.timings();
  const v1::SearchCounts& c = response.counts();
  return {{"results", results},
          {"characteristic_frame", response.characteristic_frame()},
          {"characteristic_frames", std::vector<int>(response.characteristic_frames().begin(),
                                                     response.characteristic_frames().end())},
          {"second_anchor_frame",
           response.has_second_anchor_frame() ? response.second_anchor_frame() : -1},
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

absl::Status Search(const SearchFlags& flags, bool json, const ServerConnection& connection) {
  MOTIONDB_ASSIGN_OR_RETURN(const v1::SearchRequest request, BuildRequest(flags));
  MOTIONDB_ASSIGN_OR_RETURN(
      const v1::SearchResponse response,
      CallUnary(connection, &v1::SearchService::Stub::Search, request, SearchFlagNames(flags)));
  if (json) {
    std::cout << ResponseJson(response).dump() << "\n";
    return absl::OkStatus();
  }
  // With --mirror, a last column says which results the query's mirror found.
  absl::PrintF("%4s %8s  %-40s %9s %9s %13s %10s%s\n", "RANK", "CLIP", "NAME", "START (s)",
               "END (s)", "FRAMES", "SCORE", flags.mirror ? "  MIRRORED" : "");
  int rank = 0;
  for (const v1::SearchResult& r : response.results()) {
    absl::PrintF("%4d %8d  %-40s %9.3f %9.3f %6d-%-6d %10.5f%s\n", ++rank, r.clip_id(),
                 r.clip_name(), r.start_s(), r.end_s(), r.start_frame(), r.end_frame(), r.score(),
                 !flags.mirror  ? ""
                 : r.mirrored() ? "  yes"
                                : "  no");
    if (r.has_explanation()) PrintExplanation(r.explanation());
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

v1::SeedSelection SeedSelectionNamed(const std::string& name) {
  return name == "places"    ? v1::SEED_SELECTION_DISTINCT_PLACES
         : name == "windows" ? v1::SEED_SELECTION_NEAREST_WINDOWS
         : name == "shapes"  ? v1::SEED_SELECTION_SHAPE_WINDOWS
                             : v1::SEED_SELECTION_NEAREST_FRAMES;
}

void AddSearch(Commands& commands) {
  auto flags = std::make_shared<SearchFlags>();
  const GlobalOptions& global = commands.global();
  CLI::App* search = commands.AddServer(
      commands.root(), "search", "query by example: ranges of clips that move like the query",
      [flags, &global](const ServerConnection& connection) {
        return Search(*flags, global.json, connection);
      });
  search->add_option("--space", flags->space, "the space to search in")
      ->type_name("NAME")
      ->required();
  const CLI::Option* clip = search->add_option("--clip", flags->clip, "the query: a stored clip")
                                ->type_name("ID")
                                ->check(WholeAtLeast(1));
  const CLI::Option* bvh = search->add_option("--bvh", flags->bvh, "... or a motion file (BVH, or an FBX or glTF file of one take)")
                               ->type_name("FILE")
                               ->check(ExistingFile());
  search->final_callback([clip, bvh] {
    if (clip->count() + bvh->count() != 1) {
      throw CLI::ValidationError("give exactly one of --clip ID and --bvh FILE");
    }
  });
  AddFrameRangeFlags(search, "the query", &flags->range);
  for (const Parameter& parameter : kParameters) {
    search->add_option(parameter.flag, flags.get()->*parameter.value, parameter.description)
        ->type_name(parameter.value_name)
        ->default_str(parameter.default_value)
        ->check(WholeAtLeast(parameter.least));
  }
  search->add_option("--epsilon", flags->epsilon, "approximation bound of the seed search")
      ->type_name("E")
      ->default_str("0")
      ->check(NumberAtLeast(0));
  search->add_option("--char-frame", flags->char_frame, "the query frame every warp goes through")
      ->type_name("F")
      ->default_str("auto")
      ->check(WholeAtLeast(-1));  // -1: automatic, as the server reads it
  search
      ->add_option("--char-frames", flags->char_frames,
                   "several characteristic points: query frames, increasing, each anchoring its "
                   "part of the query (cut halfway between them); results match the parts in order")
      ->type_name("F,F,...")
      ->delimiter(',')
      ->check(WholeAtLeast(0));
  search
      ->add_option("--max-point-gap", flags->max_point_gap,
                   "several points: the most seconds a result may skip between two parts")
      ->type_name("S")
      ->default_str("10")
      ->check(NumberAtLeast(0));
  search
      ->add_option("--second-anchor", flags->second_anchor,
                   "one point: a second anchor takes half the seeds when they fall in more "
                   "clusters than this share of them (a pose common to many takes); 0: never")
      ->type_name("S")
      ->default_str("0.5")
      ->check(NumberAtLeast(0));
  OneOf(search->add_option("--neutral", flags->neutral,
                           "auto --char-frame: the pose farthest from this"),
        {"mean", "boundary", "origin"})
      ->capture_default_str();
  OneOf(search->add_option("--seeds", flags->seeds,
                           "seeds: the thesis's nearest frames, distinct places, the frames "
                           "nearest by their poses a quarter second either side too, or "
                           "candidates from the query's whole shape"),
        kSeedNames)
      ->capture_default_str();
  search->add_flag("--exact", flags->exact, "the exhaustive search: the true best, slower");
  search
      ->add_option("--threads", flags->threads,
                   "threads of one search: its warps and refinement (0: every core while the "
                   "server runs no other search, else one), or with --exact the clips it "
                   "scans (0: one per core)")
      ->type_name("N")
      ->default_str("0 = auto")
      ->check(WholeAtLeast(0));
  search->add_flag("--no-refine", flags->no_refine,
                   "the thesis's search as is (faster, lower recall)");
  search
      ->add_flag("--exclude-query,!--include-query", flags->exclude_query,
                 "--clip: leave out (or keep) results overlapping the query's own range")
      ->default_str("exclude");
  search->add_flag("--path", flags->path, "each result's warp path (with --json)");
  search->add_flag("--mirror", flags->mirror,
                   "also search the query's left/right mirror (by its skeleton's humanoid map): a "
                   "left-hand wave finds right-hand waves too; each result says which found it");
  search->add_flag("--explain", flags->explain,
                   "each result's share of its distance per joint (the top three printed) and "
                   "its speed against the query");
  search->add_option("--in-clip", flags->in_clips, "only in this clip; repeat for more")
      ->type_name("ID")
      ->allow_extra_args(false)
      ->check(WholeAtLeast(1));
  search->add_option("--tag", flags->tags, "only in clips tagged T; repeat for more")
      ->type_name("T")
      ->allow_extra_args(false);
  search->footer(
      "Unset parameters take the server's defaults, the thesis's (Table 6.2), shown here.\n"
      "--seeds places: warps from distinct places (higher recall in hours of capture, slower).\n"
      "--seeds windows: seeds matched by three poses, a quarter second apart (more distinct\n"
      "takes: higher recall where many takes pass the query's pose; the first such search\n"
      "of a space builds its window index).\n"
      "--seeds shapes: candidates from the query's whole shape at its length and lengths\n"
      "either side, re-ranked by the exact warp over their ranges (no characteristic point;\n"
      "the first such search of a space builds its shape index).\n"
      "--ann-dims and --dtw-dims are at most the space's dimensions. --neutral: the query's\n"
      "mean pose, the mean of its first and last poses, or the space's origin. --no-refine\n"
      "skips re-warping each candidate free of its seed. --exact ignores the seed parameters.\n"
      "Frames count from 0 at the query's own rate; ranges are inclusive.");
}

}  // namespace motiondb::cli
