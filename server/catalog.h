// The database and the resident indices, kept in step. Every write (ingest, delete, space
// creation and deletion) goes through here: it is stored in one transaction first, and the
// affected indices are rebuilt aside and swapped in afterwards, so a search sees either the
// library before the write or after it, never half of it, and never waits.
//
// Writes are serialised by one mutex: an ingest must see every space of its skeleton, and a new
// space must see every clip, so they cannot interleave. Reads do not take it.
#ifndef MOTIONDB_SERVER_CATALOG_H_
#define MOTIONDB_SERVER_CATALOG_H_

#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "core/motion/clip.h"
#include "server/index_registry.h"
#include "server/space_builder.h"
#include "storage/database.h"

namespace motiondb::server {

struct IngestedClip {
  storage::ClipRecord record;       // as stored: with its id, skeleton and creation time
  std::vector<std::string> spaces;  // projected into
};

class Catalog {
 public:
  Catalog(storage::Database& database, IndexRegistry& registry)
      : database_(database), registry_(registry) {}

  // Loads every stored space and its cached projections into the registry (at start; nothing
  // is recomputed).
  absl::Status LoadIndices();

  // Stores the clip with its projection into every space of its skeleton.
  // The database assigns the clip's id, skeleton and creation time.
  absl::StatusOr<IngestedClip> IngestClip(const storage::ClipRecord& record, const Clip& clip);
  absl::Status DeleteClip(int64_t clip_id);

  // `should_stop` is polled between clips while the space is built (CANCELLED).
  absl::StatusOr<std::shared_ptr<const SpaceSnapshot>> CreateSpace(
      const SpaceRequest& request, const std::function<bool()>& should_stop);
  absl::Status DeleteSpace(const std::string& name);

 private:
  absl::StatusOr<std::shared_ptr<const SpaceSnapshot>> LoadSpace(
      const storage::SpaceRecord& record);

  storage::Database& database_;
  IndexRegistry& registry_;
  std::mutex write_mutex_;
};

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_CATALOG_H_
