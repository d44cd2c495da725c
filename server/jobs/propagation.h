// Markup propagation (SPEC §5, thesis 7.2.3): each manual label of the chosen descriptors, on a
// clip of a space's skeleton, runs as a search in that space (its range the query, its own range
// excluded), and every result range gets the descriptor with value = the label's value x
// SimilarityFactor(score). What one propagation job computes; server/jobs/job_runner.h runs it in
// the background and stores its output.
//
// Pure functions, and RunPropagation and SpaceScoreScale, which are thread-safe as the
// SearchRunner and Database are.
#ifndef MOTIONDB_SERVER_JOBS_PROPAGATION_H_
#define MOTIONDB_SERVER_JOBS_PROPAGATION_H_

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "server/index_registry.h"
#include "server/search_runner.h"
#include "storage/database.h"

namespace motiondb::server {

// Results per query when the job's search parameters leave max_results unset (a search's default
// is 20). Measured with bench/propagation_quality (3 examples a content, bandai2-normal): clip
// coverage 0.616 at 20, 0.903 at 100, 0.905 at 300; frame accuracy on long takes 0.819 at 50,
// 0.862 at 100, 0.860 at 300.
inline constexpr int kPropagationMaxResults = 100;

// What a propagation job is asked.
struct PropagationRequest {
  std::string space;
  // Empty: every descriptor a manual label carries (FAILED_PRECONDITION when there is none).
  std::vector<std::string> descriptors;
  // Each query's parameters: params (max_results, neighbours, ..., tags: only clips carrying one
  // of them are searched), ann_dims, dtw_dims, exact. Its space, query and exclude_query are
  // the job's to set; params.clip_ids and return_path must be unset.
  SearchRequest search;
  // Set, in (0, 1]: a range is written only when each of its rivals (DropContested) has less
  // than this share of its value. Unset: every descriptor's ranges are written.
  std::optional<double> rival_share;
};

// Checks `request` and fills its descriptors when empty. NOT_FOUND for an unknown space;
// INVALID_ARGUMENT naming the field (descriptors[i]) for a descriptor no label can carry (empty,
// over storage::kMaxDescriptorBytes, not printable text) or bad search parameters;
// FAILED_PRECONDITION for no descriptors given while no manual label exists.
absl::StatusOr<PropagationRequest> ResolvePropagation(storage::Database& database,
                                                      const IndexRegistry& registry,
                                                      PropagationRequest request);

// The job row's parameters (JSON): the space, descriptors and the search parameters set.
std::string ParametersJson(const PropagationRequest& request);
// The space and descriptors of a job's parameters, for listings (empty when unreadable).
struct PropagationTarget {
  std::string space;
  std::vector<std::string> descriptors;
};
PropagationTarget TargetOf(const storage::JobRecord& job);

// The factor a result's value is scaled by: f(s) = 2^-((s / s0)^2), with s0 the space's score
// scale (SpaceScoreScale). f(0) = 1 (the pose sequence itself), f(s0) = 1/2, f(2 s0) = 1/16: it
// falls slowly over near matches and fast past the scale. A score is a mean pose distance in a
// space's own metric, which differs between spaces (their dimensions and variances), so a fixed
// s0 would mean different things in different spaces; s0 measured on the space's library makes
// f(s) = 1/2 mean "as far as a typical window's kScaleRank-th nearest range" in every space.
double SimilarityFactor(double score, double scale);

// The sample SpaceScoreScale searches: kScaleWindows windows of kScaleWindowSeconds, and the
// rank whose score is taken. s0 was first the median k-th score of the job's own searches,
// which moved with the job's max_results (its k), descriptors (which labels query) and tags
// (which clips are searched), so that one score got different values in different jobs of one
// space. bench/propagation_quality measured both on the Bandai clips
// (bench/notes/2026-12-02-propagation-quality.md, "The similarity factor's scale"): the job's own
// s0 ranged from 0.076 to 1.70 over the jobs of one space (1, its fallback, when no list came back
// full), so that the clips whose label reached 0.5 were 0.52 to 0.995 right depending on the job;
// with the space's (0.077 for every job) they were 0.99 to 1.00 right in every experiment. Which
// labels a job keeps does not depend on s0. The rank is kPropagationMaxResults, the results a job
// keeps by default; 2 s is about a labelled action's length; 32 windows are 32 searches once per
// job and library version.
inline constexpr int kScaleWindows = 32;
inline constexpr double kScaleWindowSeconds = 2.0;
inline constexpr int kScaleRank = kPropagationMaxResults;

// s0 of the space of `snapshot`: the median, over kScaleWindows windows of kScaleWindowSeconds
// placed evenly over its library (its clips in id order, a window at the middle of each equal
// share of the frames, moved back to fit in its clip), of the score of each window's
// kScaleRank-th nearest range (every clip searched, its own range excluded, the search's
// defaults otherwise). Windows whose list comes back short or with a last score of 0 are left
// out; 1 when none is left. It depends on the space and its library only, not on any job, nor
// on the `threads` the windows are searched on. `should_stop` as in SearchRunner::Run
// (CANCELLED).
absl::StatusOr<double> SpaceScoreScale(const SpaceSnapshot& snapshot, const SearchRunner& runner,
                                       int threads, const std::function<bool()>& should_stop);

// The spaces' scales, computed on a job's first use of a space and kept while the registry
// holds the same snapshot of it: an ingest, a deletion or a rebuild makes a new snapshot, and
// the next job measures the library again. Thread-safe.
class ScoreScales {
 public:
  // The scale of the space `snapshot` is, from the cache or measured now.
  absl::StatusOr<double> Get(const std::shared_ptr<const SpaceSnapshot>& snapshot,
                             const SearchRunner& runner, int threads,
                             const std::function<bool()>& should_stop);

