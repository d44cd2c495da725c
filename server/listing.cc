#include "server/listing.h"

#include <algorithm>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "util/status_macros.h"

namespace motiondb::server {
namespace {

constexpr int kDefaultPageSize = 100;
constexpr int kMaxPageSize = 1000;

absl::StatusOr<int> ResolvePageSize(int requested) {
  if (requested < 0) return absl::InvalidArgumentError("page_size: must not be negative");
  return requested == 0 ? kDefaultPageSize : std::min(requested, kMaxPageSize);
}

}  // namespace

absl::StatusOr<storage::ClipPage> ListClips(storage::Database& database, const PageRequest& page,
                                            const std::string& tag) {
  storage::Page stored;
  MOTIONDB_ASSIGN_OR_RETURN(stored.page_size, ResolvePageSize(page.page_size));
  stored.page_token = page.page_token;
  return database.ListClips(stored, tag);
}

absl::StatusOr<SpacePage> ListSpaces(const IndexRegistry& registry, const PageRequest& page) {
  MOTIONDB_ASSIGN_OR_RETURN(const int page_size, ResolvePageSize(page.page_size));
  // The token is the last space id of the previous page: stable while spaces come and go.
  int64_t after = 0;
  if (!page.page_token.empty() && !absl::SimpleAtoi(page.page_token, &after)) {
    return absl::InvalidArgumentError(
        absl::StrCat("page_token: '", page.page_token, "' is not a token this server gave"));
  }
  SpacePage listed;
  for (std::shared_ptr<const SpaceSnapshot>& snapshot : registry.All()) {
    if (snapshot->record.space_id <= after) continue;
    if (static_cast<int>(listed.spaces.size()) == page_size) {
      listed.next_page_token = absl::StrCat(after);
      break;
    }
    after = snapshot->record.space_id;
    listed.spaces.push_back(std::move(snapshot));
  }
  return listed;
}

}  // namespace motiondb::server
