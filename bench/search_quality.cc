// Retrieval quality of the search on real labelled data (issue 4): every clip of a labelled
// folder (default ../shared/mocap/bandai2-normal; label = the file name's content field) is a
// query against the library of all the others, in a space trained on the folder. Prints mean
// precision@5 of the label for the fast and the exact search, the fast search's recall@10
// against the exact search, query latency and the mean stage times.
//
// usage: search_quality [--folder DIR] [--metric unit|eigen] [--weights mass|uniform]
//          [--rate HZ] [--neighbours K] [--ann-dims N] [--dtw-dims N] [--slope S]
//          [--neutral mean|boundary|origin] [--exact-every N] [--yaw-weight W] [--keep-heading]
//          [--no-refine]
#include <chrono>
#include <cstdio>

#include "bench/measure.h"
#include "testing/labelled_library.h"
#include "testing/retrieval_evaluation.h"
#include "util/command_line.h"
#include "util/status_macros.h"

namespace motiondb {
namespace {

absl::Status Run(const cli::CommandLine& line) {
  const std::filesystem::path mocap = bench::MocapRoot();
  const std::filesystem::path folder =
      line.value("folder").value_or((mocap / "bandai2-normal").string());
  if (!std::filesystem::is_directory(folder)) {
    std::printf("search_quality: %s is absent; nothing measured\n", folder.c_str());
    return absl::OkStatus();
  }
  SpaceOptions space_options;
  MOTIONDB_ASSIGN_OR_RETURN(const std::optional<double> rate, line.number("rate"));
  space_options.sample_rate = rate.value_or(space_options.sample_rate);
  const std::string metric = line.value("metric").value_or("unit");
  space_options.metric = metric == "eigen" ? SpaceMetric::kEigenvalueScaled : SpaceMetric::kUnit;
  MOTIONDB_ASSIGN_OR_RETURN(space_options.weights.preset,
                            ParseWeightPreset(line.value("weights").value_or("mass")));
  MOTIONDB_ASSIGN_OR_RETURN(const std::optional<double> yaw, line.number("yaw-weight"));
  space_options.yaw_rate_weight = yaw.value_or(space_options.yaw_rate_weight);
  space_options.pose.remove_heading = !line.flag("keep-heading");

  RetrievalOptions options;
  SearchParams& params = options.params;
  for (auto [name, field] : {std::pair{"neighbours", &params.neighbours},
                             {"ann-dims", &params.ann_dims},
                             {"dtw-dims", &params.dtw_dims},
                             {"slope", &params.slope_limit},
                             {"exact-every", &options.exact_every}}) {
    MOTIONDB_ASSIGN_OR_RETURN(const std::optional<int> value, line.integer(name));
    *field = value.value_or(*field);
  }
  const std::string neutral = line.value("neutral").value_or("mean");
  params.neutral = neutral == "origin"     ? NeutralPose::kOrigin
                   : neutral == "boundary" ? NeutralPose::kBoundaryMean
                                           : NeutralPose::kQueryMean;
  params.refine = !line.flag("no-refine");

  const bench::Clock::time_point start = bench::Clock::now();
  MOTIONDB_ASSIGN_OR_RETURN(const testing::LabelledLibrary library,
                            testing::LoadLabelledLibrary(folder, space_options, {params.ann_dims}));
  const double setup_s = bench::SecondsSince(start);
  MOTIONDB_ASSIGN_OR_RETURN(const RetrievalReport report,
                            EvaluateLeaveOneOut(*library.index, library.labels, options));

  std::printf("%s: %d clips, %lld frames at %.0f Hz, %d dims; load+space+index %.1f s\n",
              folder.c_str(), library.index->clip_count(),
              static_cast<long long>(library.index->total_frames()), library.space->sample_rate(),
              library.space->dims(), setup_s);
  std::printf(
      "metric %s, weights %s, neighbours %d, ann_dims %d, dtw_dims %d, slope %d, "
      "neutral %s%s%s\n",
      metric.c_str(), std::string(WeightPresetName(space_options.weights.preset)).c_str(),
      params.neighbours, params.ann_dims, params.dtw_dims, params.slope_limit, neutral.c_str(),
      space_options.pose.remove_heading ? "" : ", heading kept",
      params.refine ? "" : ", no refinement");
  std::printf("fast:  precision@%d %.3f over %d queries, latency p50 %.2f ms p99 %.2f ms\n",
              options.precision_at, report.precision, report.queries, report.latency_p50_ms,
              report.latency_p99_ms);
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
    std::printf("  %-22s precision@%d %.3f\n", label.c_str(), options.precision_at, precision);
  }
  return absl::OkStatus();
}

}  // namespace
}  // namespace motiondb

int main(int argc, char** argv) {
  const absl::StatusOr<motiondb::cli::CommandLine> line = motiondb::cli::CommandLine::Parse(
      std::vector<std::string>(argv + 1, argv + argc),
      {"folder", "metric", "weights", "rate", "neighbours", "ann-dims", "dtw-dims", "slope",
       "neutral", "exact-every", "yaw-weight"},
      {"keep-heading", "no-refine"});
  const absl::Status status = line.ok() ? motiondb::Run(*line) : line.status();
  if (!status.ok()) {
    std::fprintf(stderr, "search_quality: %s\n", std::string(status.message()).c_str());
    return 1;
  }
  return 0;
}
