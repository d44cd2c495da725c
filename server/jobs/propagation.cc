#include "server/jobs/propagation.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <map>
#include <mutex>
#include <tuple>
#include <utility>

#include <nlohmann/json.hpp>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "server/label_catalog.h"
#include "server/space_lookup.h"
#include "util/parallel_for.h"
#include "util/status_macros.h"

namespace motiondb::server {
namespace {

using Json = nlohmann::ordered_json;

// The search parameters as the runner would resolve them, checked once before the job is
// queued, so that a bad parameter fails the start rather than every query.
absl::Status CheckSearch(const SearchRequest& search, int dims) {
  if (!search.params.clip_ids.empty()) {
    return absl::InvalidArgumentError(
        "search.clip_ids: a propagation searches every clip of the space (filter by tags)");
  }
  if (search.params.return_path) {
    return absl::InvalidArgumentError("search.return_path: a propagation keeps no paths");
  }
  return ValidateSearchParams(WithSearchDims(search, dims), dims);
}

// Whether `a` and `b` (same clip) share more than half of the shorter one's frames: a long
// range containing a short one overlaps it, whichever of the two is measured.
bool OverlapsByHalf(const storage::LabelRecord& a, const storage::LabelRecord& b) {
  const int64_t shared =
      std::min(a.last_frame, b.last_frame) - std::max(a.first_frame, b.first_frame) + 1;
  const int64_t shorter =
      std::min(a.last_frame - a.first_frame + 1, b.last_frame - b.first_frame + 1);
  return 2 * shared > shorter;
}

// A label's candidate ranges, before their values are known: value holds the label's.
void AddCandidates(const storage::LabelRecord& label, const SearchOutcome& found, int64_t space_id,
                   const std::string& job_id, std::vector<storage::LabelRecord>* candidates) {
  for (const SearchHit& hit : found.hits) {
    storage::LabelRecord& candidate = candidates->emplace_back();
    candidate.clip_id = hit.clip_id;
    candidate.first_frame = hit.start_frame;
    candidate.last_frame = hit.end_frame;
    candidate.descriptor = label.descriptor;
    candidate.value = label.value;
    candidate.origin = storage::LabelOrigin::kPropagated;
    candidate.source_label_id = label.label_id;
    candidate.space_id = space_id;
    candidate.score = hit.score;
    candidate.job_id = job_id;
  }
}

// A query's failure that says the label's range cannot be a query (too short, its clip gone or
// not indexed yet), which skips the label; other failures end the job.
bool SkipsLabel(const absl::Status& status) {
  return absl::IsInvalidArgument(status) || absl::IsNotFound(status) ||
         absl::IsFailedPrecondition(status) || absl::IsUnavailable(status);
}

}  // namespace

absl::StatusOr<PropagationRequest> ResolvePropagation(storage::Database& database,
                                                      const IndexRegistry& registry,
                                                      PropagationRequest request) {
  MOTIONDB_ASSIGN_OR_RETURN(const std::shared_ptr<const SpaceSnapshot> snapshot,
                            FindSpace(registry, request.space));
  for (size_t i = 0; i < request.descriptors.size(); ++i) {
    // The rules of a label's descriptor: a descriptor no label can carry has nothing to spread.
    MOTIONDB_RETURN_IF_ERROR(
        storage::CheckDescriptor(absl::StrCat("descriptors[", i, "]"), request.descriptors[i]));
  }
  if (request.descriptors.empty()) {
    MOTIONDB_ASSIGN_OR_RETURN(request.descriptors, database.ManualDescriptors());
    if (request.descriptors.empty()) {
      return absl::FailedPreconditionError(
          "descriptors: none given and no manual label exists to propagate; add labels first");
    }
  }
  std::sort(request.descriptors.begin(), request.descriptors.end());
  request.descriptors.erase(std::unique(request.descriptors.begin(), request.descriptors.end()),
                            request.descriptors.end());
  if (request.rival_share && !(*request.rival_share > 0 && *request.rival_share <= 1)) {
    return absl::InvalidArgumentError(
        absl::StrCat("rival_share: ", *request.rival_share, " is not in (0, 1]"));
  }
  MOTIONDB_RETURN_IF_ERROR(CheckSearch(request.search, snapshot->space->dims()));
  return request;
}

std::string ParametersJson(const PropagationRequest& request) {
  const SearchRequest& search = request.search;
  const SearchParams& params = search.params;
  Json json = {{"space", request.space},
               {"descriptors", request.descriptors},
               {"max_results", params.max_results},
               {"neighbours", params.neighbours},
               {"places", params.places},
               {"seed_selection", SeedSelectionName(params.seed_selection)},
               {"epsilon", params.epsilon},
               {"slope_limit", params.slope_limit},
               {"cluster_gap_s", params.cluster_gap_s},
               {"max_overlap", params.max_overlap},
               {"refine", params.refine},
               {"exact", search.exact},
               {"tags", params.tags}};
  if (search.ann_dims) json["ann_dims"] = *search.ann_dims;
  if (search.dtw_dims) json["dtw_dims"] = *search.dtw_dims;
  if (request.rival_share) json["rival_share"] = *request.rival_share;
  return json.dump();
}

PropagationTarget TargetOf(const storage::JobRecord& job) {
  PropagationTarget target;
  const Json json = Json::parse(job.parameters_json, nullptr, /*allow_exceptions=*/false);
  if (!json.is_object()) return target;
  if (const auto space = json.find("space"); space != json.end() && space->is_string()) {
    target.space = space->get<std::string>();
  }
  if (const auto list = json.find("descriptors"); list != json.end() && list->is_array()) {
    for (const Json& item : *list) {
      if (item.is_string()) target.descriptors.push_back(item.get<std::string>());
    }
  }
  return target;
}

double SimilarityFactor(double score, double scale) {
  const double ratio = score / scale;
  return std::exp2(-ratio * ratio);
}

absl::StatusOr<double> SpaceScoreScale(const SpaceSnapshot& snapshot, const SearchRunner& runner,
                                       int threads, const std::function<bool()>& should_stop) {
  std::vector<std::pair<int64_t, ClipTiming>> clips(snapshot.clips.begin(), snapshot.clips.end());
  std::sort(clips.begin(), clips.end(),
            [](const auto& a, const auto& b) { return a.first < b.first; });
  int64_t total = 0;
  for (const auto& [clip_id, timing] : clips) total += timing.frame_count;
  std::vector<SearchRequest> windows;
  size_t clip = 0;
  int64_t clip_start = 0;  // the first frame of clips[clip] in the library's frames
  for (int w = 0; w < kScaleWindows && total > 0; ++w) {
    const int64_t at = (2 * w + 1) * total / (2 * kScaleWindows);
    while (at >= clip_start + clips[clip].second.frame_count) {
      clip_start += clips[clip++].second.frame_count;
    }
    const ClipTiming& timing = clips[clip].second;
    const int length = std::max(1, static_cast<int>(std::lround(kScaleWindowSeconds * timing.fps)));
    const int first =
        std::max(0, std::min(static_cast<int>(at - clip_start), timing.frame_count - length));
    SearchRequest& search = windows.emplace_back();
    search.space = snapshot.record.name;
    search.query = ClipSelection{clips[clip].first, first,
                                 std::min(timing.frame_count - 1, first + length - 1)};
    search.params.max_results = kScaleRank;
    search.exclude_query = true;
    search.threads = 1;  // the windows are shared out over the job's own threads
  }
  // NaN: the window left out.
  std::vector<double> last_scores(windows.size(), std::nan(""));
  MOTIONDB_RETURN_IF_ERROR(ParallelFor(
      static_cast<int64_t>(windows.size()), threads, [&](int64_t w, int) -> absl::Status {
        const absl::StatusOr<SearchOutcome> found = runner.Run(windows[w], should_stop);
        if (absl::IsCancelled(found.status())) return found.status();
        // A window that cannot be a query (a clip too short) is left out like a short list.
        if (found.ok() && static_cast<int>(found->hits.size()) == kScaleRank &&
            found->hits.back().score > 0) {
          last_scores[w] = found->hits.back().score;
        }
        return absl::OkStatus();
      }));
  std::erase_if(last_scores, [](double score) { return std::isnan(score); });
  if (last_scores.empty()) return 1;
  const auto middle = last_scores.begin() + last_scores.size() / 2;
  std::nth_element(last_scores.begin(), middle, last_scores.end());
  return *middle;
}

absl::StatusOr<double> ScoreScales::Get(const std::shared_ptr<const SpaceSnapshot>& snapshot,
                                        const SearchRunner& runner, int threads,
                                        const std::function<bool()>& should_stop) {
  const int64_t space_id = snapshot->record.space_id;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (const auto cached = by_space_.find(space_id);
        cached != by_space_.end() && cached->second.snapshot.lock() == snapshot) {
      return cached->second.scale;
    }
  }
  // Measured outside the lock: two jobs measuring one space at once compute the same value.
  MOTIONDB_ASSIGN_OR_RETURN(const double scale,
                            SpaceScoreScale(*snapshot, runner, threads, should_stop));
  std::lock_guard<std::mutex> lock(mutex_);
  by_space_[space_id] = {snapshot, scale};
  return scale;
}

