// Retrieval quality of the search on real labelled data (issues 4 and 12): the clips of labelled
// folders (default ../shared/mocap/bandai2-normal; label = the file name's content field, style
// = its style field) in a space trained on them all. `--split one`: every clip a query against
// all the others; `--split style`: against the clips of other styles only; `--split dataset`:
// the first folder's clips against the other folders' (on the contents they share). Prints
// mean precision@5 of the label for the fast and the exact search (per label, and per style or
// folder), the fast search's recall@10 against the exact search, latency and stage times.
//
// Every run also runs the window-vector baseline (bench/window_vector_baseline.h, issue 39) on the
// same queries and library, and ends with one table: precision@5 and @10, recall@10 against the
// exact search, latency p50/p90/p99 and index memory of the fast search, the exact search and the
// baseline, and the FLANN index's recall against the exact nearest windows. `--takes
// first-half|second-half` loads half of each content and style's takes (testing::Takes), for
// choosing defaults on one half and reporting on the other. `--time-scaled`: the gestures'
// (raise-up-*, wave-*) copies played 0.7x and 1.4x as fast added to the library, the share of the
// copies each search puts in a gesture's first 3.
//
// usage: search_quality [--folder DIR]... [--split one|style|dataset] [--metric unit|eigen]
//          [--weights mass|uniform] [--weight-floor F] [--weight JOINT=W]...
//          [--rate HZ] [--neighbours K] [--ann-dims N] [--dtw-dims N] [--slope S]
//          [--neutral mean|boundary|origin] [--exact-every N] [--yaw-weight W] [--keep-heading]
//          [--no-refine] [--points K] [--second-anchor S] [--learned-metric SHRINK]
//          [--unseen-labels] [--takes all|first-half|second-half] [--time-scaled]
//          [--baseline-index kd-forest|k-means|linear] [--baseline-trees N] [--baseline-checks N]
//
// `--learned-metric` searches in a metric learned from the labels (core/space/learned_metric.h,
// testing/learned_metric_folds.h): with
// `--split style`, fitted for each style left out on the other styles' clips only (one index a
// fold, the folds' figures merged); with `dataset`, on the other folders'; with `one`, on the
// other folders' too, the first folder's clips searched among themselves. The baseline is not
// run then (its figures would need an index a fold).
#include <chrono>
#include <cstdio>
#include <map>
#include <string>
#include <tuple>
#include <vector>

#include "absl/strings/match.h"
#include "absl/strings/str_join.h"
#include "bench/measure.h"
#include "bench/window_vector_baseline.h"
#include "core/bvh/bvh_reader.h"
#include "core/search/motion_search.h"
#include "core/space/search_coordinates.h"
#include "testing/labelled_index.h"
#include "testing/learned_metric_folds.h"
#include "testing/retrieval_evaluation.h"
#include "util/cli_conventions.h"
#include "util/status_macros.h"

