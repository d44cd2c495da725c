#include "testing/learned_metric_folds.h"

#include <algorithm>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "util/status_macros.h"

namespace motiondb::testing {
namespace {

// Every clip's search coordinates, in clip order.
std::vector<RowMatrixXf> AllCoordinates(const LabelledIndex& library) {
  std::vector<RowMatrixXf> coordinates;
  for (int c = 0; c < library.index->clip_count(); ++c) {
    coordinates.push_back(library.index->CopyClipCoordinates(c));
  }
  return coordinates;
}

// The metric fitted on the clips with `fit` set, paired across styles.
absl::StatusOr<Eigen::MatrixXd> FitOn(const LabelledIndex& library,
                                      const std::vector<RowMatrixXf>& coordinates,
                                      const std::vector<bool>& fit,
                                      const LearnedMetricOptions& metric) {
  std::vector<LabelledCurve> examples;
  for (size_t c = 0; c < coordinates.size(); ++c) {
    if (fit[c]) examples.push_back({&coordinates[c], library.labels[c], library.styles[c]});
  }
  return FitLearnedMetric(examples, metric);
}

// An index of the clips with `kept` set, their coordinates times `transform`, numbered from 0 in
// clip order; `labels` gets their labels.
absl::StatusOr<std::unique_ptr<LibraryIndex>> TransformedIndex(
    const LabelledIndex& library, const std::vector<RowMatrixXf>& coordinates,
    const Eigen::MatrixXd& transform, const std::vector<bool>& kept, int ann_dims,
    std::vector<std::string>* labels) {
  std::vector<LibraryClip> clips;
  for (size_t c = 0; c < coordinates.size(); ++c) {
    if (!kept[c]) continue;
    const LibraryIndex::ClipEntry& entry = library.index->clip(static_cast<int>(c));
    clips.push_back({static_cast<int64_t>(labels->size()), entry.name, entry.tags,
                     (coordinates[c].cast<double>() * transform).cast<float>()});
    labels->push_back(library.labels[c]);
  }
  return LibraryIndex::Build(std::move(clips), library.index->rate(), {ann_dims});
}

// Sums of the folds' figures, weighted by their query counts, and their means.
class FoldSums {
 public:
  // `group`: the one group of the fold's queries.
  void Add(const RetrievalReport& fold, const std::string& group) {
    all_.queries += fold.queries;
    all_.skipped_queries += fold.skipped_queries;
    all_.precision += fold.precision * fold.queries;
    all_.wide_precision += fold.wide_precision * fold.queries;
    all_.exact_queries += fold.exact_queries;
    all_.exact_precision += fold.exact_precision * fold.exact_queries;
    all_.exact_wide_precision += fold.exact_wide_precision * fold.exact_queries;
    all_.recall += fold.recall * fold.exact_queries;
    all_.latency_p50_ms += fold.latency_p50_ms * fold.queries;
    // The folds' largest: an upper bound of the merged percentiles.
    all_.latency_p90_ms = std::max(all_.latency_p90_ms, fold.latency_p90_ms);
    all_.latency_p99_ms = std::max(all_.latency_p99_ms, fold.latency_p99_ms);
    all_.exact_latency_p50_ms += fold.exact_latency_p50_ms * fold.exact_queries;
    all_.exact_latency_p99_ms = std::max(all_.exact_latency_p99_ms, fold.exact_latency_p99_ms);
    all_.precision_by_group[group] += fold.precision * fold.queries;
    group_queries_[group] += fold.queries;
    for (const auto& [label, found] : fold.confusion) {
      for (const auto& [found_label, count] : found) all_.confusion[label][found_label] += count;
    }
    for (const auto& [stage, ms] : fold.mean_stage_ms) {
      all_.mean_stage_ms[stage] += ms * fold.queries;
    }
  }

