// Retrieval in a metric learned from the labels (core/space/learned_metric.h), measured fairly:
// the metric a query is searched in is never fitted on the query's group (its style, or its
// dataset), and, when asked, not on its label either. Shared by the quality tests and the
// search_quality measurement program.
#ifndef MOTIONDB_TESTING_LEARNED_METRIC_FOLDS_H_
#define MOTIONDB_TESTING_LEARNED_METRIC_FOLDS_H_

#include "absl/status/statusor.h"
#include "core/space/learned_metric.h"
#include "testing/labelled_index.h"
#include "testing/retrieval_evaluation.h"

namespace motiondb::testing {

// `options` (with groups: a leave-group-out split) in learned metrics: for each group that holds
// queries (and, with `unseen_labels`, each label of its queries: one fold a group and label), a
// metric fitted on the clips of the other groups (and other labels), pairs of one label in two
// of library.styles; every clip's coordinates in it indexed; the fold's queries searched. The
// folds' figures merged: means over all queries, a label's precision its hits over its results.
absl::StatusOr<RetrievalReport> EvaluateInLearnedMetric(const LabelledIndex& library,
                                                        const RetrievalOptions& options,
                                                        const LearnedMetricOptions& metric,
                                                        bool unseen_labels = false);

// Leave-one-out among the first source's clips (options.groups unused) in a metric fitted on the
// other sources' clips: within one style, in a metric learned from other data.
absl::StatusOr<RetrievalReport> EvaluateFirstSourceInLearnedMetric(
    const LabelledIndex& library, const RetrievalOptions& options,
    const LearnedMetricOptions& metric);

}  // namespace motiondb::testing

#endif  // MOTIONDB_TESTING_LEARNED_METRIC_FOLDS_H_
