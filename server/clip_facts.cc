#include "server/clip_facts.h"

#include "util/status_macros.h"

namespace motiondb::server {

absl::StatusOr<ClipFacts> ClipFactsCache::Get(int64_t clip_id) {
  uint64_t erasures = 0;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (const auto it = facts_.find(clip_id); it != facts_.end()) return it->second;
    erasures = erasures_;
  }
  // Read outside the lock: two callers may read the same record once each, which is harmless,
  // while holding the lock would make every lookup wait for the database.
  MOTIONDB_ASSIGN_OR_RETURN(const storage::ClipRecord record, database_.GetClipRecord(clip_id));
  const ClipFacts facts = ClipFacts::Of(record);
  std::lock_guard<std::mutex> lock(mutex_);
  // A clip deleted meanwhile must not come back (SQLite may reuse its id for the next clip).
  if (erasures == erasures_) facts_[clip_id] = facts;
  return facts;
}

void ClipFactsCache::Put(int64_t clip_id, const ClipFacts& facts) {
  std::lock_guard<std::mutex> lock(mutex_);
  facts_[clip_id] = facts;
}

void ClipFactsCache::Erase(int64_t clip_id) {
  std::lock_guard<std::mutex> lock(mutex_);
  facts_.erase(clip_id);
  ++erasures_;
}

}  // namespace motiondb::server
