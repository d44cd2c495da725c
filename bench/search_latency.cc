// Search latency (issue 4): the fast search beside the exact search on the same data in the same
// run, on synthetic libraries reproducing the thesis's validation set (6.3.1) at several
// lengths and rates, and the thesis's sweeps of sampling rate (Table 6.3), neighbours (6.4) and
// DTW dimensions (6.5). One query thread. Queries are 2.8 s windows around generated actions,
// anchored at the action's peak (the thesis's manual characteristic point).
//
// usage: search_latency [--scenario 70s120|1h30|10h30|10h120|100h30|sweeps|all] [--queries N]
//          [--exact-queries N] [--places N ...] [--neighbours N ...] [--points K ...]
//          [--second-anchor S ...] [--threads N ...]
// real10h30: real capture from ../shared/mocap grown to 10 h by perturbed copies, real queries.
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <random>
#include <string>

#include "absl/strings/str_cat.h"
#include "bench/measure.h"
#include "bench/window_vector_baseline.h"
#include "cluster/shard_map.h"
#include "core/bvh/bvh_reader.h"
#include "core/index/library_index.h"
#include "core/search/exact_search.h"
#include "core/search/merge_part_results.h"
#include "core/search/motion_search.h"
#include "core/space/search_coordinates.h"
#include "testing/perturbed_copy.h"
#include "testing/synthetic_corpus.h"
#include "util/cli_conventions.h"
#include "util/status_macros.h"

