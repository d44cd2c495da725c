#include "server/learned_metric_fit.h"

#include <algorithm>
#include <deque>
#include <map>
#include <set>
#include <string>

#include "absl/strings/str_cat.h"
#include "core/space/search_coordinates.h"
#include "server/frame_conversion.h"
#include "server/index_registry.h"
#include "server/label_catalog.h"
#include "util/status_macros.h"
#include "util/status_prefix.h"

namespace motiondb::server {

absl::StatusOr<FittedMetric> FitMetricOnLabels(storage::Database& database,
                                               const MotionSpace& space,
                                               const std::vector<int64_t>& clip_ids,
                                               const LearnedMetricOptions& options,
                                               const std::function<bool()>& should_stop) {
  MOTIONDB_ASSIGN_OR_RETURN(const std::vector<storage::LabelRecord> labels,
                            ManualLabels(database, ""));
  const std::set<int64_t> in_space(clip_ids.begin(), clip_ids.end());
  std::map<int64_t, std::vector<const storage::LabelRecord*>> by_clip;
  for (const storage::LabelRecord& label : labels) {
    if (label.value >= kMinExampleValue && in_space.contains(label.clip_id)) {
      by_clip[label.clip_id].push_back(&label);
    }
  }

  // The labelled ranges' aligned frames only (a label may cover a long take), at stable addresses.
  std::deque<RowMatrixXf> ranges;
  std::vector<LabelledCurve> examples;
  for (const auto& [clip_id, clip_labels] : by_clip) {
    if (should_stop && should_stop()) {
      return absl::CancelledError("stopped by its caller while fitting the learned metric");
    }
    MOTIONDB_ASSIGN_OR_RETURN(const storage::StoredClip stored, database.GetClip(clip_id));
    MOTIONDB_ASSIGN_OR_RETURN(const RowMatrixXf coordinates, SearchCoordinates(space, stored.clip));
    const ClipTiming timing = ClipTiming::Of(stored.record);
    const FrameConversion conversion(timing.fps, timing.frame_count, space.sample_rate(),
                                     coordinates.rows());
    for (const storage::LabelRecord* label : clip_labels) {
      const auto [first, last] = conversion.ToSpace(
          {static_cast<int>(label->first_frame), static_cast<int>(label->last_frame)});
      ranges.push_back(
          AlignedFrames(coordinates.middleRows(first, last - first + 1), options.max_frames));
      examples.push_back({&ranges.back(), label->descriptor, absl::StrCat(clip_id)});
    }
  }
  std::map<std::string, std::set<std::string>> clips_of;  // descriptor -> its clips
  for (const LabelledCurve& example : examples) clips_of[example.label].insert(example.group);
  if (std::none_of(clips_of.begin(), clips_of.end(),
                   [](const auto& descriptor) { return descriptor.second.size() > 1; })) {
    return absl::FailedPreconditionError(absl::StrCat(
        "learned_metric: needs one descriptor labelled (manual labels, value >= ", kMinExampleValue,
        ") on at least two clips of the space's skeleton; of its ", examples.size(),
        " such labels, no descriptor is on two clips"));
  }
  MOTIONDB_ASSIGN_OR_RETURN(
      const Eigen::MatrixXd transform,
      Prefixed("learned_metric", FitLearnedMetric(examples, options, should_stop)));
  return FittedMetric{transform, static_cast<int64_t>(examples.size()),
                      static_cast<int64_t>(clips_of.size())};
}

}  // namespace motiondb::server
