// Compound queries (issue 12 item 2, thesis 7.2.3): the search through one characteristic point
// against the search through several, on libraries of "A, a held pose, B" clips beside "B then
// A", "A then C" and A alone (or, with three actions, "A then B then C" beside its
// permutations), each instance its own clip (testing/compound_clip.h), holds between the actions
// cycling over the case's list. Queries are further true-kind instances, not in the library,
// with holds of 0.3 and 1 s (and 5 s, reported apart). Each query ranks the whole library
// (max_results = its clip count; a clip's best result stands for it) with
//   one:     SearchParams::characteristic_points = 1 (the default),
//   several: characteristic_points = the case's action count (or --points; --found: 0, the
//            engine's own rule, one point per action it finds), found,
//   given:   characteristic_frames = the middle frame of each action (where a user marking the
//            actions would put them).
// Reported: precision at N (N = true instances in the library), the margin (score of the
// best-ranked other-kind clip over that of the worst-ranked true one: > 1 when every true
// instance ranks above every other clip; 0 when a true instance is not returned at all; inf
// when no clip of another kind is returned), and search latency p50 (one thread, each search
// run 5 times).
//
// Sources: synthetic (testing/synthetic_corpus.h, one action per generated clip, a fresh seed
// per instance) and real (../shared/mocap/bandai2-normal, whole takes, concatenated only within
// one skeleton: clips grouped by identical bone lengths, the largest group used).
//
// usage: compound_query_quality [--source synthetic|real]... [--case NAME]... [--instances N]
//          [--queries N] [--points K] [--seed S] [--folder DIR] [--neighbours K] [--found]
//          [--verbose]
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <map>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "bench/measure.h"
#include "core/bvh/bvh_reader.h"
#include "core/motion/resample.h"
#include "core/search/motion_search.h"
#include "core/space/search_coordinates.h"
#include "testing/compound_clip.h"
#include "testing/labelled_index.h"
#include "testing/synthetic_corpus.h"
#include "util/cli_conventions.h"
#include "util/status_macros.h"