namespace motiondb {
namespace {

using bench::Clock;
using bench::MocapRoot;
using bench::Percentile;
using bench::SecondsSince;
using bench::StatusMiB;
using testing::GenerateSyntheticCorpus;
using testing::SyntheticCorpus;
using testing::SyntheticCorpusOptions;
using testing::SyntheticSegment;

struct Query {
  RowMatrixXf coordinates;
  int characteristic_frame;
};

struct Bench {
  std::unique_ptr<MotionSpace> space;
  std::unique_ptr<LibraryIndex> library;
  std::vector<Query> queries;
  double generate_s = 0, project_s = 0, build_s = 0, build_rss_mib = 0;
};

// bench.library over `clips`, timing the build and measuring the memory it takes.
absl::Status BuildIndex(std::vector<LibraryClip> clips, double rate, Bench& bench) {
  const double rss_before = StatusMiB(getpid(), "VmRSS");
  const Clock::time_point start = Clock::now();
  MOTIONDB_ASSIGN_OR_RETURN(bench.library, LibraryIndex::Build(std::move(clips), rate, {}));
  bench.build_s = SecondsSince(start);
  bench.build_rss_mib = StatusMiB(getpid(), "VmRSS") - rss_before;
  return absl::OkStatus();
}

// A synthetic library of `duration_s` at `rate` Hz (the space rate too), projected to `dims`
// dimensions (-1: all), and queries of 2.8 s around its first actions.
absl::StatusOr<Bench> Prepare(double duration_s, double rate, int dims, int query_count) {
  Bench bench;
  Clock::time_point start = Clock::now();
  SyntheticCorpusOptions options;
  options.fps = rate;
  options.target_duration_s = duration_s;
  MOTIONDB_ASSIGN_OR_RETURN(SyntheticCorpus generated, GenerateSyntheticCorpus(options));
  bench.generate_s = SecondsSince(start);

  start = Clock::now();
  // The space is trained on the first clip (up to 10 minutes), as a studio trains on a
  // representative sample rather than on everything.
  SpaceOptions space_options;
  space_options.sample_rate = rate;
  MOTIONDB_ASSIGN_OR_RETURN(
      MotionSpace space,
      MotionSpace::Build({{"synthetic", generated.clips[0], std::nullopt}}, space_options));
  bench.space = std::make_unique<MotionSpace>(std::move(space));
  std::vector<LibraryClip> clips;
  for (size_t c = 0; c < generated.clips.size(); ++c) {
    MOTIONDB_ASSIGN_OR_RETURN(RowMatrixXf coordinates,
                              SearchCoordinates(*bench.space, generated.clips[c], dims));
    clips.push_back({static_cast<int64_t>(c), "synthetic", {}, std::move(coordinates)});
  }
  // Queries: 2.8 s windows centred on the peaks of the first actions of the script.
  const int length = static_cast<int>(std::lround(2.8 * rate));
  for (const SyntheticSegment& segment : generated.segments) {
    if (static_cast<int>(bench.queries.size()) == query_count) break;
    const int centre = (segment.peak_first_frame + segment.peak_last_frame) / 2;
    const int first = std::max(0, centre - length / 2);
    const RowMatrixXf& curve = clips[segment.clip].coordinates;
    if (first + length > curve.rows()) continue;
    bench.queries.push_back({curve.middleRows(first, length), segment.peak_first_frame - first});
  }
  generated = SyntheticCorpus();  // the joint rotations are not needed any more
  bench.project_s = SecondsSince(start);
  MOTIONDB_RETURN_IF_ERROR(BuildIndex(std::move(clips), rate, bench));
  return bench;
}

// Real capture grown to `duration_s` (issue 11, item 4): every clip of the Bandai folders (one
// skeleton), then perturbed copies of them in turn (testing/perturbed_copy.h), in a space trained
// on the originals at 30 Hz. Queries: whole bandai2-normal clips, spread over its contents, with
// the characteristic frame found automatically as a user's query would have it.
absl::StatusOr<Bench> PrepareReal(double duration_s, int query_count) {
  const double rate = 30;
  Bench bench;
  Clock::time_point start = Clock::now();
  std::vector<TrainingClip> originals;
  std::vector<size_t> query_clips;
  for (const char* folder : {"bandai2-normal", "bandai1"}) {
    std::vector<std::filesystem::path> files;
    for (const auto& entry : std::filesystem::directory_iterator(MocapRoot() / folder)) {
      if (entry.path().extension() == ".bvh") files.push_back(entry.path());
    }
    std::sort(files.begin(), files.end());
    for (const std::filesystem::path& path : files) {
      MOTIONDB_ASSIGN_OR_RETURN(BvhReadResult read, ReadBvhFile(path.string()));
      originals.push_back({path.stem().string(), std::move(read.clip), std::nullopt});
    }
    if (query_clips.empty()) {
      for (int q = 0; q < query_count; ++q) query_clips.push_back(q * files.size() / query_count);
    }
  }
  bench.generate_s = SecondsSince(start);
  start = Clock::now();
  SpaceOptions space_options;
  space_options.sample_rate = rate;
  MOTIONDB_ASSIGN_OR_RETURN(MotionSpace space, MotionSpace::Build(originals, space_options));
  bench.space = std::make_unique<MotionSpace>(std::move(space));
  std::vector<LibraryClip> clips;
  int64_t frames = 0;
  std::mt19937_64 rng(11);
  for (size_t i = 0; frames < duration_s * rate; ++i) {
    const TrainingClip& original = originals[i % originals.size()];
    Clip copy = original.clip;
    if (i >= originals.size()) {
      MOTIONDB_ASSIGN_OR_RETURN(copy, testing::PerturbedCopy(original.clip, {}, rng));
    }
    MOTIONDB_ASSIGN_OR_RETURN(RowMatrixXf coordinates, SearchCoordinates(*bench.space, copy, 16));
    frames += coordinates.rows();
    clips.push_back({static_cast<int64_t>(i), original.source, {}, std::move(coordinates)});
  }
  for (size_t q : query_clips) bench.queries.push_back({clips[q].coordinates, -1});
  bench.project_s = SecondsSince(start);
  MOTIONDB_RETURN_IF_ERROR(BuildIndex(std::move(clips), rate, bench));
  return bench;
}

struct Run {
  std::vector<double> latencies;
  double seeds = 0, clusters = 0, warps = 0, results = 0;
  double seeds_ms = 0, clusters_ms = 0, warps_ms = 0, refine_ms = 0, ranking_ms = 0;
  std::vector<SearchResponse> responses;  // per query of the first pass
};

absl::StatusOr<Run> RunQueries(const Bench& bench, SearchParams params, bool exact, int count,
                               int repeat) {
  Run run;
  for (int r = 0; r < repeat; ++r) {
    for (int q = 0; q < count && q < static_cast<int>(bench.queries.size()); ++q) {
      params.characteristic_frame = bench.queries[q].characteristic_frame;
      const CoordinateView query = CoordinateView::Of(bench.queries[q].coordinates);
      MOTIONDB_ASSIGN_OR_RETURN(const SearchResponse response,
                                exact ? ExactSearch(*bench.library, query, params)
                                      : Search(*bench.library, query, params));
      const SearchStats& s = response.stats;
      run.latencies.push_back(s.total_ms);
      run.seeds += s.seeds;
      run.clusters += s.clusters;
      run.warps += s.warps;
      run.results += response.results.size();
      run.seeds_ms += s.seeds_ms;
      run.clusters_ms += s.clusters_ms;
      run.warps_ms += s.warps_ms;
      run.refine_ms += s.refine_ms;
      run.ranking_ms += s.ranking_ms;
      if (r == 0) run.responses.push_back(response);
    }
  }
  const double n = std::max<size_t>(1, run.latencies.size());
  for (double* v : {&run.seeds, &run.clusters, &run.warps, &run.results, &run.seeds_ms,
                    &run.clusters_ms, &run.warps_ms, &run.refine_ms, &run.ranking_ms}) {
    *v /= n;
  }
  return run;
}

// The share of the exact search's first ten results (over the queries both ran) that overlap
// one of the fast search's first ten by half.
double RecallAtTen(const Run& fast, const Run& exact) {
  int found = 0, total = 0;
  for (size_t q = 0; q < exact.responses.size() && q < fast.responses.size(); ++q) {
    const std::vector<SearchResult>& f = fast.responses[q].results;
    const size_t fast_top = std::min<size_t>(10, f.size());
    for (size_t i = 0; i < 10 && i < exact.responses[q].results.size(); ++i) {
      const SearchResult& e = exact.responses[q].results[i];
      ++total;
      found += std::any_of(f.begin(), f.begin() + fast_top, [&](const SearchResult& r) {
        return Overlaps(e, r, 0.5) || Overlaps(r, e, 0.5);
      });
    }
  }
  return total > 0 ? static_cast<double>(found) / total : 0.0;
}

// The fast search's variants measured beside its defaults (the flags of the same names).
struct VariantFlags {
  std::vector<int> places;
  std::vector<int> neighbours;
  std::vector<int> windows;            // seeds by window (SeedSelection::kNearestWindows)
  std::vector<double> window_epsilon;  // the default window seeds' approximate tree search
  std::vector<int> points;             // characteristic points (0: by the query's length)
  std::vector<double> second_anchor;   // SearchParams::second_anchor_scatter values
  std::vector<int> shape_clips;        // candidates from the query's shape (kShapeWindows)
  std::vector<int> threads;            // the default search on these many threads
  std::vector<int> shape_windows;      // their windows a length (empty: the default)
  std::vector<int> parts;              // the library split in these many shards (ShardOfClip)
  std::vector<int> part_seeds;         // each part also searched with these many seeds
  bool baseline = true;                // the window-vector baseline beside (issue 39)
};

// The fast search as configured by default (the thesis's seeds, refined), without
// refinement, with the --neighbours values, with the --points values, with the --second-anchor
// values, and with distinct places as seeds: 128 of them and the --places values.
std::vector<std::pair<std::string, SearchParams>> Variants(const VariantFlags& flags) {
  SearchParams unrefined;
  unrefined.refine = false;
  std::vector<std::pair<std::string, SearchParams>> variants = {{"fast", {}},
                                                                {"fast, no refinement", unrefined}};
  for (int count : flags.threads) {
    SearchParams params;
    params.threads = count;
    variants.emplace_back(absl::StrCat("fast, ", count, count == 1 ? " thread" : " threads"),
                          params);
  }
  for (int count : flags.neighbours) {
    SearchParams params;
    params.neighbours = count;
    variants.emplace_back(absl::StrCat("fast, ", count, " neighbours"), params);
  }
  for (int count : flags.windows) {
    SearchParams params;
    params.seed_selection = SeedSelection::kNearestWindows;
    params.neighbours = count;
    variants.emplace_back(
        count == 0 ? "fast, window seeds" : absl::StrCat("fast, ", count, " window seeds"), params);
  }
  for (double epsilon : flags.window_epsilon) {
    SearchParams params;
    params.seed_selection = SeedSelection::kNearestWindows;
    params.epsilon = static_cast<float>(epsilon);
    variants.emplace_back(absl::StrCat("fast, window seeds, epsilon ", epsilon), params);
  }
  for (int count : flags.points) {
    SearchParams params;
    params.characteristic_points = count;
    variants.emplace_back(absl::StrCat("fast, ", count, " characteristic points"), params);
  }
  const std::vector<int> shape_windows = flags.shape_windows.empty()
                                             ? std::vector<int>{SearchParams().shape_windows}
                                             : flags.shape_windows;
  for (int clips : flags.shape_clips) {
    for (int windows : shape_windows) {
      SearchParams params;
      params.seed_selection = SeedSelection::kShapeWindows;
      params.shape_clips = clips;
      params.shape_windows = windows;
      variants.emplace_back(
          absl::StrCat("shape candidates, ", clips, " clips, ", windows, " windows"), params);
    }
  }
  for (double scatter : flags.second_anchor) {
    SearchParams params;
    params.second_anchor_scatter = scatter;
    variants.emplace_back(absl::StrCat("fast, second_anchor_scatter ", scatter), params);
  }
  std::vector<int> places = {SearchParams().places};
  places.insert(places.end(), flags.places.begin(), flags.places.end());
  for (int count : places) {
    SearchParams params;
    params.seed_selection = SeedSelection::kDistinctPlaces;
    params.places = count;
    variants.emplace_back(absl::StrCat("fast, ", count, " distinct places"), params);
  }
  return variants;
}

// Whether two answers hold the same results in the same order: clips (by id), frames and scores.
bool SameResults(const std::vector<SearchResult>& a, const std::vector<SearchResult>& b) {
  return std::equal(a.begin(), a.end(), b.begin(), b.end(), [](const auto& x, const auto& y) {
    return x.clip_id == y.clip_id && x.first_frame == y.first_frame &&
           x.last_frame == y.last_frame && x.score == y.score;
  });
}

// The window-vector baseline over the whole library, on the fast search's queries.
absl::Status BaselineRun(const Bench& bench, const Run& exact, int count) {
  const Clock::time_point start = Clock::now();
  MOTIONDB_ASSIGN_OR_RETURN(const std::unique_ptr<bench::WindowVectorBaseline> baseline,
                            bench::WindowVectorBaseline::Build(*bench.library, {}));
  const double build_s = SecondsSince(start);
  Run run;
  for (int q = 0; q < count && q < static_cast<int>(bench.queries.size()); ++q) {
    const Clock::time_point query_start = Clock::now();
    std::vector<SearchResult> results = baseline->Search(
        CoordinateView::Of(bench.queries[q].coordinates), SearchParams().max_results, {});
    run.latencies.push_back(SecondsSince(query_start) * 1000);
    run.responses.push_back({.results = std::move(results), .stats = {}});
  }
  std::printf(
      "window baseline: build %.1f s, %.1f MiB: p50 %.3f ms  p99 %.3f ms | recall@10 vs "
      "exact %.3f\n",
      build_s, baseline->memory_bytes() / 1048576.0, Percentile(run.latencies, 0.5),
      Percentile(run.latencies, 0.99), RecallAtTen(run, exact));
  return absl::OkStatus();
}

// The library split in `count` parts by ShardOfClip, as a cluster's shards hold it, each part
// searched alone and the parts' answers merged (MergePartResults): with each part's default
// seeds and with each of `part_seeds` nearest-frame seeds a part, the latency of the slowest part
// (shards on machines of their own) and of the parts one after another (one machine), and recall
// against the whole library's exact search; then the exact search over the parts merged against
// the whole's.
absl::Status PartsRun(const Bench& bench, int count, const Run& exact, int queries,
                      const std::vector<int>& part_seeds) {
  const LibraryIndex& whole = *bench.library;
  std::vector<std::vector<LibraryClip>> clips(count);
  for (int c = 0; c < whole.clip_count(); ++c) {
    const LibraryIndex::ClipEntry& entry = whole.clip(c);
    clips[cluster::ShardOfClip(entry.clip_id, count)].push_back(
        {entry.clip_id, entry.name, entry.tags, whole.CopyClipCoordinates(c)});
  }
  std::vector<std::unique_ptr<LibraryIndex>> parts;
  for (std::vector<LibraryClip>& part : clips) {
    if (part.empty()) continue;
    MOTIONDB_ASSIGN_OR_RETURN(std::unique_ptr<LibraryIndex> index,
                              LibraryIndex::Build(std::move(part), whole.rate(), {}));
    parts.push_back(std::move(index));
  }
  const auto search_parts = [&](int q, bool exact_mode, int neighbours,
                                std::vector<double>& slowest, std::vector<double>& serial,
                                double& seeds) -> absl::StatusOr<SearchResponse> {
    SearchParams params;
    params.neighbours = neighbours;
    params.characteristic_frame = bench.queries[q].characteristic_frame;
    const CoordinateView query = CoordinateView::Of(bench.queries[q].coordinates);
    std::vector<std::vector<SearchResult>> answers;
    double max_ms = 0, sum_ms = 0;
    for (const std::unique_ptr<LibraryIndex>& part : parts) {
      MOTIONDB_ASSIGN_OR_RETURN(SearchResponse answer, exact_mode
                                                           ? ExactSearch(*part, query, params)
                                                           : Search(*part, query, params));
      max_ms = std::max(max_ms, answer.stats.total_ms);
      sum_ms += answer.stats.total_ms;
      seeds += answer.stats.seeds;
      answers.push_back(std::move(answer.results));
    }
    slowest.push_back(max_ms);
    serial.push_back(sum_ms);
    SearchResponse merged{.results = MergePartResults(std::move(answers), params.max_results),
                          .stats = {}};
    // RecallAtTen compares results by the whole library's clip indices.
    for (SearchResult& result : merged.results) result.clip_index = whole.FindClip(result.clip_id);
    return merged;
  };
  std::vector<int> budgets = {0};  // 0: the default for each part's size
  budgets.insert(budgets.end(), part_seeds.begin(), part_seeds.end());
  for (const int neighbours : budgets) {
    Run fast;
    std::vector<double> serial;
    double seeds = 0;
    for (int repeat = 0; repeat < 3; ++repeat) {
      for (int q = 0; q < queries && q < static_cast<int>(bench.queries.size()); ++q) {
        MOTIONDB_ASSIGN_OR_RETURN(
            SearchResponse merged,
            search_parts(q, false, neighbours, fast.latencies, serial, seeds));
        if (repeat == 0) fast.responses.push_back(std::move(merged));
      }
    }
    const std::string budget =
        neighbours == 0 ? "default seeds" : absl::StrCat(neighbours, " seeds a part");
    std::printf(
        "fast over %d parts (ShardOfClip), %s: p50 %.3f ms, p99 %.3f ms of the slowest part; "
        "parts one after another p50 %.3f ms | %.0f seeds | recall@10 vs exact %.3f\n",
        count, budget.c_str(), Percentile(fast.latencies, 0.5), Percentile(fast.latencies, 0.99),
        Percentile(serial, 0.5), seeds / std::max<size_t>(1, serial.size()),
        RecallAtTen(fast, exact));
    std::fflush(stdout);
  }
  bool same = true;
  std::vector<double> exact_slowest, exact_serial;
  double exact_seeds = 0;
  for (size_t q = 0; q < exact.responses.size(); ++q) {
    MOTIONDB_ASSIGN_OR_RETURN(
        const SearchResponse merged,
        search_parts(static_cast<int>(q), true, 0, exact_slowest, exact_serial, exact_seeds));
    same = same && SameResults(merged.results, exact.responses[q].results);
  }
  std::printf("exact over %d parts, merged: p50 %.1f ms of the slowest part | results %s\n", count,
              Percentile(exact_slowest, 0.5), same ? "identical" : "DIFFER");
  std::fflush(stdout);
  return absl::OkStatus();
}

absl::Status Scenario(const std::string& name, double duration_s, double rate, int queries,
                      int exact_queries, const VariantFlags& variant_flags, bool real = false) {
  MOTIONDB_ASSIGN_OR_RETURN(const Bench bench, real ? PrepareReal(duration_s, queries)
                                                    : Prepare(duration_s, rate, 16, queries));
  const LibraryIndex& library = *bench.library;
  const double indexed_mib = library.total_frames() * library.ann_dims() * 4 / 1048576.0;
  std::printf("\n## %s: %.0f s at %.0f Hz = %lld frames (%d clips), %zu queries of %lld frames\n",
              name.c_str(), duration_s, rate, static_cast<long long>(library.total_frames()),
              library.clip_count(), bench.queries.size(),
              static_cast<long long>(bench.queries[0].coordinates.rows()));
  std::printf("generate %.2f s, space+project %.2f s, index build %.3f s\n", bench.generate_s,
              bench.project_s, bench.build_s);
  std::printf(
      "memory: indexed coordinates (%d dims, float32) %.1f MiB; kd-tree %.1f MiB = "
      "%.2fx; stored coordinates (16 dims) %.1f MiB; RSS growth during build %.1f MiB\n",
      library.ann_dims(), indexed_mib, library.tree_bytes() / 1048576.0,
      library.tree_bytes() / 1048576.0 / indexed_mib, library.coordinate_bytes() / 1048576.0,
      bench.build_rss_mib);
  // The exact search on one thread, then on two, over the same queries.
  SearchParams one_thread, two_threads;
  one_thread.exact_threads = 1;
  two_threads.exact_threads = 2;
  MOTIONDB_ASSIGN_OR_RETURN(const Run exact, RunQueries(bench, one_thread, true, exact_queries, 1));
  MOTIONDB_ASSIGN_OR_RETURN(const Run exact2,
                            RunQueries(bench, two_threads, true, exact_queries, 1));
  bool same = exact.responses.size() == exact2.responses.size();
  for (size_t q = 0; same && q < exact.responses.size(); ++q) {
    same = SameResults(exact.responses[q].results, exact2.responses[q].results);
  }
  if (!variant_flags.windows.empty()) {
    // The first window search builds the window index; the variants' times are without it.
    SearchParams params;
    params.seed_selection = SeedSelection::kNearestWindows;
    const auto start = std::chrono::steady_clock::now();
    MOTIONDB_RETURN_IF_ERROR(
        Search(library, CoordinateView::Of(bench.queries[0].coordinates), params).status());
    std::printf(
        "first window search (builds the window index) %.1f ms; kd-trees and windows "
        "then %.1f MiB = %.2fx\n",
        SecondsSince(start) * 1000, library.tree_bytes() / 1048576.0,
        library.tree_bytes() / 1048576.0 / indexed_mib);
  }
  if (!variant_flags.shape_clips.empty()) {
    // The first shape search builds the shape index; the variants' times are without it.
    SearchParams params;
    params.seed_selection = SeedSelection::kShapeWindows;
    const auto start = std::chrono::steady_clock::now();
    MOTIONDB_RETURN_IF_ERROR(
        Search(library, CoordinateView::Of(bench.queries[0].coordinates), params).status());
    std::printf("first shape search (builds the shape index) %.1f ms; shape index %.1f MiB\n",
                SecondsSince(start) * 1000, library.shape_bytes() / 1048576.0);
  }
  for (const auto& [label, params] : Variants(variant_flags)) {
    MOTIONDB_ASSIGN_OR_RETURN(const Run run, RunQueries(bench, params, false, queries, 3));
    std::printf(
        "%s: p50 %.3f ms  p99 %.3f ms  | seeds %.3f clusters %.3f warps %.3f refine %.3f "
        "ranking %.3f ms | %.0f seeds, %.1f clusters, %.1f warps, %.1f results | recall@10 vs "
        "exact %.3f\n",
        label.c_str(), Percentile(run.latencies, 0.5), Percentile(run.latencies, 0.99),
        run.seeds_ms, run.clusters_ms, run.warps_ms, run.refine_ms, run.ranking_ms, run.seeds,
        run.clusters, run.warps, run.results, RecallAtTen(run, exact));
    std::fflush(stdout);
  }
  if (variant_flags.baseline) MOTIONDB_RETURN_IF_ERROR(BaselineRun(bench, exact, queries));
  for (const int count : variant_flags.parts) {
    MOTIONDB_RETURN_IF_ERROR(PartsRun(bench, count, exact, queries, variant_flags.part_seeds));
  }
  std::printf("exact, 1 thread: p50 %.1f ms  p99 %.1f ms  (%zu queries) | %.1f results\n",
              Percentile(exact.latencies, 0.5), Percentile(exact.latencies, 0.99),
              exact.latencies.size(), exact.results);
  std::printf("exact, 2 threads: p50 %.1f ms  p99 %.1f ms | %.2fx | results %s\n",
              Percentile(exact2.latencies, 0.5), Percentile(exact2.latencies, 0.99),
              Percentile(exact.latencies, 0.5) / Percentile(exact2.latencies, 0.5),
              same ? "identical" : "DIFFER");
  std::fflush(stdout);
  return absl::OkStatus();
}

absl::Status Sweeps(int queries) {
  std::printf("\n## Sweeps on 70 s of synthetic capture (thesis Tables 6.3-6.5)\n");
  std::printf("\n| rate (Hz) | results | fast p50 (ms) | exact p50 (ms) |\n|---|---|---|---|\n");
  for (double rate : {240.0, 120.0, 60.0, 30.0}) {
    MOTIONDB_ASSIGN_OR_RETURN(const Bench bench, Prepare(70, rate, 16, queries));
    MOTIONDB_ASSIGN_OR_RETURN(const Run fast, RunQueries(bench, {}, false, queries, 3));
    MOTIONDB_ASSIGN_OR_RETURN(const Run exact, RunQueries(bench, {}, true, 3, 1));
    std::printf("| %.0f | %.1f | %.3f | %.1f |\n", rate, fast.results,
                Percentile(fast.latencies, 0.5), Percentile(exact.latencies, 0.5));
  }
  MOTIONDB_ASSIGN_OR_RETURN(const Bench bench, Prepare(70, 120, -1, queries));
  std::printf(
      "\n120 Hz, %d dims:\n\n| neighbours | clusters | results | fast p50 (ms) |\n"
      "|---|---|---|---|\n",
      bench.library->dims());
  for (int k : {100, 250, 500, 1000, 1500, 2500, 5000}) {
    SearchParams params;
    params.neighbours = k;
    MOTIONDB_ASSIGN_OR_RETURN(const Run fast, RunQueries(bench, params, false, queries, 3));
    std::printf("| %d | %.1f | %.1f | %.3f |\n", k, fast.clusters, fast.results,
                Percentile(fast.latencies, 0.5));
  }
  std::printf("\n| DTW dims | results | fast p50 (ms) | exact p50 (ms) |\n|---|---|---|---|\n");
  for (int dims : {1, 3, 5, 10, 20, bench.library->dims()}) {
    SearchParams params;
    params.dtw_dims = dims;
    MOTIONDB_ASSIGN_OR_RETURN(const Run fast, RunQueries(bench, params, false, queries, 3));
    MOTIONDB_ASSIGN_OR_RETURN(const Run exact, RunQueries(bench, params, true, 3, 1));
    std::printf("| %d | %.1f | %.3f | %.1f |\n", dims, fast.results,
                Percentile(fast.latencies, 0.5), Percentile(exact.latencies, 0.5));
  }
  return absl::OkStatus();
}

absl::Status Main(const std::string& scenario, int q, int e, const VariantFlags& v) {
  const auto wants = [&](const char* name) { return scenario == "all" || scenario == name; };
  if (wants("70s120")) MOTIONDB_RETURN_IF_ERROR(Scenario("70 s at 120 Hz", 70, 120, q, e, v));
  if (wants("1h30")) MOTIONDB_RETURN_IF_ERROR(Scenario("1 h at 30 Hz", 3600, 30, q, e, v));
  if (wants("10h30")) MOTIONDB_RETURN_IF_ERROR(Scenario("10 h at 30 Hz", 36000, 30, q, e, v));
  if (wants("10h120")) MOTIONDB_RETURN_IF_ERROR(Scenario("10 h at 120 Hz", 36000, 120, q, e, v));
  // Not in "all": it needs ../shared/mocap and takes minutes.
  if (scenario == "real10h30") {
    if (!std::filesystem::is_directory(MocapRoot() / "bandai1")) {
      std::printf("search_latency: %s is absent; real10h30 not measured\n", MocapRoot().c_str());
    } else {
      MOTIONDB_RETURN_IF_ERROR(Scenario("10 h at 30 Hz of real capture and perturbed copies", 36000,
                                        30, q, e, v, /*real=*/true));
    }
  }
  // Not in "all": it takes minutes and about 3 GB.
  if (scenario == "100h30") {
    MOTIONDB_RETURN_IF_ERROR(Scenario("100 h at 30 Hz", 360000, 30, q, e, v));
  }
  if (wants("sweeps")) MOTIONDB_RETURN_IF_ERROR(Sweeps(q));
  return absl::OkStatus();
}

}  // namespace
}  // namespace motiondb