  absl::StatusOr<RetrievalReport> Means() && {
    if (all_.queries == 0) return absl::InvalidArgumentError("no query has enough relevant clips");
    all_.precision /= all_.queries;
    all_.wide_precision /= all_.queries;
    all_.latency_p50_ms /= all_.queries;
    for (auto& [stage, ms] : all_.mean_stage_ms) ms /= all_.queries;
    for (auto& [group, sum] : all_.precision_by_group) sum /= group_queries_[group];
    if (all_.exact_queries > 0) {
      all_.exact_precision /= all_.exact_queries;
      all_.exact_wide_precision /= all_.exact_queries;
      all_.recall /= all_.exact_queries;
      all_.exact_latency_p50_ms /= all_.exact_queries;
    }
    for (const auto& [label, found] : all_.confusion) {
      int results = 0;
      for (const auto& [found_label, count] : found) results += count;
      all_.precision_by_label[label] =
          found.contains(label) ? static_cast<double>(found.at(label)) / results : 0.0;
    }
    return std::move(all_);
  }

 private:
  RetrievalReport all_;
  std::map<std::string, int> group_queries_;
};

}  // namespace

absl::StatusOr<RetrievalReport> EvaluateInLearnedMetric(const LabelledIndex& library,
                                                        const RetrievalOptions& options,
                                                        const LearnedMetricOptions& metric,
                                                        bool unseen_labels) {
  const int clips = library.index->clip_count();
  if (options.groups.size() != static_cast<size_t>(clips)) {
    return absl::InvalidArgumentError("groups: one per library clip (a leave-group-out split)");
  }
  const std::vector<RowMatrixXf> coordinates = AllCoordinates(library);
  std::set<std::pair<std::string, std::string>> folds;  // group, and label or ""
  for (int c = 0; c < clips; ++c) {
    if (options.queries.empty() || options.queries[c]) {
      folds.insert({options.groups[c], unseen_labels ? library.labels[c] : ""});
    }
  }
  FoldSums sums;
  for (const auto& [group, label] : folds) {
    std::vector<bool> fit(clips);
    RetrievalOptions fold = options;
    fold.queries.assign(clips, false);
    for (int c = 0; c < clips; ++c) {
      const bool same_label = label.empty() || library.labels[c] == label;
      fit[c] = options.groups[c] != group && (label.empty() || !same_label);
      fold.queries[c] = options.groups[c] == group && same_label &&
                        (options.queries.empty() || options.queries[c]);
    }
    MOTIONDB_ASSIGN_OR_RETURN(const Eigen::MatrixXd transform,
                              FitOn(library, coordinates, fit, metric));
    std::vector<std::string> labels;
    MOTIONDB_ASSIGN_OR_RETURN(
        const std::unique_ptr<LibraryIndex> index,
        TransformedIndex(library, coordinates, transform, std::vector<bool>(clips, true),
                         options.params.ann_dims, &labels));
    absl::StatusOr<RetrievalReport> report = EvaluateRetrieval(*index, labels, fold);
    // A fold of one label may hold only queries with too few clips of it to find.
    if (unseen_labels && absl::IsInvalidArgument(report.status())) continue;
    if (!report.ok()) return report.status();
    sums.Add(*report, group);
  }
  return std::move(sums).Means();
}

absl::StatusOr<RetrievalReport> EvaluateFirstSourceInLearnedMetric(
    const LabelledIndex& library, const RetrievalOptions& options,
    const LearnedMetricOptions& metric) {
  const std::vector<RowMatrixXf> coordinates = AllCoordinates(library);
  std::vector<bool> fit(coordinates.size()), searched(coordinates.size());
  for (size_t c = 0; c < coordinates.size(); ++c) {
    searched[c] = library.sources[c] == library.sources.front();
    fit[c] = !searched[c];
  }
  MOTIONDB_ASSIGN_OR_RETURN(const Eigen::MatrixXd transform,
                            FitOn(library, coordinates, fit, metric));
  std::vector<std::string> labels;
  MOTIONDB_ASSIGN_OR_RETURN(const std::unique_ptr<LibraryIndex> index,
                            TransformedIndex(library, coordinates, transform, searched,
                                             options.params.ann_dims, &labels));
  RetrievalOptions within = options;
  within.groups.clear();
  within.queries.clear();
  return EvaluateRetrieval(*index, labels, within);
}

}  // namespace motiondb::testing
