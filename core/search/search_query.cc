#include "core/search/internal/search_query.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"
#include "util/status_macros.h"

namespace motiondb {

absl::StatusOr<SearchFilter> PrepareQuery(const LibraryIndex& library, CoordinateView query,
                                          const SearchParams& params) {
  MOTIONDB_RETURN_IF_ERROR(ValidateSearchParams(params, library.dims()));
  if (query.rows < 1) return absl::InvalidArgumentError("the query has no frames");
  if (query.stride < library.dims()) {
    return absl::InvalidArgumentError(absl::StrCat(
        "the query has ", query.stride, " dimensions; the library has ", library.dims()));
  }
  for (int64_t f = 0; f < query.rows; ++f) {
    if (!std::all_of(query.row(f), query.row(f) + library.dims(),
                     [](float v) { return std::isfinite(v); })) {
      return absl::InvalidArgumentError(absl::StrCat("query frame ", f, " is not finite"));
    }
  }
  if (params.characteristic_frame < -1 || params.characteristic_frame >= query.rows) {
    return absl::InvalidArgumentError(
        absl::StrCat("characteristic_frame ", params.characteristic_frame,
                     " is outside the query's frames 0-", query.rows - 1));
  }
  for (size_t i = 0; i < params.characteristic_frames.size(); ++i) {
    const int frame = params.characteristic_frames[i];
    if (frame < 0 || frame >= query.rows) {
      return absl::InvalidArgumentError(absl::StrCat("characteristic_frames[", i, "] ", frame,
                                                     " is outside the query's frames 0-",
                                                     query.rows - 1));
    }
    if (i > 0 && frame <= params.characteristic_frames[i - 1]) {
      return absl::InvalidArgumentError(absl::StrCat("characteristic_frames[", i, "] ", frame,
                                                     " does not follow the frame before it, ",
                                                     params.characteristic_frames[i - 1]));
    }
  }
  SearchFilter filter;
  if (params.excluded) {
    // A clip outside the library has no results to leave out.
    filter.excluded_clip = library.FindClip(params.excluded->clip_id);
    filter.excluded_first = params.excluded->first_frame;
    filter.excluded_last = params.excluded->last_frame;
  }
  if (params.clip_ids.empty() && params.tags.empty()) return filter;
  std::vector<bool>& allowed = filter.allowed;
  allowed.assign(library.clip_count(), false);
  for (int64_t id : params.clip_ids) {
    const int index = library.FindClip(id);
    if (index < 0) return absl::NotFoundError(absl::StrCat("clip ", id, " is not in the library"));
    allowed[index] = true;
  }
  if (!params.tags.empty()) {
    for (int c = 0; c < library.clip_count(); ++c) {
      if (!params.clip_ids.empty() && !allowed[c]) continue;  // both filters must hold
      const std::vector<std::string>& tags = library.clip(c).tags;
      allowed[c] = std::any_of(params.tags.begin(), params.tags.end(), [&](const std::string& t) {
        return std::find(tags.begin(), tags.end(), t) != tags.end();
      });
    }
  }
  return filter;
}

SearchResult MakeResult(int clip_index, int64_t clip_id, Warp warp, int64_t seed_frame) {
  SearchResult result;
  result.clip_index = clip_index;
  result.clip_id = clip_id;
  result.first_frame = warp.first;
  result.last_frame = warp.last;
  result.score = warp.score;
  result.seed_frame = seed_frame;
  result.path = std::move(warp.path);
  return result;
}

std::vector<SearchResult> FinishResults(const LibraryIndex& library, const SearchFilter& filter,
                                        std::vector<SearchResult> candidates,
                                        const SearchParams& params) {
  // Refinement and the exact search's paths may move a candidate that was admitted.
  std::erase_if(candidates, [&](const SearchResult& c) { return !filter.Admits(c); });
  std::vector<SearchResult> results =
      RankResults(std::move(candidates), params.max_overlap, params.max_results);
  for (SearchResult& result : results) {
    const LibraryIndex::ClipEntry& clip = library.clip(result.clip_index);
    result.clip_name = clip.name;
    result.start_s = result.first_frame / library.rate();
    result.end_s = result.last_frame / library.rate();
  }
  return results;
}

absl::Status SearchStopped() {
  return absl::CancelledError("the search was stopped by its caller");
}

double MillisecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

}  // namespace motiondb
