// A search metric learned from labelled examples (issue 12): the directions in which examples of
// one label but different groups (styles, performers, takes) differ, once aligned in time, are
// shrunk, and the coordinates are rotated again so that their first dimensions, the ones the
// search's seeds and warps use, carry the most variance in the new metric: an LDA-like ratio of
// the examples' spread to the groups' spread. Measured on bandai1's 15 styles (each style's
// queries in a metric fitted on the other 14): leave-style-out precision@5 0.648 -> 0.806 at 5
// warp dimensions and 0.828 at 10 (bench/notes/2026-12-06-across-styles.md, "A metric learned
// from the labels").
#ifndef MOTIONDB_CORE_SPACE_LEARNED_METRIC_H_
#define MOTIONDB_CORE_SPACE_LEARNED_METRIC_H_

#include <functional>
#include <string>

#include <Eigen/Core>

#include "absl/status/statusor.h"
#include "absl/types/span.h"
#include "core/motion/matrix.h"

namespace motiondb {

struct LearnedMetricOptions {
  // How far the groups' differences are whitened, in [0, 1): 0 keeps the coordinates' own metric
  // (the result is a rotation); towards 1 a direction counts the less the more groups differ
  // along it. Of 0.5-0.99 on bandai1, 0.95 was best (0.9 and 0.99 within 0.015 of it); 1 would
  // make directions in which no two groups differ infinitely long.
  double shrink = 0.95;
  // Each example is aligned with at most this many later examples of its label in other groups:
  // the fit's time grows with it (a dynamic time warp each).
  int partners = 4;
  // Longer examples are aligned over every k-th frame, at most this many: an alignment costs
  // time and memory as the product of the two lengths (300 x 300 frames: 1.4 MB, a few ms).
  // Bandai's clips, 6 s at 30 Hz on average, are aligned whole.
  int max_frames = 300;
};

// INVALID_ARGUMENT naming the field when an option is out of its range.
absl::Status ValidateLearnedMetricOptions(const LearnedMetricOptions& options);

// One example: a clip's (or a range's) search coordinates, its label, its group.
struct LabelledCurve {
  const RowMatrixXf* coordinates = nullptr;  // frames x dims; not owned
  std::string label;
  std::string group;
};

// D x D, D the examples' dimensions: search coordinates (rows) times it are the learned metric's
// coordinates, ordered by decreasing variance over the examples' frames and scaled so that their
// total variance is the original's. An error when the examples disagree on D, hold a non-finite
// number, or include no two of one label in two groups; CANCELLED when `should_stop`, asked
// between examples, says so.
absl::StatusOr<Eigen::MatrixXd> FitLearnedMetric(absl::Span<const LabelledCurve> examples,
                                                 const LearnedMetricOptions& options = {},
                                                 const std::function<bool()>& should_stop = {});

// The frames of `rows` an example is aligned over: every k-th, at most `max_frames` (at least 1).
// A caller holding many long examples may keep only these (the fit takes them as they are).
RowMatrixXf AlignedFrames(const Eigen::Ref<const RowMatrixXf>& rows, int max_frames);

}  // namespace motiondb

#endif  // MOTIONDB_CORE_SPACE_LEARNED_METRIC_H_
