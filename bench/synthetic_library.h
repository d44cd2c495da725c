// A library of synthetic capture (testing/synthetic_corpus.h) and one space over it, stored
// through the server's own library code rather than over gRPC, for the benchmarks that then
// start motiondb-server on it: they time the server on hours of capture, not the making of it.
// Benchmarks that include it link motiondb_app.
#ifndef MOTIONDB_BENCH_SYNTHETIC_LIBRARY_H_
#define MOTIONDB_BENCH_SYNTHETIC_LIBRARY_H_

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/str_cat.h"
#include "server/catalog.h"
#include "server/index_registry.h"
#include "storage/database.h"
#include "testing/synthetic_corpus.h"
#include "util/status_macros.h"

namespace motiondb::bench {

struct StoredLibrary {
  std::vector<int64_t> clip_ids;  // in the corpus's order, named synthetic_0, synthetic_1, ...
  std::vector<int> frame_counts;  // of each clip
  int64_t frames = 0;
};

// Stores `hours` of synthetic capture at `fps` (clips of at most 10 minutes) into the database
// at `db` (created when absent) and creates the space `space` over it, trained on the first clip.
inline absl::StatusOr<StoredLibrary> StoreSyntheticLibrary(const std::string& db, double hours,
                                                           double fps, const std::string& space) {
  testing::SyntheticCorpusOptions options;
  options.fps = fps;
  options.target_duration_s = hours * 3600;
  MOTIONDB_ASSIGN_OR_RETURN(testing::SyntheticCorpus generated,
                            testing::GenerateSyntheticCorpus(options));
  MOTIONDB_ASSIGN_OR_RETURN(std::unique_ptr<storage::Database> database,
                            storage::Database::Open(db));
  server::IndexRegistry registry;
  server::Catalog catalog(*database, registry);
  StoredLibrary library;
  for (size_t c = 0; c < generated.clips.size(); ++c) {
    storage::ClipRecord record;
    record.name = absl::StrCat("synthetic_", c);
    record.source_file = record.name + ".bvh";
    MOTIONDB_ASSIGN_OR_RETURN(const server::IngestedClip ingested,
                              catalog.IngestClip(record, generated.clips[c]));
    library.clip_ids.push_back(ingested.record.clip_id);
    library.frame_counts.push_back(generated.clips[c].frame_count());
    library.frames += generated.clips[c].frame_count();
  }
  server::SpaceRequest request;
  request.name = space;
  request.training = {{library.clip_ids.front(), std::nullopt, std::nullopt}};
  MOTIONDB_RETURN_IF_ERROR(catalog.CreateSpace(request, [] { return false; }).status());
  return library;
}

}  // namespace motiondb::bench

#endif  // MOTIONDB_BENCH_SYNTHETIC_LIBRARY_H_