namespace motiondb {
namespace {

using testing::GenerateSyntheticCorpus;
using testing::SyntheticAction;
using testing::SyntheticActionName;
using testing::SyntheticCorpus;
using testing::SyntheticCorpusOptions;

struct Flags {
  std::vector<std::string> sources = {"synthetic", "real"};
  std::vector<std::string> cases;  // empty: every case of the sources
  int instances = 5;
  int queries = 2;
  int points = 0;  // 0: the case's action count
  uint64_t seed = 1;
  std::string folder = (bench::MocapRoot() / "bandai2-normal").string();
  bool verbose = false;  // print every ranking
  int neighbours = 0;    // SearchParams::neighbours (0: by the library's size)
  bool found = false;    // several: characteristic_points = 0, the engine's rule (one per action)
};

// A case: its actions (A, B, C), the kinds of clip in its library (the first is the true kind,
// as indices into `actions`), the holds the library's instances cycle over.
struct Case {
  std::string name;
  std::string source;
  std::vector<std::string> actions;
  std::vector<std::vector<int>> kinds;
  std::vector<double> holds;
  std::string why;
};

const std::vector<double> kHolds = {0.3, 1.0, 2.0, 3.5, 5.0};
const std::vector<double> kLongHolds = {2.0, 3.5, 5.0, 7.0, 9.0};
const std::vector<std::vector<int>> kPairKinds = {{0, 1}, {1, 0}, {0, 2}, {0}};
const std::vector<std::vector<int>> kTripleKinds = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2},
                                                    {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};

std::vector<Case> Cases() {
  const std::vector<std::string> arms = {"right-arm-raise", "left-arm-raise", "both-arms-raise"};
  const std::vector<std::string> raises = {"raise-up-right-hand", "raise-up-left-hand",
                                           "raise-up-both-hands"};
  return {
      {"syn-AB", "synthetic", arms, kPairKinds, kHolds, "C's second arm is B's"},
      {"syn-shared",
       "synthetic",
       {"right-arm-raise", "shrug", "both-arms-raise"},
       kPairKinds,
       kHolds,
       "C shares A's raised right arm"},
      {"syn-long", "synthetic", arms, kPairKinds, kLongHolds, "holds of 2-9 s"},
      {"syn-ABC", "synthetic", arms, kTripleKinds, kHolds, "three actions, permutations"},
      {"real-AB", "real", raises, kPairKinds, kHolds, "C's raised left hand is B's"},
      {"real-wave",
       "real",
       {"raise-up-right-hand", "wave-left-hand", "wave-both-hands"},
       kPairKinds,
       kHolds,
       "B and C 6-7 s takes, A 2 s"},
      {"real-long", "real", raises, kPairKinds, kLongHolds, "holds of 2-9 s"},
      {"real-ABC", "real", raises, kTripleKinds, kHolds, "three actions, permutations"},
  };
}

// One fresh instance of an action, by name.
using InstanceSource = std::function<absl::StatusOr<Clip>(const std::string& action)>;

InstanceSource SyntheticInstances(uint64_t seed) {
  auto next_seed = std::make_shared<uint64_t>(seed * 1000003);
  return [next_seed](const std::string& action) -> absl::StatusOr<Clip> {
    SyntheticCorpusOptions options;
    options.seed = ++*next_seed;
    options.fps = 30;
    options.rest_min_s = options.rest_max_s = 0.5;
    options.threads = 1;
    for (const SyntheticAction a :
         {SyntheticAction::kRightArmRaise, SyntheticAction::kLeftArmRaise,
          SyntheticAction::kBothArmsRaise, SyntheticAction::kShrug, SyntheticAction::kSlouch}) {
      if (SyntheticActionName(a) == action) options.script = {{a, 1}};
    }
    if (options.script.size() != 1) return absl::InvalidArgumentError(action);
    MOTIONDB_ASSIGN_OR_RETURN(SyntheticCorpus corpus, GenerateSyntheticCorpus(options));
    return std::move(corpus.clips[0]);
  };
}

// The takes of the real folder, by content, of the one skeleton most of them share.
struct RealTakes {
  std::map<std::string, std::vector<Clip>> by_content;
  int groups = 0;
  int used = 0;
};

// Bone lengths of a Bandai take: the header's offsets and the first frame's position channels
// of every joint but the root and the pelvis (Bandai gives every joint position channels).
std::string SkeletonKey(const Clip& clip) {
  std::string key;
  for (const Joint& joint : clip.skeleton().joints()) {
    absl::StrAppend(&key, absl::StrFormat("%.2f,%.2f,%.2f;", joint.offset.x(), joint.offset.y(),
                                          joint.offset.z()));
  }
  for (int j = 2; j < clip.skeleton().joint_count(); ++j) {
    const int slot = clip.skeleton().position_slot(j);
    if (slot < 0) continue;
    for (int c = 0; c < 3; ++c) {
      absl::StrAppend(&key, absl::StrFormat("%.2f,", clip.positions()(0, 3 * slot + c)));
    }
  }
  return key;
}

absl::StatusOr<RealTakes> ReadRealTakes(const std::string& folder,
                                        const std::vector<std::string>& contents) {
  std::map<std::string, std::map<std::string, std::vector<Clip>>> by_key;
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::directory_iterator(folder)) files.push_back(entry);
  std::sort(files.begin(), files.end());
  for (const std::filesystem::path& path : files) {
    const std::string content = testing::ContentLabel(path);
    if (path.extension() != ".bvh" ||
        std::find(contents.begin(), contents.end(), content) == contents.end()) {
      continue;
    }
    MOTIONDB_ASSIGN_OR_RETURN(BvhReadResult read, ReadBvhFile(path.string()));
    by_key[SkeletonKey(read.clip)][content].push_back(std::move(read.clip));
  }
  RealTakes takes;
  takes.groups = static_cast<int>(by_key.size());
  size_t best = 0;
  for (auto& [key, group] : by_key) {
    size_t fewest = SIZE_MAX;
    for (const std::string& content : contents) fewest = std::min(fewest, group[content].size());
    if (fewest > best || takes.by_content.empty()) {
      best = fewest;
      takes.by_content = group;
    }
  }
  for (const auto& [content, clips] : takes.by_content) takes.used += clips.size();
  return takes;
}

