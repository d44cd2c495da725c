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
//    projecting the range).
//
// usage: mirrored_search [--folder DIR] [--rounds N]
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "core/bvh/bvh_reader.h"
#include "server/catalog.h"
#include "server/index_registry.h"
#include "server/search_runner.h"
#include "storage/database.h"
#include "testing/corpus_paths.h"
#include "util/status_macros.h"

namespace motiondb {
namespace {

// "wave-left-hand" of "dataset-2_wave-left-hand_normal_012".
std::string ContentOf(const std::string& stem) {
  const size_t first = stem.find('_');
  const size_t last = stem.find("_normal_");
  if (first == std::string::npos || last == std::string::npos || last <= first) return stem;
  return stem.substr(first + 1, last - first - 1);
}

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

absl::Status Run(const std::filesystem::path& folder, int rounds) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / absl::StrCat("mirrored_search_", ::getpid());
  std::filesystem::create_directories(dir);
  MOTIONDB_ASSIGN_OR_RETURN(std::unique_ptr<storage::Database> database,
                            storage::Database::Open((dir / "bench.sqlite").string()));
  server::IndexRegistry registry;
  server::Catalog catalog(*database, registry);
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::directory_iterator(folder)) {
    if (entry.path().extension() == ".bvh") files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  std::map<int64_t, std::string> content;  // by clip id
  for (const std::filesystem::path& file : files) {
    MOTIONDB_ASSIGN_OR_RETURN(const BvhReadResult read, ReadBvhFile(file.string()));
    storage::ClipRecord record;
    record.name = file.stem().string();
    record.source_file = file.filename().string();
    MOTIONDB_ASSIGN_OR_RETURN(const server::IngestedClip stored,
                              catalog.IngestClip(record, read.clip));
    content[stored.record.clip_id] = ContentOf(record.name);
  }
  server::SpaceRequest space;
  space.name = "bandai";
  MOTIONDB_RETURN_IF_ERROR(catalog.CreateSpace(space, {}).status());
  const server::SearchRunner runner(registry, *database, {});
  absl::PrintF("%d clips of %s in one space\n", files.size(), folder.string());

  const std::map<std::string, std::string> other = {{"wave-left-hand", "wave-right-hand"},
                                                    {"wave-right-hand", "wave-left-hand"}};
  std::map<std::string, Precision> mirrored, same, plain_other;
  std::vector<double> plain_ms, mirror_ms, plain_search_ms, mirror_search_ms;
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
  absl::PrintF("%-16s %28s %26s %28s\n", "query", "mirrored hits: other hand",
               "plain hits: same hand", "plain search: other hand");
  for (const auto& [label, precision] : mirrored) {
    absl::PrintF("%-16s %20.3f (%3d) %18.3f (%3d) %20.3f (%3d)\n", label, precision.value(),
                 precision.counted, same[label].value(), same[label].counted,
                 plain_other[label].value(), plain_other[label].counted);
  }
  absl::PrintF("request ms: plain p50 %.2f p90 %.2f; mirror p50 %.2f p90 %.2f (x%.2f at p50)\n",
               Percentile(plain_ms, 0.5), Percentile(plain_ms, 0.9), Percentile(mirror_ms, 0.5),
               Percentile(mirror_ms, 0.9), Percentile(mirror_ms, 0.5) / Percentile(plain_ms, 0.5));
  absl::PrintF(
      "search proper (both halves' SearchStats::total_ms): plain p50 %.2f, mirror p50 %.2f\n",
      Percentile(plain_search_ms, 0.5), Percentile(mirror_search_ms, 0.5));
  std::filesystem::remove_all(dir);
  return absl::OkStatus();
}

}  // namespace
}  // namespace motiondb

int main(int argc, char** argv) {
  std::filesystem::path folder;
  int rounds = 3;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string flag = argv[i];
    if (flag == "--folder") {
      folder = argv[i + 1];
    } else if (flag == "--rounds") {
      rounds = std::max(1, std::atoi(argv[i + 1]));
    } else {
      std::fprintf(stderr, "usage: mirrored_search [--folder DIR] [--rounds N]\n");
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
  const absl::Status status = motiondb::Run(folder, rounds);
  if (!status.ok()) {
    std::fprintf(stderr, "%s\n", std::string(status.message()).c_str());
    return 1;
  }
  return 0;
}
