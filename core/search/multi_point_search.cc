#include "core/search/multi_point_search.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>
#include <utility>

#include "absl/container/flat_hash_map.h"
#include "core/search/internal/search_query.h"
#include "core/search/motion_search.h"
#include "util/status_macros.h"

namespace motiondb {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

// Matches kept per part, per result asked (and at least kMinPartMatches): a part alone, one
// action, matches far more places than the whole query (every instance of its action in
// whatever company), and a chain needs its instance's match of every part among them.
constexpr int kPartMatchesPerResult = 10;
constexpr int kMinPartMatches = 200;

// Query rows [first, first + rows), anchored at its own row `anchor`.
struct Part {
  int first = 0;
  int rows = 0;
  int anchor = 0;
};

// The query cut halfway between adjacent anchors.
std::vector<Part> QueryParts(int64_t rows, const std::vector<int>& anchors) {
  std::vector<Part> parts;
  for (size_t k = 0; k < anchors.size(); ++k) {
    const int first = k == 0 ? 0 : (anchors[k - 1] + anchors[k]) / 2 + 1;
    const int end =
        k + 1 == anchors.size() ? static_cast<int>(rows) : (anchors[k] + anchors[k + 1]) / 2 + 1;
    parts.push_back({first, end - first, anchors[k] - first});
  }
  return parts;
}

// The best chain of matches of parts 0..k that ends in one match of part k.
struct Link {
  double cost = kInfinity;  // sum of pose distances over the chain's query rows
  int previous = -1;        // the chain's match of part k - 1
  // Where the chain's matches of parts k - 1 and k meet when they overlap: the clip frame that
  // the earlier one's rows matched past it and the later one's rows matched before it are moved
  // to (a pause at the junction); -1 when they do not overlap (the path jumps forward there).
  int64_t meet = -1;
};

// What the links need to price a junction: the query, the library, the warp's dimensions.
struct Chaining {
  CoordinateView query;
  const LibraryIndex& library;
  int dims = 0;
  int64_t max_gap = 0;  // library frames a jump may skip
};

// The change in cost when `match`'s rows [first, first + rows) of the query matched to clip
// frames beyond `frame` (before it when `before`) are matched to `frame` instead.
double ClampCost(const Chaining& chaining, const SearchResult& match, int first, bool before,
                 int64_t frame) {
  const CoordinateView clip = chaining.library.clip_coordinates(match.clip_index);
  double change = 0;
  for (size_t r = 0; r < match.path.size(); ++r) {
    const int64_t matched = match.path[r];
    if (before ? matched >= frame : matched <= frame) continue;
    const float* q = chaining.query.row(first + static_cast<int64_t>(r));
    change +=
        Distance(q, clip.row(frame), chaining.dims) - Distance(q, clip.row(matched), chaining.dims);
  }
  return change;
}

// Where adjacent parts' matches join, and the change in cost: nothing when the later one
// starts after the earlier one ends, at most max_gap later (a pause held longer in the clip than
// in the query is skipped); when they overlap, a frame between their anchors where the path
// pauses instead (held longer in the query): the cheapest of the later one's start, the earlier
// one's end and the middle between the anchors, of those that lie between them. nullopt: no
// join (a gap beyond max_gap, or the anchors out of order).
std::optional<std::pair<int64_t, double>> Join(const Chaining& chaining,
                                               const SearchResult& previous, int previous_first,
                                               const SearchResult& next, int next_first) {
  const int64_t gap = next.first_frame - previous.last_frame;
  if (gap - 1 > chaining.max_gap) return std::nullopt;  // gap - 1 frames skipped
  if (gap >= 0) return std::pair<int64_t, double>{-1, 0.0};
  if (previous.seed_frame > next.seed_frame) return std::nullopt;
  std::optional<std::pair<int64_t, double>> best;
  for (const int64_t meet :
       {next.first_frame, previous.last_frame, (previous.seed_frame + next.seed_frame) / 2}) {
    if (meet < previous.seed_frame || meet > next.seed_frame) continue;
    const double change = ClampCost(chaining, previous, previous_first, false, meet) +
                          ClampCost(chaining, next, next_first, true, meet);
    if (!best || change < best->second) best = {meet, change};
  }
  return best;
}

// Links of part k's `matches` onto the chains of part k - 1.
std::vector<Link> LinkPart(const Chaining& chaining, const Part& previous_part,
                           const std::vector<SearchResult>& previous,
                           const std::vector<Link>& previous_links, const Part& part,
                           const std::vector<SearchResult>& matches) {
  absl::flat_hash_map<int, std::vector<int>> previous_by_clip;
  for (size_t j = 0; j < previous.size(); ++j) {
    if (previous_links[j].cost < kInfinity) previous_by_clip[previous[j].clip_index].push_back(j);
  }
  std::vector<Link> links(matches.size());
  for (size_t i = 0; i < matches.size(); ++i) {
    const SearchResult& match = matches[i];
    const auto clip = previous_by_clip.find(match.clip_index);
    if (clip == previous_by_clip.end()) continue;
    const double own = match.score * part.rows;
    for (const int j : clip->second) {
      // No pruning on the previous chain's cost alone: a pause at the junction can lower it.
      const auto join = Join(chaining, previous[j], previous_part.first, match, part.first);
      if (!join) continue;
      const double cost = previous_links[j].cost + own + join->second;
      if (cost < links[i].cost) links[i] = {cost, j, join->first};
    }
  }
  return links;
}

// The chain ending at the last part's match `end` as one result over the whole query.
SearchResult ChainResult(const std::vector<std::vector<SearchResult>>& matches,
                         const std::vector<std::vector<Link>>& links,
                         const std::vector<Part>& parts, int end, int64_t query_rows,
                         bool with_path) {
  std::vector<int> chain(parts.size());
  for (int k = static_cast<int>(parts.size()) - 1, i = end; k >= 0; --k) {
    chain[k] = i;
    i = links[k][i].previous;
  }
  const SearchResult& first = matches.front()[chain.front()];
  const SearchResult& last = matches.back()[end];
  SearchResult result;
  result.clip_index = first.clip_index;
  result.first_frame = first.first_frame;
  result.last_frame = last.last_frame;
  result.seed_frame = first.seed_frame;
  result.score = links.back()[end].cost / static_cast<double>(query_rows);
  if (!with_path) return result;
  result.path.reserve(query_rows);
  for (size_t k = 0; k < parts.size(); ++k) {
    const SearchResult& match = matches[k][chain[k]];
    const size_t from = result.path.size();
    result.path.insert(result.path.end(), match.path.begin(), match.path.end());
    if (k == 0) continue;
    const int64_t meet = links[k][chain[k]].meet;
    if (meet < 0) continue;
    for (size_t r = 0; r < from; ++r) result.path[r] = std::min(result.path[r], meet);
    for (size_t r = from; r < result.path.size(); ++r) {
      result.path[r] = std::max(result.path[r], meet);
    }
  }
  return result;
}

void AddStageStats(const SearchStats& part, SearchStats& total) {
  total.seeds += part.seeds;
  total.clusters += part.clusters;
  total.warps += part.warps;
  total.characteristic_ms += part.characteristic_ms;
  total.seeds_ms += part.seeds_ms;
  total.clusters_ms += part.clusters_ms;
  total.warps_ms += part.warps_ms;
  total.refine_ms += part.refine_ms;
  total.ranking_ms += part.ranking_ms;
}

}  // namespace