InstanceSource RealInstances(const RealTakes& takes, uint64_t seed) {
  auto pools = std::make_shared<std::map<std::string, std::vector<const Clip*>>>();
  std::mt19937_64 rng(seed);
  for (const auto& [content, clips] : takes.by_content) {
    std::vector<const Clip*>& pool = (*pools)[content];
    for (const Clip& clip : clips) pool.push_back(&clip);
    std::shuffle(pool.begin(), pool.end(), rng);
  }
  return [pools](const std::string& action) -> absl::StatusOr<Clip> {
    std::vector<const Clip*>& pool = (*pools)[action];
    if (pool.empty()) return absl::ResourceExhaustedError("no takes of " + action + " left");
    const Clip* clip = pool.back();
    pool.pop_back();
    return *clip;
  };
}

// One compound clip and the frames of each of its actions, at its own rate.
struct Instance {
  Clip clip;
  std::vector<FrameRange> actions;
};

absl::StatusOr<Instance> MakeInstance(const Case& c, const std::vector<int>& kind, double hold,
                                      const InstanceSource& source) {
  MOTIONDB_ASSIGN_OR_RETURN(Clip first, source(c.actions[kind[0]]));
  Instance instance{first, {{0, first.frame_count() - 1}}};
  for (size_t k = 1; k < kind.size(); ++k) {
    MOTIONDB_ASSIGN_OR_RETURN(const Clip next, source(c.actions[kind[k]]));
    MOTIONDB_ASSIGN_OR_RETURN(testing::CompoundClip compound,
                              testing::ConcatenateWithHold(instance.clip, next, {hold, 0.25}));
    instance.clip = std::move(compound.clip);
    instance.actions.push_back(compound.second);
  }
  return instance;
}

std::string KindName(const std::vector<int>& kind) {
  std::string name;
  for (const int a : kind) name += static_cast<char>('A' + a);
  return name;
}

// The middle frame of each action, at the space rate: where a user marking the actions would put
// the points.
std::vector<int> GivenFrames(const Instance& query, int64_t rows, double rate) {
  const double scale = rate * query.clip.frame_time();
  std::vector<int> frames;
  for (const FrameRange& action : query.actions) {
    frames.push_back(static_cast<int>(
        std::clamp<int64_t>(std::lround(0.5 * (action.first + action.last) * scale), 0, rows - 1)));
  }
  return frames;
}

// Which action each point falls in ("A", "B", ...; "-" between actions).
std::string PointsInActions(const std::vector<int>& points, const Instance& query, double rate) {
  std::string where;
  const double scale = rate * query.clip.frame_time();
  for (const int p : points) {
    char c = '-';
    for (size_t a = 0; a < query.actions.size(); ++a) {
      if (p >= query.actions[a].first * scale && p <= query.actions[a].last * scale) {
        c = static_cast<char>('A' + a);
      }
    }
    where += c;
  }
  return where;
}

struct Outcome {
  double precision = 0;
  double margin = 0;
  int missing = 0;  // true instances not returned
  std::vector<double> latency_ms;
  std::vector<int> points;  // the characteristic frames the search used
};

constexpr double kInfinity = std::numeric_limits<double>::infinity();

const std::vector<std::string> kConfigs = {"one", "several", "given"};