namespace motiondb {
namespace {

using testing::BaselineFigures;
using testing::EvaluateRetrieval;
using testing::RetrievalOptions;
using testing::RetrievalReport;

// The flags, with the defaults of the space and the search.
struct QualityFlags {
  std::vector<std::string> folders = {(bench::MocapRoot() / "bandai2-normal").string()};
  std::string split = "one";
  std::string metric = "unit";
  std::string weights = "mass";
  std::string neutral = "mean";
  bool keep_heading = false, no_refine = false, windows = false, shapes = false;
  int places = 0;
  double learned_metric = -1;  // LearnedMetricOptions::shrink; negative: the space's metric
  bool unseen_labels = false;  // --learned-metric fitted without the queries' labels
  std::vector<std::string> weight_overrides;  // JOINT=W
  double root_velocity = SpaceOptions().root_velocity_weight;
  std::string takes = "all";
  bool time_scaled = false;
  std::string baseline_index = "k-means";
  bench::WindowBaselineOptions baseline;
  int window_recall_k = 100;
  SpaceOptions space;
  RetrievalOptions retrieval;
};

void AddFlags(CLI::App& app, QualityFlags* flags) {
  app.add_option("--folder", flags->folders, "labelled BVH folders (repeat for several)")
      ->type_name("DIR")
      ->capture_default_str();
  cli::OneOf(app.add_option("--split", flags->split, "what each query searches"),
             {"one", "style", "dataset"})
      ->capture_default_str();
  cli::OneOf(app.add_option("--metric", flags->metric, "the space's metric"), {"unit", "eigen"})
      ->capture_default_str();
  cli::OneOf(app.add_option("--weights", flags->weights, "the joint-weight preset"),
             {"mass", "uniform"})
      ->capture_default_str();
  app.add_option("--weight-floor", flags->space.weights.floor,
                 "mass weights: the smallest as a fraction of the largest")
      ->type_name("F")
      ->capture_default_str()
      ->check(cli::NumberAbove(0));
  app.add_option("--weight", flags->weight_overrides,
                 "a joint's final weight, replacing the preset's (repeat for several)")
      ->type_name("JOINT=W")
      ->delimiter(',');
  app.add_option("--rate", flags->space.sample_rate, "the space's sample rate")
      ->type_name("HZ")
      ->capture_default_str()
      ->check(cli::NumberAbove(0));
  app.add_option("--yaw-weight", flags->space.yaw_rate_weight, "the yaw-rate dimension's weight")
      ->type_name("W")
      ->capture_default_str()
      ->check(cli::NumberAbove(0));
  app.add_option("--root-velocity", flags->root_velocity,
                 "the root-velocity dimensions' weight (0: no such dimensions)")
      ->type_name("W")
      ->capture_default_str()
      ->check(cli::NumberAtLeast(0));
  app.add_flag("--keep-heading", flags->keep_heading, "keep the body's facing in the pose");
  SearchParams& params = flags->retrieval.params;
  for (auto [name, field, what, min] :
       {std::tuple{"--neighbours", &params.neighbours, "seeds (0: by the library's size)", 0},
        {"--places", &flags->places, "distinct places as seeds (0: the nearest frames)", 0},
        {"--ann-dims", &params.ann_dims, "seed search dimensions", 1},
        {"--dtw-dims", &params.dtw_dims, "time-warp dimensions", 1},
        {"--slope", &params.slope_limit, "the warp's slope limit", 1},
        {"--points", &params.characteristic_points,
         "characteristic points per query (0: one per action of the query)", 0},
        {"--threads", &params.threads,
         "threads of the fast search's warps and refinement (0: one per core)", 0},
        {"--exact-every", &flags->retrieval.exact_every,
         "run the exact search on every N-th query (0: never)", 0}}) {
    app.add_option(name, *field, what)
        ->type_name("N")
        ->capture_default_str()
        ->check(cli::WholeAtLeast(min));
  }
  cli::OneOf(app.add_option("--neutral", flags->neutral, "the characteristic pose's neutral pose"),
             {"mean", "boundary", "origin"})
      ->capture_default_str();
  app.add_flag("--no-refine", flags->no_refine, "the thesis's search as is");
  app.add_flag("--windows", flags->windows, "seeds by window (the poses 0.25 s either side too)");
  app.add_flag("--shapes", flags->shapes,
               "candidates from the query's whole shape, re-ranked by the warp over their ranges");
  for (auto [name, field, what, min] :
       {std::tuple{"--shape-windows", &params.shape_windows, "--shapes: windows a length", 1},
        {"--shape-clips", &params.shape_clips, "--shapes: distinct clips re-ranked", 1},
        {"--shape-lengths", &params.shape_lengths_either_side,
         "--shapes: window lengths searched either side of the query's", 0}}) {
    app.add_option(name, *field, what)
        ->type_name("N")
        ->capture_default_str()
        ->check(cli::WholeAtLeast(min));
  }
  app.add_option("--second-anchor", params.second_anchor_scatter,
                 "a second anchor when the seeds scatter over more clusters than this share of "
                 "them (0: never)")
      ->type_name("S")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1.0));
  app.add_option("--learned-metric", flags->learned_metric,
                 "search in a metric learned from the other styles' (or folders') labels, its "
                 "style differences whitened by this share (0-1)")
      ->type_name("SHRINK")
      ->check(CLI::Range(0.0, 1.0));
  app.add_flag("--unseen-labels", flags->unseen_labels,
               "--learned-metric: each fold's metric fitted without its queries' label either (one "
               "fold a style and label)");
  cli::OneOf(app.add_option("--takes", flags->takes,
                            "the takes loaded: of each content and style's n files in name order, "
                            "the first ceil(n/2) or the others"),
             {"all", "first-half", "second-half"})
      ->capture_default_str();
  app.add_flag("--time-scaled", flags->time_scaled,
               "also: the gestures' copies at 0.7x and 1.4x speed in the library, the share in a "
               "gesture's first 3");
  cli::OneOf(app.add_option("--baseline-index", flags->baseline_index,
                            "the window baseline's FLANN index"),
             {"kd-forest", "k-means", "linear"})
      ->capture_default_str();
  bench::WindowBaselineOptions& baseline = flags->baseline;
  for (auto [name, field, what] :
       {std::tuple{"--baseline-trees", &baseline.trees, "the baseline's kd-trees"},
        {"--baseline-checks", &baseline.checks, "leaves the baseline's FLANN search visits"},
        {"--window-recall-k", &flags->window_recall_k,
         "FLANN's recall is measured on this many nearest windows"}}) {
    app.add_option(name, *field, what)
        ->type_name("N")
        ->capture_default_str()
        ->check(cli::WholeAtLeast(1));
  }
}