absl::StatusOr<SearchResponse> MultiPointSearch(const LibraryIndex& library, CoordinateView query,
                                                const std::vector<int>& anchors,
                                                const SearchParams& params) {
  const auto start = std::chrono::steady_clock::now();
  const std::vector<Part> parts = QueryParts(query.rows, anchors);
  SearchParams part_params = params;
  part_params.characteristic_frames.clear();
  part_params.characteristic_points = 1;
  part_params.return_path = true;
  part_params.max_results = std::min(
      kMaxSearchResults, std::max(kMinPartMatches, kPartMatchesPerResult * params.max_results));
  SearchResponse response;
  SearchStats& stats = response.stats;
  stats.characteristic_frame = anchors.front();
  stats.characteristic_frames = anchors;

  std::vector<std::vector<SearchResult>> matches(parts.size());
  for (size_t k = 0; k < parts.size(); ++k) {
    part_params.characteristic_frame = parts[k].anchor;
    MOTIONDB_ASSIGN_OR_RETURN(
        SearchResponse part,
        Search(library, query.middle_rows(parts[k].first, parts[k].rows), part_params));
    AddStageStats(part.stats, stats);
    matches[k] = std::move(part.results);
    // A part of one frame is a pose query, whose matches are one frame with no path.
    for (SearchResult& match : matches[k]) {
      if (match.path.empty()) match.path = {match.first_frame};
    }
  }

  const auto stage = std::chrono::steady_clock::now();
  const Chaining chaining{query, library, params.dtw_dims,
                          std::llround(params.max_point_gap_s * library.rate())};
  std::vector<std::vector<Link>> links(parts.size());
  for (const SearchResult& match : matches[0]) {
    links[0].push_back({match.score * parts[0].rows, -1, -1});
  }
  for (size_t k = 1; k < parts.size(); ++k) {
    links[k] = LinkPart(chaining, parts[k - 1], matches[k - 1], links[k - 1], parts[k], matches[k]);
  }
  std::vector<SearchResult> candidates;
  for (size_t i = 0; i < matches.back().size(); ++i) {
    if (links.back()[i].cost == kInfinity) continue;
    candidates.push_back(
        ChainResult(matches, links, parts, static_cast<int>(i), query.rows, params.return_path));
  }
  response.results = FinishResults(library, std::move(candidates), params);
  stats.ranking_ms += MillisecondsSince(stage);
  stats.total_ms = MillisecondsSince(start);
  return response;
}

}  // namespace motiondb