absl::StatusOr<Outcome> RankLibrary(const LibraryIndex& library, const RowMatrixXf& query,
                                    const SearchParams& params, const std::string& true_kind,
                                    int truths, bool verbose) {
  Outcome outcome;
  absl::StatusOr<SearchResponse> response;
  for (int repeat = 0; repeat < 5; ++repeat) {
    const bench::Clock::time_point start = bench::Clock::now();
    response = Search(library, CoordinateView::Of(query), params);
    outcome.latency_ms.push_back(1e3 * bench::SecondsSince(start));
    if (!response.ok()) return response.status();
  }
  std::vector<bool> seen(library.clip_count(), false);
  int rank = 0, true_in_top = 0, true_found = 0;
  double worst_true = 0, best_false = -1;
  for (const SearchResult& r : response->results) {
    if (seen[r.clip_index]) continue;
    seen[r.clip_index] = true;
    const bool truth = r.clip_name.starts_with(true_kind + " ");
    if (rank++ < truths && truth) ++true_in_top;
    if (truth) {
      ++true_found;
      worst_true = r.score;
    } else if (best_false < 0) {
      best_false = r.score;
    }
  }
  outcome.precision = static_cast<double>(true_in_top) / truths;
  outcome.missing = truths - true_found;
  outcome.margin = outcome.missing > 0 ? 0
                   : best_false < 0    ? kInfinity  // no clip of another kind returned
                                       : best_false / worst_true;
  outcome.points = response->stats.characteristic_frames;
  if (verbose) {
    for (const SearchResult& r : response->results) {
      std::printf("    %s %.4f [%lld-%lld]\n", r.clip_name.c_str(), r.score,
                  static_cast<long long>(r.first_frame), static_cast<long long>(r.last_frame));
    }
  }
  return outcome;
}

