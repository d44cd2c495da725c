#include "server/space_builder.h"

#include <algorithm>
#include <chrono>
#include <map>

#include "absl/strings/str_cat.h"
#include "absl/time/clock.h"
#include "absl/time/time.h"
#include "core/motion/resample.h"
#include "core/space/search_coordinates.h"
#include "server/frame_conversion.h"
#include "server/learned_metric_fit.h"
#include "server/listing.h"
#include "server/skeleton_map.h"
#include "server/space_report.h"
#include "util/name_text.h"
#include "util/status_macros.h"

namespace motiondb::server {
namespace {

absl::StatusOr<storage::ClipRecord> TrainingRecord(storage::Database& database, size_t index,
                                                   int64_t clip_id) {
  absl::StatusOr<storage::ClipRecord> record = database.GetClipRecord(clip_id);
  if (absl::IsNotFound(record.status())) {
    return absl::NotFoundError(absl::StrCat("training[", index, "]: no clip with id ", clip_id));
  }
  return record;
}

// The skeleton the space is built on, from the request's training clips, its skeleton_id, or
// the database's only skeleton.
absl::StatusOr<int64_t> ResolveSkeleton(storage::Database& database, const SpaceRequest& request) {
  if (!request.training.empty()) {
    std::optional<int64_t> skeleton;
    int64_t first_clip = 0;
    for (size_t i = 0; i < request.training.size(); ++i) {
      MOTIONDB_ASSIGN_OR_RETURN(const storage::ClipRecord record,
                                TrainingRecord(database, i, request.training[i].clip_id));
      if (!skeleton) {
        skeleton = record.skeleton_id;
        first_clip = record.clip_id;
      } else if (record.skeleton_id != *skeleton) {
        return absl::FailedPreconditionError(absl::StrCat(
            "training clips are of different skeletons: clip ", first_clip, " is on skeleton ",
            *skeleton, ", clip ", record.clip_id, " on skeleton ", record.skeleton_id));
      }
    }
    if (request.skeleton_id && *request.skeleton_id != *skeleton) {
      return absl::FailedPreconditionError(absl::StrCat("the training clips are on skeleton ",
                                                        *skeleton, ", not on skeleton_id ",
                                                        *request.skeleton_id));
    }
    return *skeleton;
  }
  if (request.skeleton_id) return *request.skeleton_id;
  MOTIONDB_ASSIGN_OR_RETURN(const std::vector<storage::SkeletonSummary> skeletons,
                            database.ListSkeletons());
  if (skeletons.size() > 1) {
    // Listed, so that the caller can choose one without another call.
    std::string listed;
    for (const storage::SkeletonSummary& skeleton : skeletons) {
      absl::StrAppend(&listed, listed.empty() ? "" : "; ", "skeleton ", skeleton.skeleton_id, " '",
                      SkeletonName(skeleton), "' with ", skeleton.clip_count,
                      skeleton.clip_count == 1 ? " clip" : " clips");
    }
    return absl::InvalidArgumentError(absl::StrCat("the database holds ", skeletons.size(),
                                                   " skeletons (", listed,
                                                   "): give skeleton_id, or training clips"));
  }
  MOTIONDB_ASSIGN_OR_RETURN(const storage::ClipPage page, database.ListClips(storage::Page{1, ""}));
  if (page.clips.empty()) {
    return absl::FailedPreconditionError("the database holds no clips to train a space on");
  }
  return page.clips.front().skeleton_id;
}

// A space over several skeletons: each listed once and mapped completely (by id), the training
// clips of them.
absl::StatusOr<std::map<int64_t, HumanoidMap>> ResolveSkeletons(storage::Database& database,
                                                                const SpaceRequest& request) {
  if (request.skeleton_id) {
    return absl::InvalidArgumentError("give skeleton_id or skeleton_ids, not both");
  }
  if (request.learned_metric) {
    return absl::FailedPreconditionError(
        "a learned metric is fitted in a space over one skeleton only: leave out skeleton_ids");
  }
  std::map<int64_t, HumanoidMap> maps;
  for (const int64_t id : request.skeleton_ids) {
    if (maps.contains(id)) {
      return absl::InvalidArgumentError(absl::StrCat("skeleton_ids lists skeleton ", id, " twice"));
    }
    MOTIONDB_ASSIGN_OR_RETURN(maps[id], CanonicalMapOfSkeleton(database, id));
  }
  for (size_t i = 0; i < request.training.size(); ++i) {
    MOTIONDB_ASSIGN_OR_RETURN(const storage::ClipRecord record,
                              TrainingRecord(database, i, request.training[i].clip_id));
    if (!maps.contains(record.skeleton_id)) {
      return absl::FailedPreconditionError(absl::StrCat("training[", i, "]: clip ", record.clip_id,
                                                        " is on skeleton ", record.skeleton_id,
                                                        ", which skeleton_ids does not list"));
    }
  }
  return maps;
}

}  // namespace

absl::Status ValidateSpaceName(const std::string& name) {
  if (name.empty() || name.size() > 128) {
    return absl::InvalidArgumentError("name: a space name has 1 to 128 characters");
  }
  for (const char c : name) {
    const bool allowed = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') ||
                         (c >= '0' && c <= '9') || c == '.' || c == '_' || c == '-';
    if (!allowed) {
      return absl::InvalidArgumentError(absl::StrCat(
          "name: ", QuotedNameText(name), " may only contain letters, digits, '.', '_' and '-'"));
    }
  }
  return absl::OkStatus();
}

absl::StatusOr<BuiltSpace> BuildSpace(storage::Database& database, const SpaceRequest& request,
                                      const std::function<bool()>& should_stop) {
  const auto start = std::chrono::steady_clock::now();
  auto check_stop = [&]() -> absl::Status {
    if (should_stop && should_stop()) {
      return absl::CancelledError("stopped by its caller while projecting the library");
    }
    return absl::OkStatus();
  };
  const bool several = !request.skeleton_ids.empty();
  std::map<int64_t, HumanoidMap> maps;  // of a space over several skeletons, by skeleton
  if (several) {
    MOTIONDB_ASSIGN_OR_RETURN(maps, ResolveSkeletons(database, request));
  }
  MOTIONDB_ASSIGN_OR_RETURN(const int64_t skeleton_id, several
                                                           ? request.skeleton_ids.front()
                                                           : ResolveSkeleton(database, request));
  std::vector<int64_t> clip_ids;
  for (const int64_t id : several ? request.skeleton_ids : std::vector<int64_t>{skeleton_id}) {
    MOTIONDB_ASSIGN_OR_RETURN(const std::vector<int64_t> of_skeleton, database.ClipsOfSkeleton(id));
    if (of_skeleton.empty()) {
      return absl::NotFoundError(absl::StrCat("skeleton ", id, " has no clips"));
    }
    clip_ids.insert(clip_ids.end(), of_skeleton.begin(), of_skeleton.end());
  }
  std::sort(clip_ids.begin(), clip_ids.end());
  SpaceOptions options = request.options;
  if (several) {
    options.representation = SpaceRepresentation::kCanonicalBones;
    // Each training clip's skeleton is one of the listed: found by its topology.
    options.map_of = [&](const Skeleton& skeleton) -> absl::StatusOr<HumanoidMap> {
      MOTIONDB_ASSIGN_OR_RETURN(const int64_t id, database.FindSkeleton(skeleton));
      const auto found = maps.find(id);
      if (found == maps.end()) {
        return absl::FailedPreconditionError(
            absl::StrCat("a training clip's skeleton is not one of skeleton_ids"));
      }
      return found->second;
    };
  }

  // The training clips are read from the database as each pass needs them (two to train, one to
  // measure), so that a space over a large library holds one clip at a time.
  std::vector<ClipSelection> ranges = request.training;
  if (ranges.empty()) {
    for (const int64_t id : clip_ids) ranges.push_back({id, std::nullopt, std::nullopt});
  }
  std::vector<TrainingReport> used;
  std::vector<storage::ClipRecord> records;
  for (size_t i = 0; i < ranges.size(); ++i) {
    MOTIONDB_ASSIGN_OR_RETURN(const storage::ClipRecord record,
                              TrainingRecord(database, i, ranges[i].clip_id));
    MOTIONDB_ASSIGN_OR_RETURN(const FrameRange frames,
                              ResolveFrameRange(ranges[i], static_cast<int>(record.frame_count),
                                                absl::StrCat("training[", i, "]")));
    used.push_back({ranges[i].clip_id, frames});
    records.push_back(record);
  }
  // The last clip read is kept, so that several ranges of one long take, given one after
  // another, read it once a pass.
  std::optional<storage::StoredClip> last;
  const TrainingSet training{ranges.size(), [&](size_t i) -> absl::StatusOr<TrainingClip> {
                               if (!last || last->record.clip_id != ranges[i].clip_id) {
                                 last.reset();
                                 MOTIONDB_ASSIGN_OR_RETURN(last,
                                                           database.GetClip(ranges[i].clip_id));
                               }
                               return TrainingClip{last->record.name, last->clip, used[i].frames};
                             }};

  MOTIONDB_ASSIGN_OR_RETURN(MotionSpace built, MotionSpace::Build(training, options, should_stop));
  // Counted once Build has checked the sample rate (a rate of 1e295 overflowed the count).
  int64_t training_frames = 0;
  for (size_t i = 0; i < used.size(); ++i) {
    training_frames +=
        ResampledFrameCount(used[i].frames.size(), records[i].frame_time, built.sample_rate());
  }
  MOTIONDB_ASSIGN_OR_RETURN(
      const std::vector<ReconstructionError> errors,
      built.RepresentationalError(training, kErrorReportDims, should_stop, options.map_of));
  last.reset();
  std::optional<FittedMetric> fitted;
  if (request.learned_metric) {
    MOTIONDB_ASSIGN_OR_RETURN(
        fitted, FitMetricOnLabels(database, built, clip_ids, *request.learned_metric, should_stop));
    MOTIONDB_ASSIGN_OR_RETURN(built, built.WithSearchTransform(fitted->transform));
  }
  auto space = std::make_shared<const MotionSpace>(std::move(built));

  BuiltSpace result;
  for (const int64_t id : clip_ids) {
    MOTIONDB_RETURN_IF_ERROR(check_stop());
    MOTIONDB_ASSIGN_OR_RETURN(const storage::StoredClip stored, database.GetClip(id));
    MOTIONDB_ASSIGN_OR_RETURN(
        RowMatrixXf coordinates,
        SearchCoordinates(*space, stored.clip, -1,
                          several ? &maps.at(stored.record.skeleton_id) : nullptr));
    result.clips.push_back({{id, stored.record.name, stored.record.tags, std::move(coordinates)},
                            ClipTiming::Of(stored.record)});
  }

  SpaceReport report = DescribeSpace(*space);
  report.training = std::move(used);
  report.weight_preset = request.options.weights.preset;
  report.training_frames = training_frames;
  report.reconstruction_error = errors;
  report.projected_clips = static_cast<int64_t>(result.clips.size());
  if (fitted) {
    report.learned_metric_shrink = request.learned_metric->shrink;
    report.learned_metric_examples = fitted->examples;
    report.learned_metric_descriptors = fitted->descriptors;
  }
  report.build_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();

  result.record.name = request.name;
  result.record.skeleton_id = skeleton_id;
  if (several) {
    // The space's own skeleton is its first training clip's (MotionSpace::skeleton), listed first.
    result.record.skeleton_id = records.front().skeleton_id;
    result.record.skeleton_ids = {result.record.skeleton_id};
    for (const int64_t id : request.skeleton_ids) {
      if (id != result.record.skeleton_id) result.record.skeleton_ids.push_back(id);
    }
  }
  result.record.version = 1;
  result.record.created_unix_ms = absl::ToUnixMillis(absl::Now());
  result.record.build_report_json = ReportToJson(report);
  result.space = std::move(space);
  return result;
}

}  // namespace motiondb::server
