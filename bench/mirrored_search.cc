// Mirrored search on labelled real capture (issue 40, item 4), in process (server::SearchRunner
// on a temporary database, as the server runs it): every clip of a labelled folder (default
// ../shared/mocap/bandai2-normal) ingested, one space over them, then each wave-left-hand and
// wave-right-hand clip, whole, as a stored query (its own clip left out), searched plain and with
// mirror (max_results 20 each, one after the other, query by query, for --rounds rounds):
//  - precision@5 of the other hand's waves among the first five mirrored hits of the mirrored
//    search, and of the same hand's waves among its first five plain hits;
//  - the baseline: precision@5 of the other hand's waves among the plain search's first five;
//  - each search's request time (SearchOutcome::request_ms), mirror against plain, as the
//    median and p90 over every query and round, and the search proper's (SearchStats::total_ms,
//    both halves'): the rest is the query's preparation (the mirror: reading, mirroring and
//    projecting the range);
//  - beside it, the window-vector baseline (bench/window_vector_baseline.h) over the same
//    space's index, searched with the query and with its mirror (mirrored and projected as the
//    server does): the same precisions, and its search time for both.
// `--takes first-half|second-half` loads half of each content's takes (testing::Takes): the
// second half is held out from the defaults chosen since issue 39. `--space canonical-bones`
// builds the space as one over several skeletons (here over the folder's one), whose queries
// mirror their bone directions (MirrorCanonicalPoses) instead of their joints.
//
// usage: mirrored_search [--folder DIR] [--rounds N] [--takes all|first-half|second-half]
//                        [--space joint-rotations|canonical-bones]
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "bench/window_vector_baseline.h"
#include "core/space/canonical_pose.h"
#include "server/catalog.h"
#include "server/index_registry.h"
#include "server/query_mirror.h"
#include "server/search_runner.h"
#include "storage/database.h"
#include "testing/corpus_paths.h"
#include "testing/labelled_index.h"
#include "util/status_macros.h"

namespace motiondb {
namespace {

double Percentile(std::vector<double> values, double share) {
  if (values.empty()) return 0;
  std::sort(values.begin(), values.end());
  return values[std::min(values.size() - 1, static_cast<size_t>(share * values.size()))];
}

struct Precision {
  int hits = 0;
  int counted = 0;
  void Add(bool right) { hits += right ? 1 : 0, ++counted; }
  double value() const { return counted > 0 ? static_cast<double>(hits) / counted : 0; }
};

// The first five clips of a baseline search's results, each counted as `want`'s or not.
void CountFirstFive(const LibraryIndex& library, const std::vector<SearchResult>& results,
                    const std::map<int64_t, std::string>& content, const std::string& want,
                    Precision& precision) {
  for (size_t i = 0; i < std::min<size_t>(5, results.size()); ++i) {
    precision.Add(content.at(library.clip(results[i].clip_index).clip_id) == want);
  }
}

double MillisecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

absl::Status Run(const std::filesystem::path& folder, int rounds, testing::Takes takes,
                 SpaceRepresentation representation) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / absl::StrCat("mirrored_search_", ::getpid());
  std::filesystem::create_directories(dir);
  MOTIONDB_ASSIGN_OR_RETURN(std::unique_ptr<storage::Database> database,
                            storage::Database::Open((dir / "bench.sqlite").string()));
  server::IndexRegistry registry;
  server::Catalog catalog(*database, registry);
  std::vector<std::string> labels;
  MOTIONDB_ASSIGN_OR_RETURN(const std::vector<TrainingClip> files,
                            testing::ReadLabelledFolder(folder, &labels, takes));
  std::map<int64_t, std::string> content;  // by clip id
  std::map<int64_t, const Clip*> clips;    // by clip id
  for (size_t i = 0; i < files.size(); ++i) {
    storage::ClipRecord record;
    record.name = std::filesystem::path(files[i].source).stem().string();
    record.source_file = files[i].source;
    MOTIONDB_ASSIGN_OR_RETURN(const server::IngestedClip stored,
                              catalog.IngestClip(record, files[i].clip));
    content[stored.record.clip_id] = labels[i];
    clips[stored.record.clip_id] = &files[i].clip;
  }
  server::SpaceRequest space;
  space.name = "bandai";
  if (representation == SpaceRepresentation::kCanonicalBones) {
    MOTIONDB_ASSIGN_OR_RETURN(const storage::ClipRecord first,
                              database->GetClipRecord(content.begin()->first));
    space.skeleton_ids = {first.skeleton_id};
  }
  MOTIONDB_RETURN_IF_ERROR(catalog.CreateSpace(space, {}).status());
  const server::SearchRunner runner(registry, *database, {});
  const std::shared_ptr<const server::SpaceSnapshot> snapshot = registry.Find("bandai");
  const LibraryIndex& library = *snapshot->index;
  MOTIONDB_ASSIGN_OR_RETURN(const std::unique_ptr<bench::WindowVectorBaseline> baseline,
                            bench::WindowVectorBaseline::Build(library, {}));
  absl::PrintF("%d clips of %s in one space (%s); window baseline %.1f MiB\n", files.size(),
               folder.string(), SpaceRepresentationName(representation),
               baseline->memory_bytes() / 1048576.0);