int main(int argc, char** argv) {
  CLI::App app("Search latency, index build time and memory on synthetic libraries.",
               "search_latency");
  std::string scenario = "all";
  int queries = 20, exact_queries = 5;
  motiondb::cli::OneOf(
      app.add_option("--scenario", scenario, "the library to measure, or the sweeps, or all"),
      {"70s120", "1h30", "10h30", "10h120", "100h30", "real10h30", "sweeps", "all"})
      ->capture_default_str();
  app.add_option("--queries", queries, "fast-search queries per scenario")
      ->type_name("N")
      ->capture_default_str()
      ->check(motiondb::cli::WholeAtLeast(1));
  app.add_option("--exact-queries", exact_queries, "exact-search queries per scenario")
      ->type_name("N")
      ->capture_default_str()
      ->check(motiondb::cli::WholeAtLeast(0));
  motiondb::VariantFlags variants;
  app.add_option("--places", variants.places,
                 "also measure the fast search with these numbers of places")
      ->type_name("N ...")
      ->check(motiondb::cli::WholeAtLeast(1));
  app.add_option("--neighbours", variants.neighbours,
                 "also measure the fast search with these numbers of nearest-frame seeds")
      ->type_name("N ...")
      ->check(motiondb::cli::WholeAtLeast(1));
  app.add_option("--windows", variants.windows,
                 "also measure the fast search with these numbers of window seeds (0: the "
                 "default)")
      ->type_name("N ...")
      ->check(motiondb::cli::WholeAtLeast(0));
  app.add_option("--window-epsilon", variants.window_epsilon,
                 "also measure the fast search with the default window seeds found by an "
                 "approximate tree search of these epsilons (SearchParams::epsilon)")
      ->type_name("E ...")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--shapes", variants.shape_clips,
                 "also measure the search from the query's shape with these numbers of clips "
                 "re-ranked (SearchParams::shape_clips)")
      ->type_name("N ...")
      ->check(motiondb::cli::WholeAtLeast(1));
  app.add_option("--threads", variants.threads,
                 "also measure the default search with its warps and refinement on these "
                 "numbers of threads (SearchParams::threads)")
      ->type_name("N ...")
      ->check(motiondb::cli::WholeAtLeast(1));
  app.add_option("--parts", variants.parts,
                 "also measure the library split in these many parts by ShardOfClip, as a "
                 "cluster's shards hold it, each searched alone and the answers merged")
      ->type_name("N ...")
      ->check(motiondb::cli::WholeAtLeast(2));
  app.add_option("--part-seeds", variants.part_seeds,
                 "--parts: each part also searched with these many nearest-frame seeds")
      ->type_name("N ...")
      ->check(motiondb::cli::WholeAtLeast(1));
  app.add_flag("--baseline,!--no-baseline", variants.baseline,
               "the window-vector baseline beside (on by default)")
      ->capture_default_str();
  app.add_option("--shape-windows", variants.shape_windows,
                 "--shapes: with each of these numbers of windows a length "
                 "(SearchParams::shape_windows; default: its default)")
      ->type_name("N ...")
      ->check(motiondb::cli::WholeAtLeast(1));
  app.add_option("--points", variants.points,
                 "also measure the fast search with these numbers of characteristic points (0: "
                 "one per action of the query)")
      ->type_name("K ...")
      ->check(motiondb::cli::WholeAtLeast(0));
  app.add_option("--second-anchor", variants.second_anchor,
                 "also measure the fast search with these second_anchor_scatter values (a second "
                 "anchor when the seeds fall in more clusters than this share of them; 0: never)")
      ->type_name("S ...")
      ->check(CLI::Range(0.0, 1.0));
  if (const std::optional<int> exit_code = motiondb::cli::ParseCommandLine(app, argc, argv)) {
    return *exit_code;
  }
  const absl::Status status = motiondb::Main(scenario, queries, exact_queries, variants);
  if (!status.ok()) {
    std::fprintf(stderr, "search_latency: %s\n", std::string(status.message()).c_str());
    return 1;
  }
  return 0;
}