 private:
  struct Cached {
    std::weak_ptr<const SpaceSnapshot> snapshot;
    double scale = 1;
  };
  std::mutex mutex_;
  std::map<int64_t, Cached> by_space_;  // by space id
};

// Of propagated candidates (any descriptors and clips), those to write: strongest first (then
// lowest score), a candidate is dropped when it shares more than half of the shorter range's
// frames with a kept one of its descriptor and clip, or with a `manual` label of its descriptor
// (so a long weaker range around a stronger short one, or over a manual one, is dropped too).
// Kept in that order.
std::vector<storage::LabelRecord> KeepStrongest(std::vector<storage::LabelRecord> candidates,
                                                const std::vector<storage::LabelRecord>& manual);

// Of KeepStrongest's output, the ranges each of whose rivals (the ranges of another descriptor on
// its clip sharing more than half of the shorter one's frames) has less than `share` of its
// value: where two descriptors come out nearly as strong on one range, neither is written. Kept
// in their order. Measured on bandai1 across styles (bench/notes/2026-12-07-propagation-across-
// styles.md): a clip's label is right more often where no other descriptor comes near it.
std::vector<storage::LabelRecord> DropContested(std::vector<storage::LabelRecord> kept,
                                                double share);

struct PropagationProgress {
  int64_t done = 0, total = 0;  // manual labels searched, of those to search
  int64_t queries = 0;          // searches run
  int64_t skipped = 0;          // labels whose range could not be a query (e.g. too short)
};

// Runs the propagation of a resolved `request` as job `job_id` and returns its output (labels
// and counts; output.job holds only the counts), the factor's s0 from `scales`. The labels'
// searches run on `threads` threads (util/parallel_for.h: at the caller's priority); the output
// does not depend on their number. `should_stop` is polled between queries and inside each
// search (CANCELLED); `on_progress` is called after each query, one call at a time. NOT_FOUND when
// the space was deleted while the job ran; FAILED_PRECONDITION when every label was skipped (there
// were some and none could be a query): a failed job leaves the earlier output as it was.
absl::StatusOr<storage::PropagationOutput> RunPropagation(
    storage::Database& database, const IndexRegistry& registry, const SearchRunner& runner,
    ScoreScales& scales, const PropagationRequest& request, const std::string& job_id, int threads,
    const std::function<bool()>& should_stop,
    const std::function<void(const PropagationProgress&)>& on_progress);

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_JOBS_PROPAGATION_H_
