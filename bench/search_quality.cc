// Retrieval quality of the search on real labelled data (issues 4 and 12): the clips of labelled
// folders (default ../shared/mocap/bandai2-normal; label = the file name's content field, style
// = its style field) in a space trained on them all. `--split one`: every clip a query against
// all the others; `--split style`: against the clips of other styles only; `--split dataset`:
// the first folder's clips against the other folders' (on the contents they share). Prints
// mean precision@5 of the label for the fast and the exact search (per label, and per style or
// folder), the fast search's recall@10 against the exact search, latency and stage times.
//
// usage: search_quality [--folder DIR]... [--split one|style|dataset] [--metric unit|eigen]
//          [--weights mass|uniform] [--weight-floor F] [--weight JOINT=W]...
//          [--rate HZ] [--neighbours K] [--ann-dims N] [--dtw-dims N] [--slope S]
//          [--neutral mean|boundary|origin] [--exact-every N] [--yaw-weight W] [--keep-heading]
//          [--no-refine] [--points K] [--second-anchor S] [--learned-metric SHRINK]
//          [--unseen-labels]
//
// `--learned-metric` searches in a metric learned from the labels (core/space/learned_metric.h,
// testing/learned_metric_folds.h): with
// `--split style`, fitted for each style left out on the other styles' clips only (one index a
// fold, the folds' figures merged); with `dataset`, on the other folders'; with `one`, on the
// other folders' too, the first folder's clips searched among themselves.
#include <chrono>
#include <cstdio>
#include <string>
#include <tuple>
#include <vector>

#include "absl/strings/str_join.h"
#include "bench/measure.h"
#include "testing/labelled_index.h"
#include "testing/learned_metric_folds.h"
#include "testing/retrieval_evaluation.h"
#include "util/cli_conventions.h"
#include "util/status_macros.h"

namespace motiondb {
namespace {

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
  bool keep_heading = false, no_refine = false, windows = false;
  int places = 0;
  double learned_metric = -1;  // LearnedMetricOptions::shrink; negative: the space's metric
  bool unseen_labels = false;  // --learned-metric fitted without the queries' labels
  std::vector<std::string> weight_overrides;  // JOINT=W
  double root_velocity = SpaceOptions().root_velocity_weight;
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
  }

  const bench::Clock::time_point start = bench::Clock::now();
  MOTIONDB_ASSIGN_OR_RETURN(const testing::LabelledIndex library,
                            testing::LoadLabelledIndex(folders, space_options, {params.ann_dims}));
  const double setup_s = bench::SecondsSince(start);
  SetSplit(library, flags.split, &options);
  MOTIONDB_ASSIGN_OR_RETURN(
      const RetrievalReport report,
      flags.learned_metric < 0 ? EvaluateRetrieval(*library.index, library.labels, options)
      : flags.split == "one"
          ? testing::EvaluateFirstSourceInLearnedMetric(library, options,
                                                        {.shrink = flags.learned_metric})
          : testing::EvaluateInLearnedMetric(library, options, {.shrink = flags.learned_metric},
                                             flags.unseen_labels));

  std::printf("%s: %d clips, %lld frames at %.0f Hz, %d dims; load+space+index %.1f s\n",
              absl::StrJoin(flags.folders, " + ").c_str(), library.index->clip_count(),
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