  const std::map<std::string, std::string> other = {{"wave-left-hand", "wave-right-hand"},
                                                    {"wave-right-hand", "wave-left-hand"}};
  std::map<std::string, Precision> mirrored, same, plain_other, window_mirrored, window_other;
  std::vector<double> plain_ms, mirror_ms, plain_search_ms, mirror_search_ms, window_ms;
  int queries = 0;
  for (int round = 0; round < rounds; ++round) {
    for (const auto& [clip_id, label] : content) {
      if (!other.contains(label)) continue;
      queries += round == 0 ? 1 : 0;
      server::SearchRequest request;
      request.space = "bandai";
      server::ClipSelection query;
      query.clip_id = clip_id;
      request.query = query;
      request.params.max_results = 20;
      // The baseline: its index searched with the query, then with its mirror.
      const int own = library.FindClip(clip_id);
      std::vector<bool> allowed(library.clip_count(), true);
      allowed[own] = false;
      MOTIONDB_ASSIGN_OR_RETURN(
          const RowMatrixXf mirrored_rows,
          server::MirroredCoordinates(*database, *snapshot, *clips.at(clip_id)));
      const auto window_start = std::chrono::steady_clock::now();
      const std::vector<SearchResult> window_plain =
          baseline->Search(library.clip_coordinates(own), 20, allowed);
      const std::vector<SearchResult> window_mirror =
          baseline->Search(CoordinateView::Of(mirrored_rows), 20, allowed);
      window_ms.push_back(MillisecondsSince(window_start));
      if (round == 0) {
        CountFirstFive(library, window_plain, content, other.at(label), window_other[label]);
        CountFirstFive(library, window_mirror, content, other.at(label), window_mirrored[label]);
      }
      for (const bool mirror : {false, true}) {
        request.mirror = mirror;
        MOTIONDB_ASSIGN_OR_RETURN(const server::SearchOutcome found, runner.Run(request, {}));
        (mirror ? mirror_ms : plain_ms).push_back(found.request_ms);
        (mirror ? mirror_search_ms : plain_search_ms).push_back(found.stats.total_ms);
        if (round > 0) continue;
        int mirrored_seen = 0, plain_seen = 0;
        for (const server::SearchHit& hit : found.hits) {
          const std::string& found_label = content.at(hit.clip_id);
          if (!mirror && plain_seen++ < 5) plain_other[label].Add(found_label == other.at(label));
          if (mirror && hit.mirrored && mirrored_seen++ < 5) {
            mirrored[label].Add(found_label == other.at(label));
          }
          if (mirror && !hit.mirrored && plain_seen++ < 5) same[label].Add(found_label == label);
        }
      }
    }
  }
  absl::PrintF("%d queries, %d rounds\n", queries, rounds);
  absl::PrintF("%-16s %28s %26s %28s %28s %28s\n", "query", "mirrored hits: other hand",
               "plain hits: same hand", "plain search: other hand", "window, mirror: other hand",
               "window, plain: other hand");
  for (const auto& [label, precision] : mirrored) {
    absl::PrintF("%-16s %20.3f (%3d) %18.3f (%3d) %20.3f (%3d) %20.3f (%3d) %20.3f (%3d)\n", label,
                 precision.value(), precision.counted, same[label].value(), same[label].counted,
                 plain_other[label].value(), plain_other[label].counted,
                 window_mirrored[label].value(), window_mirrored[label].counted,
                 window_other[label].value(), window_other[label].counted);
  }
  absl::PrintF("request ms: plain p50 %.2f p90 %.2f; mirror p50 %.2f p90 %.2f (x%.2f at p50)\n",
               Percentile(plain_ms, 0.5), Percentile(plain_ms, 0.9), Percentile(mirror_ms, 0.5),
               Percentile(mirror_ms, 0.9), Percentile(mirror_ms, 0.5) / Percentile(plain_ms, 0.5));
  absl::PrintF(
      "search proper (both halves' SearchStats::total_ms): plain p50 %.2f, mirror p50 %.2f\n",
      Percentile(plain_search_ms, 0.5), Percentile(mirror_search_ms, 0.5));
  absl::PrintF("window baseline, query and mirror searched: p50 %.2f ms, p90 %.2f ms\n",
               Percentile(window_ms, 0.5), Percentile(window_ms, 0.9));
  std::filesystem::remove_all(dir);
  return absl::OkStatus();
}

}  // namespace
}  // namespace motiondb

int main(int argc, char** argv) {
  std::filesystem::path folder;
  int rounds = 3;
  motiondb::testing::Takes takes = motiondb::testing::Takes::kAll;
  motiondb::SpaceRepresentation representation = motiondb::SpaceRepresentation::kJointRotations;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string flag = argv[i];
    if (flag == "--folder") {
      folder = argv[i + 1];
    } else if (flag == "--rounds") {
      rounds = std::max(1, std::atoi(argv[i + 1]));
    } else if (flag == "--takes" && std::string(argv[i + 1]) == "all") {
      takes = motiondb::testing::Takes::kAll;
    } else if (flag == "--takes" && std::string(argv[i + 1]) == "first-half") {
      takes = motiondb::testing::Takes::kFirstHalf;
    } else if (flag == "--takes" && std::string(argv[i + 1]) == "second-half") {
      takes = motiondb::testing::Takes::kSecondHalf;
    } else if (flag == "--space" && motiondb::ParseSpaceRepresentation(argv[i + 1]).ok()) {
      representation = *motiondb::ParseSpaceRepresentation(argv[i + 1]);
    } else {
      std::fprintf(stderr,
                   "usage: mirrored_search [--folder DIR] [--rounds N] "
                   "[--takes all|first-half|second-half] "
                   "[--space joint-rotations|canonical-bones]\n");
      return 2;
    }
  }
  if (folder.empty()) {
    const auto mocap = motiondb::testing::MocapDir();
    if (!mocap) {
      std::fprintf(stderr, "../shared/mocap is absent: give --folder\n");
      return 2;
    }
    folder = *mocap / "bandai2-normal";
  }
  const absl::Status status = motiondb::Run(folder, rounds, takes, representation);
  if (!status.ok()) {
    std::fprintf(stderr, "%s\n", std::string(status.message()).c_str());
    return 1;
  }
  return 0;
}