std::vector<storage::LabelRecord> KeepStrongest(std::vector<storage::LabelRecord> candidates,
                                                const std::vector<storage::LabelRecord>& manual) {
  using Key = std::pair<std::string, int64_t>;  // descriptor, clip
  std::map<Key, std::vector<storage::LabelRecord>> taken;
  for (const storage::LabelRecord& label : manual) {
    taken[{label.descriptor, label.clip_id}].push_back(label);
  }
  // Ties in the order of clip and frames, so that a re-run writes the same labels.
  std::sort(candidates.begin(), candidates.end(), [](const auto& a, const auto& b) {
    return std::tie(b.value, a.score, a.clip_id, a.first_frame, a.last_frame, a.source_label_id) <
           std::tie(a.value, b.score, b.clip_id, b.first_frame, b.last_frame, b.source_label_id);
  });
  std::vector<storage::LabelRecord> kept;
  for (storage::LabelRecord& candidate : candidates) {
    std::vector<storage::LabelRecord>& near = taken[{candidate.descriptor, candidate.clip_id}];
    const bool covered = std::any_of(near.begin(), near.end(), [&](const auto& other) {
      return OverlapsByHalf(candidate, other);
    });
    if (covered) continue;
    near.push_back(candidate);
    kept.push_back(std::move(candidate));
  }
  return kept;
}