// The baseline's answer to a search's request: params.clip_ids (here the clips' indices) allowed.
std::vector<SearchResult> BaselineSearch(const bench::WindowVectorBaseline& baseline,
                                         const LibraryIndex& library, CoordinateView query,
                                         const SearchParams& params) {
  std::vector<bool> allowed(library.clip_count(), params.clip_ids.empty());
  for (const int64_t id : params.clip_ids) allowed[library.FindClip(id)] = true;
  return baseline.Search(query, params.max_results, allowed);
}

bool IsGesture(const std::string& label) {
  return absl::StartsWith(label, "raise-up") || absl::StartsWith(label, "wave");
}

// Copies of the gestures played 0.7x and 1.4x as fast (the same frames at another frame time,
// projected as an ingest would), added to the library: of each gesture's two copies, the share
// the fast search and the baseline put in the gesture's first 3 (the gesture itself excluded).
absl::Status MeasureTimeScaled(const QualityFlags& flags, const testing::LabelledIndex& library,
                               const std::vector<std::filesystem::path>& folders,
                               const bench::WindowBaselineOptions& baseline_options) {
  const LibraryIndex& index = *library.index;
  std::vector<LibraryClip> clips;
  std::map<int64_t, int> copy_of;  // copy's id -> its gesture's index
  for (int c = 0; c < index.clip_count(); ++c) {
    clips.push_back({c, index.clip(c).name, {}, index.CopyClipCoordinates(c)});
  }
  std::vector<int> gestures;
  for (int c = 0; c < index.clip_count(); ++c) {
    if (!IsGesture(library.labels[c])) continue;
    gestures.push_back(c);
    std::filesystem::path path;
    for (const auto& folder : folders) {
      if (folder.filename().string() == library.sources[c]) path = folder / index.clip(c).name;
    }
    MOTIONDB_ASSIGN_OR_RETURN(const BvhReadResult read, ReadBvhFile(path.string()));
    for (const double speed : {0.7, 1.4}) {
      MOTIONDB_ASSIGN_OR_RETURN(
          const Clip copy, Clip::Create(read.clip.shared_skeleton(), read.clip.frame_time() / speed,
                                        read.clip.rotations(), read.clip.positions()));
      MOTIONDB_ASSIGN_OR_RETURN(RowMatrixXf coordinates, SearchCoordinates(*library.space, copy));
      const int64_t id = static_cast<int64_t>(clips.size());
      copy_of[id] = c;
      clips.push_back(
          {id, index.clip(c).name + "@" + std::to_string(speed), {}, std::move(coordinates)});
    }
  }
  if (gestures.empty()) {
    std::printf("time-scaled copies: no gesture (raise-up-*, wave-*) in the library\n");
    return absl::OkStatus();
  }
  MOTIONDB_ASSIGN_OR_RETURN(
      const std::unique_ptr<LibraryIndex> scaled,
      LibraryIndex::Build(std::move(clips), index.rate(), {flags.retrieval.params.ann_dims}));
  MOTIONDB_ASSIGN_OR_RETURN(const auto baseline,
                            bench::WindowVectorBaseline::Build(*scaled, baseline_options));
  int fast_found = 0, baseline_found = 0;
  for (const int q : gestures) {
    SearchParams params = flags.retrieval.params;
    params.max_results = 3;
    for (int c = 0; c < scaled->clip_count(); ++c) {
      if (c != q) params.clip_ids.push_back(c);
    }
    const CoordinateView query = scaled->clip_coordinates(q);
    MOTIONDB_ASSIGN_OR_RETURN(const SearchResponse fast, Search(*scaled, query, params));
    const auto count = [&](const std::vector<SearchResult>& results) {
      int found = 0;
      for (const SearchResult& r : results) {
        const auto it = copy_of.find(r.clip_id);
        found += it != copy_of.end() && it->second == q;
      }
      return found;
    };
    fast_found += count(fast.results);
    baseline_found += count(BaselineSearch(*baseline, *scaled, query, params));
  }
  const double copies = 2.0 * gestures.size();
  std::printf(
      "time-scaled copies (0.7x, 1.4x) of %zu gestures in the first 3: fast %.3f, window "
      "baseline %.3f\n",
      gestures.size(), fast_found / copies, baseline_found / copies);
  return absl::OkStatus();
}