absl::Status RunCase(const Case& c, const Flags& flags, const InstanceSource& source) {
  // The library: `instances` of every kind, holds cycling.
  std::vector<TrainingClip> training;
  for (const std::vector<int>& kind : c.kinds) {
    for (int i = 0; i < flags.instances; ++i) {
      const double hold = c.holds[i % c.holds.size()];
      MOTIONDB_ASSIGN_OR_RETURN(Instance instance, MakeInstance(c, kind, hold, source));
      training.push_back({absl::StrFormat("%s %d hold %.1f", KindName(kind), i, hold),
                          std::move(instance.clip), std::nullopt});
    }
  }
  // The queries, drawn before anything is printed (a real case may run out of takes).
  std::vector<std::pair<double, Instance>> queries;
  for (const double hold : {0.3, 1.0, 5.0}) {
    for (int i = 0; i < flags.queries; ++i) {
      MOTIONDB_ASSIGN_OR_RETURN(Instance query, MakeInstance(c, c.kinds[0], hold, source));
      queries.emplace_back(hold, std::move(query));
    }
  }
  const bench::Clock::time_point start = bench::Clock::now();
  MOTIONDB_ASSIGN_OR_RETURN(MotionSpace space, MotionSpace::Build(training, SpaceOptions{}));
  std::vector<LibraryClip> projected;
  double library_s = 0;
  for (size_t i = 0; i < training.size(); ++i) {
    MOTIONDB_ASSIGN_OR_RETURN(RowMatrixXf rows, SearchCoordinates(space, training[i].clip));
    library_s += training[i].clip.duration_s();
    projected.push_back({static_cast<int64_t>(i), training[i].source, {}, std::move(rows)});
  }
  MOTIONDB_ASSIGN_OR_RETURN(std::unique_ptr<LibraryIndex> library,
                            LibraryIndex::Build(std::move(projected), space.sample_rate(), {}));
  const int points = flags.points > 0 ? flags.points : static_cast<int>(c.kinds[0].size());
  const std::string true_kind = KindName(c.kinds[0]);
  std::vector<std::string> kinds;
  for (const auto& kind : c.kinds) kinds.push_back(KindName(kind));
  std::printf("\n### %s (%s): A = %s, B = %s, C = %s; %s\n\n", c.name.c_str(), c.source.c_str(),
              c.actions[0].c_str(), c.actions[1].c_str(), c.actions[2].c_str(), c.why.c_str());
  std::printf(
      "Library: %d clips (%d each of %s), %.0f s, library holds %s s; space and index %.1f s; "
      "several = %s. True kind %s, N = %d.\n\n",
      library->clip_count(), flags.instances, absl::StrJoin(kinds, ", ").c_str(), library_s,
      absl::StrJoin(c.holds, ", ").c_str(), bench::SecondsSince(start),
      flags.found ? "one point per action found" : absl::StrCat(points, " points").c_str(),
      true_kind.c_str(), flags.instances);
  std::printf(
      "| query | hold s | one P@N | one margin | several P@N | several margin | several points "
      "| given P@N | given margin |\n|---|---|---|---|---|---|---|---|---|\n");

  struct Summary {
    std::vector<double> precision, margin, latency;
  };
  std::map<std::pair<bool, std::string>, Summary> summary;  // (5 s hold, config)
  int q = 0;
  for (const auto& [hold, query] : queries) {
    MOTIONDB_ASSIGN_OR_RETURN(const RowMatrixXf rows, SearchCoordinates(space, query.clip));
    SearchParams params;
    params.max_results = library->clip_count();
    params.neighbours = flags.neighbours;
    std::string line = absl::StrFormat("| q%d | %.1f |", q, hold);
    for (const std::string& config : kConfigs) {
      params.characteristic_points = config != "several" ? 1 : flags.found ? 0 : points;
      params.characteristic_frames.clear();
      if (flags.verbose) std::printf("  q%d %s\n", q, config.c_str());
      if (config == "given") {
        params.characteristic_frames = GivenFrames(query, rows.rows(), space.sample_rate());
      }
      MOTIONDB_ASSIGN_OR_RETURN(
          const Outcome outcome,
          RankLibrary(*library, rows, params, true_kind, flags.instances, flags.verbose));
      Summary& s = summary[{hold > 4, config}];
      s.precision.push_back(outcome.precision);
      s.margin.push_back(outcome.margin);
      s.latency.insert(s.latency.end(), outcome.latency_ms.begin(), outcome.latency_ms.end());
      absl::StrAppend(
          &line,
          absl::StrFormat(" %.2f | %s |", outcome.precision,
                          outcome.missing > 0 ? absl::StrFormat("0 (%d missing)", outcome.missing)
                                              : absl::StrFormat("%.3f", outcome.margin)));
      if (config == "several") {
        absl::StrAppend(&line, " ", PointsInActions(outcome.points, query, space.sample_rate()),
                        " |");
      }
    }
    std::printf("%s\n", line.c_str());
    ++q;
  }
  std::printf(
      "\n| queries | config | mean P@N | min P@N | mean margin (finite) | min margin "
      "| latency p50 ms |\n"
      "|---|---|---|---|---|---|---|\n");
  for (const bool long_hold : {false, true}) {
    for (const std::string& config : kConfigs) {
      const Summary& s = summary[{long_hold, config}];
      const auto mean = [](const std::vector<double>& v) {  // of the finite values
        double sum = 0;
        int count = 0;
        for (const double x : v) {
          if (std::isfinite(x)) sum += x, ++count;
        }
        return count > 0 ? sum / count : kInfinity;
      };
      std::printf("| %s | %s | %.2f | %.2f | %.3f | %.3f | %.2f |\n",
                  long_hold ? "hold 5 s" : "holds 0.3, 1 s", config.c_str(), mean(s.precision),
                  *std::min_element(s.precision.begin(), s.precision.end()), mean(s.margin),
                  *std::min_element(s.margin.begin(), s.margin.end()),
                  bench::Percentile(s.latency, 0.5));
    }
  }
  return absl::OkStatus();
}