std::vector<storage::LabelRecord> DropContested(std::vector<storage::LabelRecord> kept,
                                                double share) {
  std::map<int64_t, std::vector<const storage::LabelRecord*>> by_clip;
  for (const storage::LabelRecord& label : kept) by_clip[label.clip_id].push_back(&label);
  std::vector<bool> contested(kept.size(), false);
  for (size_t i = 0; i < kept.size(); ++i) {
    const storage::LabelRecord& label = kept[i];
    for (const storage::LabelRecord* rival : by_clip[label.clip_id]) {
      if (rival->descriptor != label.descriptor && OverlapsByHalf(label, *rival) &&
          rival->value >= share * label.value) {
        contested[i] = true;
        break;
      }
    }
  }
  std::vector<storage::LabelRecord> uncontested;
  for (size_t i = 0; i < kept.size(); ++i) {
    if (!contested[i]) uncontested.push_back(std::move(kept[i]));
  }
  return uncontested;
}

absl::StatusOr<storage::PropagationOutput> RunPropagation(
    storage::Database& database, const IndexRegistry& registry, const SearchRunner& runner,
    ScoreScales& scales, const PropagationRequest& request, const std::string& job_id, int threads,
    const std::function<bool()>& should_stop,
    const std::function<void(const PropagationProgress&)>& on_progress) {
  MOTIONDB_ASSIGN_OR_RETURN(const std::shared_ptr<const SpaceSnapshot> snapshot,
                            FindSpace(registry, request.space));
  std::vector<storage::LabelRecord> manual, queries;
  for (const std::string& descriptor : request.descriptors) {
    MOTIONDB_ASSIGN_OR_RETURN(std::vector<storage::LabelRecord> labels,
                              ManualLabels(database, descriptor));
    for (storage::LabelRecord& label : labels) {
      if (snapshot->clips.contains(label.clip_id)) queries.push_back(label);
      manual.push_back(std::move(label));
    }
  }
  PropagationProgress progress{.total = static_cast<int64_t>(queries.size())};
  on_progress(progress);
  // Each label's candidates apart, so that the job's output does not depend on which thread
  // searched what; `progress`, the callback and `last_skip` under `progress_mutex`.
  std::vector<std::vector<storage::LabelRecord>> found_by_label(queries.size());
  std::mutex progress_mutex;
  absl::Status last_skip;
  int64_t last_skip_index = -1;  // the label of last_skip, the highest skipped
  MOTIONDB_RETURN_IF_ERROR(ParallelFor(
      static_cast<int64_t>(queries.size()), threads, [&](int64_t i, int) -> absl::Status {
        const storage::LabelRecord& label = queries[i];
        if (should_stop()) return absl::CancelledError("the job was stopped between queries");
        SearchRequest search = request.search;
        search.space = request.space;
        search.query = ClipSelection{label.clip_id, static_cast<int>(label.first_frame),
                                     static_cast<int>(label.last_frame)};
        search.exclude_query = true;
        // One thread a search: the job shares its queries out over its own threads
        // (--job-threads), whose cores a search's spinning helpers would only take.
        search.threads = 1;
        const absl::StatusOr<SearchOutcome> found = runner.Run(search, should_stop);
        if (found.ok()) {
          AddCandidates(label, *found, snapshot->record.space_id, job_id, &found_by_label[i]);
        } else if (!SkipsLabel(found.status())) {
          return absl::Status(found.status().code(), absl::StrCat("label ", label.label_id, ": ",
                                                                  found.status().message()));
        } else if (absl::IsNotFound(found.status()) && !FindSpace(registry, request.space).ok()) {
          // A space deleted while the job ran answers NOT_FOUND too: that ends the job.
          return absl::NotFoundError(
              absl::StrCat("space '", request.space, "' was deleted while the job ran"));
        }
        const std::lock_guard<std::mutex> lock(progress_mutex);
        if (found.ok()) {
          ++progress.queries;
        } else {
          ++progress.skipped;
          if (i > last_skip_index) {
            last_skip_index = i;
            last_skip = absl::Status(
                found.status().code(),
                absl::StrCat("label ", label.label_id, ": ", found.status().message()));
          }
        }
        ++progress.done;
        on_progress(progress);
        return absl::OkStatus();
      }));
  if (progress.total > 0 && progress.skipped == progress.total) {
    // Nothing was searched: an output would only delete the earlier one.
    return absl::FailedPreconditionError(absl::StrCat(
        "every one of the ", progress.total,
        " labels was skipped, none could be a query (the last: ", last_skip.message(), ")"));
  }
  MOTIONDB_ASSIGN_OR_RETURN(const double scale, scales.Get(snapshot, runner, threads, should_stop));
  std::vector<storage::LabelRecord> candidates;
  for (std::vector<storage::LabelRecord>& found : found_by_label) {
    std::move(found.begin(), found.end(), std::back_inserter(candidates));
  }
  for (storage::LabelRecord& candidate : candidates) {
    candidate.value *= SimilarityFactor(candidate.score, scale);
  }
  // A zero value (a label of value 0, or a factor that underflowed) carries nothing to spread.
  std::erase_if(candidates, [](const auto& candidate) { return !(candidate.value > 0); });
  storage::PropagationOutput output;
  output.space_id = snapshot->record.space_id;
  output.descriptors = request.descriptors;
  output.labels = KeepStrongest(std::move(candidates), manual);
  if (request.rival_share)
    output.labels = DropContested(std::move(output.labels), *request.rival_share);
  output.job.queries = progress.queries;
  output.job.queries_skipped = progress.skipped;
  output.job.done = progress.done;
  output.job.total = progress.total;
  return output;
}

}  // namespace motiondb::server