// FLANN's recall against the exact nearest windows, mean over the queries (every clip).
double MeanWindowRecall(const bench::WindowVectorBaseline& baseline, const LibraryIndex& library,
                        const RetrievalOptions& options, int k) {
  double sum = 0;
  int queries = 0;
  for (int c = 0; c < library.clip_count(); ++c) {
    if (!options.queries.empty() && !options.queries[c]) continue;
    sum += baseline.WindowRecall(library.clip_coordinates(c), k);
    ++queries;
  }
  return queries > 0 ? sum / queries : 0.0;
}

// The three searches side by side.
void PrintTable(const RetrievalOptions& options, const RetrievalReport& report,
                const std::string& split, double motiondb_mib, double baseline_mib) {
  const BaselineFigures& b = report.baseline;
  const bool exact = report.exact_queries > 0, base = b.queries > 0;
  // A figure, or "-" where the search did not run.
  const auto cell = [](bool have, const char* format, double value) {
    char text[32] = "-";
    if (have) std::snprintf(text, sizeof(text), format, value);
    return std::string(text);
  };
  std::printf(
      "\n| %s split, %d queries (exact: %d) | motiondb fast | motiondb exact | window "
      "baseline |\n|---|---|---|---|\n",
      split.c_str(), report.queries, report.exact_queries);
  std::printf("| precision@%d | %.3f | %s | %s |\n", options.precision_at, report.precision,
              cell(exact, "%.3f", report.exact_precision).c_str(),
              cell(base, "%.3f", b.precision).c_str());
  std::printf("| precision@%d | %.3f | %s | %s |\n", options.wide_precision_at,
              report.wide_precision, cell(exact, "%.3f", report.exact_wide_precision).c_str(),
              cell(base, "%.3f", b.wide_precision).c_str());
  std::printf("| recall@%d against exact | %s | %s | %s |\n", options.recall_at,
              cell(exact, "%.3f", report.recall).c_str(), exact ? "1" : "-",
              cell(exact && base, "%.3f", b.recall).c_str());
  std::printf("| latency p50 / p90 / p99, ms | %.2f / %.2f / %.2f | %s / - / %s | %s / %s / %s |\n",
              report.latency_p50_ms, report.latency_p90_ms, report.latency_p99_ms,
              cell(exact, "%.1f", report.exact_latency_p50_ms).c_str(),
              cell(exact, "%.1f", report.exact_latency_p99_ms).c_str(),
              cell(base, "%.2f", b.latency_p50_ms).c_str(),
              cell(base, "%.2f", b.latency_p90_ms).c_str(),
              cell(base, "%.2f", b.latency_p99_ms).c_str());
  std::printf("| index memory, MiB | %.1f | (the same coordinates) | %s |\n", motiondb_mib,
              cell(base, "%.1f", baseline_mib).c_str());
  if (!b.precision_by_group.empty()) {
    std::printf("baseline precision@%d by %s:", options.precision_at, split.c_str());
    for (const auto& [group, precision] : b.precision_by_group) {
      std::printf(" %s %.3f", group.c_str(), precision);
    }
    std::printf("\n");
  }
}

// Groups and queries of `split` (see the file comment).
void SetSplit(const testing::LabelledIndex& library, const std::string& split,
              RetrievalOptions* options) {
  if (split == "style") options->groups = library.styles;
  if (split != "dataset") return;
  options->groups = library.sources;
  for (const std::string& source : library.sources) {
    options->queries.push_back(source == library.sources.front());
  }
}

