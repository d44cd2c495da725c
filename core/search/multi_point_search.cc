#include "core/search/internal/multi_point_search.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>
#include <utility>

#include "absl/container/flat_hash_map.h"
#include "core/search/internal/pose_search.h"
#include "core/search/internal/search_query.h"
#include "core/search/internal/single_point_search.h"
#include "util/status_macros.h"

namespace motiondb {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

// Matches kept per part, per result asked (and at least kMinPartMatches): a part alone, one
// action, matches far more places than the whole query (every instance of its action in
// whatever company), and a chain needs its instance's match of every part among them.
constexpr int kPartMatchesPerResult = 10;
constexpr int kMinPartMatches = 200;

// A pose held between two actions is cut out of the parts: each part is warped through its own
// point with the search's slope limit, which cannot fit a hold of 5 s in the query onto one of
// 0.3 s in the clip (or the reverse), so a hold split between two parts made both match badly.
// The hold's rows are matched to the clip frame where the parts' matches join instead, at the
// pose distance from it. A row is held when the pose moved less than kStillShare of the query's
// mean movement a row since the previous one; a run of held rows is a hold from kMinHoldS.
constexpr double kStillShare = 0.2;
constexpr double kMinHoldS = 0.5;
// Each part keeps this much of the hold's edge, so that its warp sees the pose settle.
constexpr double kHoldEdgeS = 0.5;

// Query rows [first, first + rows), anchored at its own row `anchor`. Rows between one part's
// end and the next one's first are a hold.
struct Part {
  int first = 0;
  int rows = 0;
  int anchor = 0;
};

// Per query row from 1, whether the pose moved less than kStillShare of the mean movement.
std::vector<bool> HeldRows(CoordinateView query, int dims) {
  std::vector<float> moved(query.rows, 0.0f);
  double total = 0;
  for (int64_t r = 1; r < query.rows; ++r) {
    moved[r] = Distance(query.row(r), query.row(r - 1), dims);
    total += moved[r];
  }
  const double still = kStillShare * total / std::max<int64_t>(1, query.rows - 1);
  std::vector<bool> held(query.rows, false);
  for (int64_t r = 1; r < query.rows; ++r) held[r] = moved[r] < still;
  return held;
}

// Of the runs of held rows strictly between rows `from` and `to` that last `min_rows`, the one
// nearest the middle between them, as [first, end); empty (first == end) when there is none. The
// middle, not the longest: an action's own extreme is often held too, and cutting there would
// leave the held pose between the actions inside a part.
std::pair<int, int> MiddleHold(const std::vector<bool>& held, int from, int to, int min_rows) {
  std::pair<int, int> best{from, from};
  const double middle = 0.5 * (from + to);
  double best_distance = kInfinity;
  for (int r = from + 1; r < to;) {
    if (!held[r]) {
      ++r;
      continue;
    }
    const int first = r;
    while (r < to && held[r]) ++r;
    if (r - first < min_rows) continue;
    const double distance = first > middle ? first - middle : (r <= middle ? middle - r : 0.0);
    if (distance < best_distance) {
      best_distance = distance;
      best = {first, r};
    }
  }
  return best;
}

// The query cut between adjacent anchors: around the hold between them nearest their middle
// (MiddleHold), keeping kHoldEdgeS of it in each part; halfway when there is none.
std::vector<Part> QueryParts(CoordinateView query, const std::vector<int>& anchors, int dims,
                             double rate) {
  const std::vector<bool> held = HeldRows(query, dims);
  const int min_hold = std::max(1, static_cast<int>(std::lround(kMinHoldS * rate)));
  const int edge = static_cast<int>(std::lround(kHoldEdgeS * rate));
  std::vector<std::pair<int, int>> cuts;  // [end of part k, first of part k + 1)
  for (size_t k = 0; k + 1 < anchors.size(); ++k) {
    const auto [first, end] = MiddleHold(held, anchors[k], anchors[k + 1], min_hold);
    if (end > first) {
      const int part_end = std::min(first + edge, anchors[k + 1]);
      cuts.push_back({part_end, std::max(end - edge, part_end)});
    } else {
      const int middle = (anchors[k] + anchors[k + 1]) / 2 + 1;
      cuts.push_back({middle, middle});
    }
  }
  std::vector<Part> parts;
  for (size_t k = 0; k < anchors.size(); ++k) {
    const int first = k == 0 ? 0 : cuts[k - 1].second;
    const int end = k + 1 == anchors.size() ? static_cast<int>(query.rows) : cuts[k].first;
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
  // The clip frame the hold between parts k - 1 and k is matched to (unused without a hold).
  int64_t hold_frame = -1;
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

// The pose distance of query rows [first, end) (a hold) from clip frame `frame`.
double HoldCost(const Chaining& chaining, int clip_index, int first, int end, int64_t frame) {
  const CoordinateView clip = chaining.library.clip_coordinates(clip_index);
  double cost = 0;
  for (int r = first; r < end; ++r) {
    cost += Distance(chaining.query.row(r), clip.row(frame), chaining.dims);
  }
  return cost;
}

struct Junction {
  int64_t meet = -1;        // as Link::meet
  int64_t hold_frame = -1;  // as Link::hold_frame
  double change = 0;        // what the junction adds to the chain's cost
};

// Where adjacent parts' matches join, and the change in cost: when the later one starts after
// the earlier one ends, at most max_gap later than the hold between the parts lasts (a pause held
// longer in the clip than in the query is skipped), the hold's rows at the clip frame between
// them nearest the hold's middle row; when they overlap, a frame between their anchors where the
// path pauses instead (held longer in the query), the hold's rows there too: the cheapest of the
// later one's start, the earlier one's end and the middle between the anchors, of those that lie
// between them. nullopt: no join (a gap beyond max_gap, or the anchors out of order).
std::optional<Junction> Join(const Chaining& chaining, const SearchResult& previous,
                             const Part& previous_part, const SearchResult& next,
                             const Part& next_part) {
  const int hold_first = previous_part.first + previous_part.rows;
  const int hold_end = next_part.first;
  // gap - 1 frames skipped: a pause in the clip up to max_gap longer than the query's hold.
  const int64_t gap = next.first_frame - previous.last_frame;
  if (gap - 1 > chaining.max_gap + (hold_end - hold_first)) return std::nullopt;
  const auto hold_cost = [&](int64_t frame) {
    return HoldCost(chaining, next.clip_index, hold_first, hold_end, frame);
  };
  if (gap >= 0) {
    if (hold_first == hold_end) return Junction{};
    // The clip frame between the matches nearest the hold's middle row: the clip's own hold,
    // when it has one.
    const CoordinateView clip = chaining.library.clip_coordinates(next.clip_index);
    const float* middle = chaining.query.row((hold_first + hold_end) / 2);
    int64_t frame = previous.last_frame;
    float nearest = std::numeric_limits<float>::infinity();
    for (int64_t f = previous.last_frame; f <= next.first_frame; ++f) {
      const float distance = Distance(middle, clip.row(f), chaining.dims);
      if (distance < nearest) {
        nearest = distance;
        frame = f;
      }
    }
    return Junction{-1, frame, hold_cost(frame)};
  }
  if (previous.seed_frame > next.seed_frame) return std::nullopt;
  std::optional<Junction> best;
  for (const int64_t meet :
       {next.first_frame, previous.last_frame, (previous.seed_frame + next.seed_frame) / 2}) {
    if (meet < previous.seed_frame || meet > next.seed_frame) continue;
    const double change = ClampCost(chaining, previous, previous_part.first, false, meet) +
                          ClampCost(chaining, next, next_part.first, true, meet) + hold_cost(meet);
    if (!best || change < best->change) best = Junction{meet, meet, change};
  }
  return best;
}

// Links of part k's `matches` onto the chains of part k - 1. Counts its work in `stop`, and
// returns early once it says stop.
std::vector<Link> LinkPart(const Chaining& chaining, const Part& previous_part,
                           const std::vector<SearchResult>& previous,
                           const std::vector<Link>& previous_links, const Part& part,
                           const std::vector<SearchResult>& matches, StopPoll& stop) {
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
      // A join reads both matches' rows and the clip's frames between them (up to max_gap):
      // thousands of matches of one clip make millions of joins.
      if (stop.Done(previous_part.rows + part.rows +
                    std::max<int64_t>(0, match.first_frame - previous[j].last_frame))) {
        return links;
      }
      // No pruning on the previous chain's cost alone: a pause at the junction can lower it.
      const std::optional<Junction> join = Join(chaining, previous[j], previous_part, match, part);
      if (!join) continue;
      const double cost = previous_links[j].cost + own + join->change;
      if (cost < links[i].cost) links[i] = {cost, j, join->meet, join->hold_frame};
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
  result.clip_id = first.clip_id;
  result.first_frame = first.first_frame;
  result.last_frame = last.last_frame;
  result.seed_frame = first.seed_frame;
  result.score = links.back()[end].cost / static_cast<double>(query_rows);
  if (!with_path) return result;
  result.path.reserve(query_rows);
  for (size_t k = 0; k < parts.size(); ++k) {
    const SearchResult& match = matches[k][chain[k]];
    if (k > 0) {
      const int hold_rows = parts[k].first - (parts[k - 1].first + parts[k - 1].rows);
      result.path.insert(result.path.end(), hold_rows, links[k][chain[k]].hold_frame);
    }
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

}  // namespace

absl::StatusOr<SearchResponse> MultiPointSearch(const LibraryIndex& library, CoordinateView query,
                                                const std::vector<int>& anchors,
                                                const SearchFilter& filter,
                                                const SearchParams& params) {
  const auto start = std::chrono::steady_clock::now();
  const std::vector<Part> parts = QueryParts(query, anchors, params.dtw_dims, library.rate());
  SearchParams part_params = params;
  part_params.characteristic_frames.clear();
  part_params.characteristic_points = 1;
  // Each part is one anchor of the chain; a second anchor inside a part is not measured there.
  part_params.second_anchor_scatter = 0;
  part_params.return_path = true;
  part_params.max_results = std::min(
      kMaxSearchResults, std::max(kMinPartMatches, kPartMatchesPerResult * params.max_results));
  SearchResponse response;
  SearchStats& stats = response.stats;
  stats.characteristic_frame = anchors.front();
  stats.characteristic_frames = anchors;

  std::vector<std::vector<SearchResult>> matches(parts.size());
  for (size_t k = 0; k < parts.size(); ++k) {
    const CoordinateView part_query = query.middle_rows(parts[k].first, parts[k].rows);
    MOTIONDB_ASSIGN_OR_RETURN(
        SearchResponse part,
        part_query.rows == 1
            ? PoseSearch(library, part_query, filter, part_params)
            : SinglePointSearch(library, part_query, parts[k].anchor, filter, part_params));
    AddStageStats(part.stats, stats);
    stats.threads = part.stats.threads;
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
  StopPoll stop = SearchStop(params);
  for (size_t k = 1; k < parts.size(); ++k) {
    links[k] =
        LinkPart(chaining, parts[k - 1], matches[k - 1], links[k - 1], parts[k], matches[k], stop);
    if (stop.stopped()) return SearchStopped();
  }
  std::vector<SearchResult> candidates;
  for (size_t i = 0; i < matches.back().size(); ++i) {
    if (stop.Done(query.rows)) return SearchStopped();
    if (links.back()[i].cost == kInfinity) continue;
    candidates.push_back(
        ChainResult(matches, links, parts, static_cast<int>(i), query.rows, params.return_path));
  }
  response.results = FinishResults(library, filter, std::move(candidates), params);
  stats.ranking_ms += MillisecondsSince(stage);
  stats.total_ms = MillisecondsSince(start);
  return response;
}

}  // namespace motiondb
