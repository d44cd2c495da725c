#include "server/listing.h"

#include <algorithm>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "util/status_macros.h"

namespace motiondb::server {
namespace {

// The API's reading of a page size (server/listing.h), in storage's limits.
absl::StatusOr<int> ResolvePageSize(int requested) {
  if (requested < 0) return absl::InvalidArgumentError("page_size: must not be negative");
  return requested == 0 ? storage::kDefaultPageSize : std::min(requested, storage::kMaxPageSize);
}

// Whether `a` comes before `b` in `order`: by its sort key, then its id (as the database orders
// a listing; SQLite compares names bytewise, as std::string does).
bool ListedBefore(storage::ClipOrder order, const storage::ClipRecord& a,
                  const storage::ClipRecord& b) {
  switch (order) {
    case storage::ClipOrder::kName:
      if (a.name != b.name) return a.name < b.name;
      break;
    case storage::ClipOrder::kCreated:
      if (a.created_unix_ms != b.created_unix_ms) return a.created_unix_ms < b.created_unix_ms;
      break;
    case storage::ClipOrder::kId:
      break;
  }
  return a.clip_id < b.clip_id;
}

}  // namespace

absl::StatusOr<storage::ClipOrder> ClipOrderOf(const std::string& sort) {
  if (sort.empty() || sort == "id") return storage::ClipOrder::kId;
  if (sort == "name") return storage::ClipOrder::kName;
  if (sort == "created") return storage::ClipOrder::kCreated;
  return absl::InvalidArgumentError(
      absl::StrCat("sort: '", sort.substr(0, 40), "' is not id, name or created"));
}

MergedClipPage MergeClipPages(storage::ClipOrder order, int page_size,
                              const std::vector<PartPage>& parts) {
  std::vector<std::pair<size_t, size_t>> all;
  const storage::ClipRecord* bound = nullptr;  // the first last clip of a part with more
  bool more = false;
  for (size_t p = 0; p < parts.size(); ++p) {
    for (size_t i = 0; i < parts[p].positions.size(); ++i) all.emplace_back(p, i);
    if (!parts[p].more) continue;
    more = true;
    const storage::ClipRecord& last = parts[p].positions.back();
    if (bound == nullptr || ListedBefore(order, last, *bound)) bound = &last;
  }
  const auto at = [&](const std::pair<size_t, size_t>& item) -> const storage::ClipRecord& {
    return parts[item.first].positions[item.second];
  };
  std::sort(all.begin(), all.end(),
            [&](const auto& a, const auto& b) { return ListedBefore(order, at(a), at(b)); });
  MergedClipPage page;
  for (const auto& item : all) {
    if (static_cast<int>(page.taken.size()) == page_size) break;
    if (bound != nullptr && ListedBefore(order, *bound, at(item))) break;
    page.taken.push_back(item);
  }
  if (!page.taken.empty() && (more || page.taken.size() < all.size())) {
    page.next_page_token = storage::ClipPageToken(order, at(page.taken.back()));
  }
  return page;
}

absl::StatusOr<storage::Page> StoragePage(const PageRequest& page) {
  storage::Page stored;
  MOTIONDB_ASSIGN_OR_RETURN(stored.page_size, ResolvePageSize(page.page_size));
  stored.page_token = page.page_token;
  return stored;
}

absl::StatusOr<storage::ClipPage> ListClips(storage::Database& database,
                                            const ClipListRequest& request,
                                            const AnswerLimit& answers) {
  MOTIONDB_ASSIGN_OR_RETURN(storage::Page stored, StoragePage(request.page));
  stored.page_size =
      static_cast<int>(std::min<int64_t>(stored.page_size, answers.MostItems(ClipListItemBytes())));
  // The text's encoding is at most its length and a framing a field (counted above), but a
  // provenance's sources are encoded from its JSON, where one takes at least 42 characters
  // against at most kClipRangeBytes (43) encoded: half the rest leaves room for that.
  const int64_t rest =
      answers.max_bytes() - kAnswerFixedBytes - int64_t{stored.page_size} * ClipListItemBytes();
  storage::ClipFilter filter{.tag = request.tag,
                             .name_contains = request.name_contains,
                             .skeleton_id = request.skeleton_id,
                             .descriptor = request.descriptor,
                             .max_text_bytes = std::max<int64_t>(1, rest / 2)};
  MOTIONDB_ASSIGN_OR_RETURN(filter.order, ClipOrderOf(request.sort));
  return database.ListClips(stored, filter);
}

std::string SkeletonName(const storage::SkeletonSummary& skeleton) {
  if (skeleton.first_clip_name.empty()) return skeleton.root_joint;
  return absl::StrCat(skeleton.root_joint, " (", skeleton.first_clip_name, ")");
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
