// A listing gathered from parts of a library (server/listing.h MergeClipPages): the whole
// library's pages, in each order, from the parts' pages of the same request; a part cut short
// bounds what is taken.
#include <gtest/gtest.h>

#include <algorithm>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include "server/listing.h"
#include "storage/database.h"

namespace motiondb::server {
namespace {

storage::ClipRecord At(int64_t id, std::string name, int64_t created) {
  storage::ClipRecord record;
  record.clip_id = id;
  record.name = std::move(name);
  record.created_unix_ms = created;
  return record;
}

// The library: 9 clips over 3 parts, names and times that order them otherwise than ids.
const std::vector<std::vector<storage::ClipRecord>>& Parts() {
  static const auto* parts = new std::vector<std::vector<storage::ClipRecord>>{
      {At(1, "walk", 30), At(4, "jump", 10), At(7, "Zed", 30)},
      {At(2, "run", 20), At(5, "walk/b", 10), At(8, "a", 40)},
      {At(3, "kick", 20), At(6, "run", 5), At(9, "é", 30)}};
  return *parts;
}

bool Before(storage::ClipOrder order, const storage::ClipRecord& a, const storage::ClipRecord& b) {
  const auto key = [&](const storage::ClipRecord& r) {
    return std::make_tuple(order == storage::ClipOrder::kName ? r.name : std::string(),
                           order == storage::ClipOrder::kCreated ? r.created_unix_ms : 0,
                           r.clip_id);
  };
  return key(a) < key(b);
}

// A part's page as a database gives it: its first `size` clips after `after`, in order; `more`
// when more follow. `cut_at` (when smaller) cuts it shorter, as an answer limit does.
PartPage PageOf(const std::vector<storage::ClipRecord>& part, storage::ClipOrder order,
                const storage::ClipRecord* after, int size, size_t cut_at = 1000) {
  std::vector<storage::ClipRecord> sorted = part;
  std::sort(sorted.begin(), sorted.end(),
            [&](const auto& a, const auto& b) { return Before(order, a, b); });
  PartPage page;
  for (const storage::ClipRecord& record : sorted) {
    if (after != nullptr && !Before(order, *after, record)) continue;
    if (static_cast<int>(page.positions.size()) == size || page.positions.size() == cut_at) {
      page.more = true;
      break;
    }
    page.positions.push_back(record);
  }
  return page;
}

// Pages through the merged listing; returns the ids in the order listed.
std::vector<int64_t> ListAll(storage::ClipOrder order, int size, size_t cut_at) {
  std::vector<int64_t> ids;
  std::optional<storage::ClipRecord> after;
  for (int pages = 0; pages < 50; ++pages) {
    std::vector<PartPage> parts;
    for (size_t p = 0; p < Parts().size(); ++p) {
      // The first part's answers are cut shorter than the page.
      parts.push_back(
          PageOf(Parts()[p], order, after ? &*after : nullptr, size, p == 0 ? cut_at : 1000));
    }
    const MergedClipPage page = MergeClipPages(order, size, parts);
    EXPECT_FALSE(page.taken.empty());
    for (const auto& [part, index] : page.taken) {
      ids.push_back(parts[part].positions[index].clip_id);
      after = parts[part].positions[index];
    }
    if (page.next_page_token.empty()) return ids;
    EXPECT_EQ(page.next_page_token, storage::ClipPageToken(order, *after));
  }
  ADD_FAILURE() << "no last page";
  return ids;
}

TEST(ListingMergeTest, PagesOfThePartsMergeIntoTheLibrarysPages) {
  for (const storage::ClipOrder order :
       {storage::ClipOrder::kId, storage::ClipOrder::kName, storage::ClipOrder::kCreated}) {
    std::vector<storage::ClipRecord> all;
    for (const auto& part : Parts()) all.insert(all.end(), part.begin(), part.end());
    std::sort(all.begin(), all.end(),
              [&](const auto& a, const auto& b) { return Before(order, a, b); });
    std::vector<int64_t> expected;
    for (const storage::ClipRecord& record : all) expected.push_back(record.clip_id);
    for (const int size : {1, 2, 4, 9, 100}) {
      EXPECT_EQ(ListAll(order, size, /*cut_at=*/1000), expected)
          << "order " << static_cast<int>(order) << ", pages of " << size;
      // A part whose answers are cut at one clip: nothing after its last is taken early.
      EXPECT_EQ(ListAll(order, size, /*cut_at=*/1), expected)
          << "order " << static_cast<int>(order) << ", pages of " << size << ", cut";
    }
  }
}

TEST(ListingMergeTest, AnEmptyLibraryHasOneEmptyPage) {
  const MergedClipPage page = MergeClipPages(storage::ClipOrder::kId, 10, {PartPage{}, {}});
  EXPECT_TRUE(page.taken.empty());
  EXPECT_TRUE(page.next_page_token.empty());
}

}  // namespace
}  // namespace motiondb::server
