// A linear metric learned from labelled clips (issue 12's "metric learned from the labelled
// contents"), for measurement: the directions in which clips of one content but different styles
// differ, once aligned in time, are shrunk, and the space is rotated again so that its first
// dimensions (the ones the search's seeds and warps use) carry the most variance in the new
// metric, an LDA-like ratio of the library's spread to the styles' spread.
#ifndef MOTIONDB_BENCH_STYLE_METRIC_H_
#define MOTIONDB_BENCH_STYLE_METRIC_H_

#include <string>
#include <vector>

#include <Eigen/Core>

#include "absl/status/statusor.h"
#include "core/motion/matrix.h"

namespace motiondb::bench {

struct StyleMetricOptions {
  // 0 keeps the space's own metric (the result is its PCA rotation, the identity up to signs);
  // 1 whitens the style differences fully. In [0, 1].
  double shrink = 0.5;
  // Each fitting clip is aligned with at most this many clips of its content in other styles.
  int partners = 4;
};

// D x D: coordinates (frames x D rows) times it are the learned metric's coordinates, ordered by
// decreasing variance over the fitting clips and scaled so that their total variance is the
// original's. Fitted on the clips with `fit[c]` set: pairs of the same label and different
// styles. An error when no such pair is there.
absl::StatusOr<Eigen::MatrixXd> FitStyleMetric(const std::vector<RowMatrixXf>& coordinates,
                                               const std::vector<std::string>& labels,
                                               const std::vector<std::string>& styles,
                                               const std::vector<bool>& fit,
                                               const StyleMetricOptions& options);

}  // namespace motiondb::bench

#endif  // MOTIONDB_BENCH_STYLE_METRIC_H_