absl::Status Run(const Flags& flags) {
  for (const std::string& source : flags.sources) {
    std::vector<Case> cases;
    for (const Case& c : Cases()) {
      if (c.source != source) continue;
      if (!flags.cases.empty() &&
          std::find(flags.cases.begin(), flags.cases.end(), c.name) == flags.cases.end()) {
        continue;
      }
      cases.push_back(c);
    }
    if (cases.empty()) continue;
    if (source == "synthetic") {
      std::printf("\n## synthetic (testing/synthetic_corpus.h at 30 Hz, 0.5 s rest either side)\n");
      for (const Case& c : cases) {
        MOTIONDB_RETURN_IF_ERROR(RunCase(c, flags, SyntheticInstances(flags.seed)));
      }
      continue;
    }
    if (!std::filesystem::is_directory(flags.folder)) {
      std::printf("\n## real: %s is absent; nothing measured on real data\n", flags.folder.c_str());
      continue;
    }
    std::vector<std::string> contents;
    for (const Case& c : cases) contents.insert(contents.end(), c.actions.begin(), c.actions.end());
    MOTIONDB_ASSIGN_OR_RETURN(const RealTakes takes, ReadRealTakes(flags.folder, contents));
    std::printf(
        "\n## real (%s, whole takes): %d skeleton group(s) by bone lengths; the largest, %d "
        "takes of the contents used, is drawn from\n",
        flags.folder.c_str(), takes.groups, takes.used);
    for (const Case& c : cases) {
      const absl::Status status = RunCase(c, flags, RealInstances(takes, flags.seed));
      if (absl::IsResourceExhausted(status)) {
        std::printf("\n### %s: skipped, %s\n", c.name.c_str(),
                    std::string(status.message()).c_str());
        continue;
      }
      MOTIONDB_RETURN_IF_ERROR(status);
    }
  }
  return absl::OkStatus();
}

}  // namespace
}  // namespace motiondb

int main(int argc, char** argv) {
  CLI::App app("One characteristic point against several on compound queries.",
               "compound_query_quality");
  motiondb::Flags flags;
  motiondb::cli::OneOf(app.add_option("--source", flags.sources, "data sources (repeatable)"),
                       {"synthetic", "real"})
      ->capture_default_str();
  app.add_option("--case", flags.cases, "only these cases (repeatable; default all)");
  app.add_option("--instances", flags.instances, "library instances of each kind (N)")
      ->capture_default_str()
      ->check(motiondb::cli::WholeAtLeast(1));
  app.add_option("--queries", flags.queries, "queries of each hold (0.3, 1, 5 s)")
      ->capture_default_str()
      ->check(motiondb::cli::WholeAtLeast(1));
  app.add_option("--points", flags.points, "points of the several-point search (0: the actions)")
      ->capture_default_str()
      ->check(motiondb::cli::WholeAtLeast(0));
  app.add_option("--seed", flags.seed, "draws of instances and takes")->capture_default_str();
  app.add_option("--folder", flags.folder, "the real labelled folder")->capture_default_str();
  app.add_option("--neighbours", flags.neighbours, "seeds of every search (0: by library size)")
      ->capture_default_str()
      ->check(motiondb::cli::WholeAtLeast(0));
  app.add_flag("--found", flags.found,
               "several: characteristic_points = 0 (the engine finds one point per action)");
  app.add_flag("--verbose", flags.verbose, "print every ranking");
  if (const std::optional<int> exit_code = motiondb::cli::ParseCommandLine(app, argc, argv)) {
    return *exit_code;
  }
  const absl::Status status = motiondb::Run(flags);
  if (!status.ok()) {
    std::fprintf(stderr, "compound_query_quality: %s\n", std::string(status.message()).c_str());
    return 1;
  }
  return 0;
}