absl::Status Run(QualityFlags& flags) {
  std::vector<std::filesystem::path> folders;
  for (const std::string& folder : flags.folders) {
    if (!std::filesystem::is_directory(folder)) {
      std::printf("search_quality: %s is absent; nothing measured\n", folder.c_str());
      return absl::OkStatus();
    }
    folders.push_back(folder);
  }
  SpaceOptions& space_options = flags.space;
  const std::string& metric = flags.metric;
  space_options.metric = metric == "eigen" ? SpaceMetric::kEigenvalueScaled : SpaceMetric::kUnit;
  MOTIONDB_ASSIGN_OR_RETURN(space_options.weights.preset, ParseWeightPreset(flags.weights));
  for (const std::string& entry : flags.weight_overrides) {
    MOTIONDB_ASSIGN_OR_RETURN(const auto joint_weight, cli::ParseJointValue(entry, "--weight"));
    space_options.weights.overrides[joint_weight.first] = joint_weight.second;
  }
  space_options.pose.remove_heading = !flags.keep_heading;
  space_options.pose.root_velocity = flags.root_velocity > 0;
  if (flags.root_velocity > 0) space_options.root_velocity_weight = flags.root_velocity;

  RetrievalOptions& options = flags.retrieval;
  SearchParams& params = flags.retrieval.params;
  const std::string& neutral = flags.neutral;
  params.neutral = neutral == "origin"     ? NeutralPose::kOrigin
                   : neutral == "boundary" ? NeutralPose::kBoundaryMean
                                           : NeutralPose::kQueryMean;
  params.refine = !flags.no_refine;
  if (flags.places > 0) {
    params.seed_selection = SeedSelection::kDistinctPlaces;
    params.places = flags.places;
  } else if (flags.windows) {
    params.seed_selection = SeedSelection::kNearestWindows;
  } else if (flags.shapes) {
    params.seed_selection = SeedSelection::kShapeWindows;
  }

  const bench::Clock::time_point start = bench::Clock::now();
  const testing::Takes takes = flags.takes == "first-half"    ? testing::Takes::kFirstHalf
                               : flags.takes == "second-half" ? testing::Takes::kSecondHalf
                                                              : testing::Takes::kAll;
  MOTIONDB_ASSIGN_OR_RETURN(
      const testing::LabelledIndex library,
      testing::LoadLabelledIndex(folders, space_options, {params.ann_dims}, takes));
  const double setup_s = bench::SecondsSince(start);
  SetSplit(library, flags.split, &options);

  bench::WindowBaselineOptions& baseline_options = flags.baseline;
  baseline_options.kind = flags.baseline_index == "k-means"  ? bench::WindowIndexKind::kKMeans
                          : flags.baseline_index == "linear" ? bench::WindowIndexKind::kLinear
                                                             : bench::WindowIndexKind::kKdForest;
  std::unique_ptr<bench::WindowVectorBaseline> baseline;
  double baseline_build_s = 0, window_recall = 0;
  if (flags.learned_metric < 0) {
    const bench::Clock::time_point baseline_start = bench::Clock::now();
    MOTIONDB_ASSIGN_OR_RETURN(baseline,
                              bench::WindowVectorBaseline::Build(*library.index, baseline_options));
    baseline_build_s = bench::SecondsSince(baseline_start);
    options.baseline = [&](CoordinateView query, const SearchParams& p) {
      return BaselineSearch(*baseline, *library.index, query, p);
    };
    window_recall = MeanWindowRecall(*baseline, *library.index, options, flags.window_recall_k);
  }
  MOTIONDB_ASSIGN_OR_RETURN(
      const RetrievalReport report,
      flags.learned_metric < 0 ? EvaluateRetrieval(*library.index, library.labels, options)
      : flags.split == "one"
          ? testing::EvaluateFirstSourceInLearnedMetric(library, options,
                                                        {.shrink = flags.learned_metric})
          : testing::EvaluateInLearnedMetric(library, options, {.shrink = flags.learned_metric},
                                             flags.unseen_labels));

  std::printf(
      "%s (takes: %s): %d clips, %lld frames at %.0f Hz, %d dims; load+space+index %.1f s\n",
      absl::StrJoin(flags.folders, " + ").c_str(), flags.takes.c_str(), library.index->clip_count(),
      static_cast<long long>(library.index->total_frames()), library.space->sample_rate(),
      library.space->dims(), setup_s);
  std::printf(
      "metric %s, weights %s, root velocity %g, %s %d, ann_dims %d, dtw_dims %d, slope %d, "
      "neutral %s%s%s\n",
      metric.c_str(), std::string(WeightPresetName(space_options.weights.preset)).c_str(),
      flags.root_velocity, SeedSelectionName(params.seed_selection),
      flags.places > 0 ? flags.places : params.neighbours, params.ann_dims, params.dtw_dims,
      params.slope_limit, neutral.c_str(),
      space_options.pose.remove_heading ? "" : ", heading kept",
      params.refine ? "" : ", no refinement");
  std::printf("joint weights:");
  const Eigen::VectorXd& joint_weights = library.space->data().joint_weights;
  for (int j = 0; j < joint_weights.size(); ++j) {
    std::printf(" %s %.3g", library.space->skeleton().joint(j).name.c_str(), joint_weights[j]);
  }
  std::printf("\n");
  std::printf(
      "fast:  precision@%d %.3f over %d queries (split %s, %d left out), latency p50 %.2f ms p99 "
      "%.2f ms\n",
      options.precision_at, report.precision, report.queries, flags.split.c_str(),
      report.skipped_queries, report.latency_p50_ms, report.latency_p99_ms);
  std::printf("fast stages, mean ms:");
  for (const auto& [stage, ms] : report.mean_stage_ms) std::printf(" %s %.2f", stage.c_str(), ms);
  std::printf("\n");
  if (report.exact_queries > 0) {
    std::printf(
        "exact: precision@%d %.3f over %d queries, latency p50 %.1f ms; recall@%d of "
        "fast vs exact %.3f\n",
        options.precision_at, report.exact_precision, report.exact_queries,
        report.exact_latency_p50_ms, options.recall_at, report.recall);
  }
  for (const auto& [label, precision] : report.precision_by_label) {
    std::printf("  %-22s precision@%d %.3f, found:", label.c_str(), options.precision_at,
                precision);
    for (const auto& [found, count] : report.confusion.at(label)) {
      std::printf(" %s %d", found.c_str(), count);
    }
    std::printf("\n");
  }
  for (const auto& [group, precision] : report.precision_by_group) {
    std::printf("  %-22s precision@%d %.3f\n", group.c_str(), options.precision_at, precision);
  }
  constexpr double kMiB = 1024.0 * 1024.0;
  if (baseline) {
    std::printf(
        "window baseline: %s, %d trees, checks %d, windows of %s s, stride 1/%d, %d samples x %d "
        "dims; built in %.1f s; FLANN recall@%d against the exact nearest windows %.3f\n",
        bench::WindowIndexKindName(baseline_options.kind), baseline_options.trees,
        baseline_options.checks, absl::StrJoin(baseline_options.window_s, "/").c_str(),
        baseline_options.stride_divisor, baseline_options.samples, baseline->dims(),
        baseline_build_s, flags.window_recall_k, window_recall);
    for (const auto& [label, precision] : report.baseline.precision_by_label) {
      std::printf("  baseline %-22s precision@%d %.3f\n", label.c_str(), options.precision_at,
                  precision);
    }
  } else {
    std::printf("window baseline: not run with --learned-metric\n");
  }
  PrintTable(options, report, flags.split,
             (library.index->coordinate_bytes() + library.index->tree_bytes() +
              library.index->shape_bytes()) /
                 kMiB,
             baseline ? baseline->memory_bytes() / kMiB : 0.0);
  if (flags.time_scaled && baseline) {
    MOTIONDB_RETURN_IF_ERROR(MeasureTimeScaled(flags, library, folders, baseline_options));
  }
  return absl::OkStatus();
}

}  // namespace
}  // namespace motiondb

int main(int argc, char** argv) {
  CLI::App app("Retrieval quality of the search on real labelled data.", "search_quality");
  motiondb::QualityFlags flags;
  motiondb::AddFlags(app, &flags);
  if (const std::optional<int> exit_code = motiondb::cli::ParseCommandLine(app, argc, argv)) {
    return *exit_code;
  }
  const absl::Status status = motiondb::Run(flags);
  if (!status.ok()) {
    std::fprintf(stderr, "search_quality: %s\n", std::string(status.message()).c_str());
    return 1;
  }
  return 0;
}
