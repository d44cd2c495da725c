// Pages of clips and of spaces, as every list call of the API pages them (SPEC §7, AIP-158
// style): page_size 0 (unset) means 100, more than 1000 is read as 1000, negative is
// INVALID_ARGUMENT; page tokens are opaque to clients and stable while items come and go.
#ifndef MOTIONDB_SERVER_LISTING_H_
#define MOTIONDB_SERVER_LISTING_H_

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/statusor.h"
#include "server/answer_limit.h"
#include "server/index_registry.h"
#include "storage/database.h"

namespace motiondb::server {

struct PageRequest {
  int page_size = 0;
  std::string page_token;  // empty for the first page
};

// `page` as storage::Database's listings take it: the size resolved as above.
absl::StatusOr<storage::Page> StoragePage(const PageRequest& page);

// A clip listing's page, filters and order as the API gives them: sort is "id" (or empty),
// "name" or "created"; another is INVALID_ARGUMENT naming `sort`.
struct ClipListRequest {
  PageRequest page;
  std::string tag;
  std::string name_contains;
  std::string sort;
  int64_t skeleton_id = 0;  // 0: any
  std::string descriptor;   // clips carrying a label of it; empty: any
};

// A page holds at most the clips an answer of `answers` holds: fewer than page_size when their
// text (an operator's clip's provenance holds its request) would pass it.
absl::StatusOr<storage::ClipPage> ListClips(storage::Database& database,
                                            const ClipListRequest& request,
                                            const AnswerLimit& answers);

// `sort` as the API gives it: "id" (or empty), "name" or "created"; another is INVALID_ARGUMENT
// naming `sort`.
absl::StatusOr<storage::ClipOrder> ClipOrderOf(const std::string& sort);

// A page of the same clip listing from each part of a library (a cluster's shard nodes, whose
// clips are no other's): where each clip stands (its id, name and creation time; the rest of a
// record is not read), in the listing's order, and whether the part has clips after its page.
struct PartPage {
  std::vector<storage::ClipRecord> positions;
  bool more = false;
};
// The whole library's page: which clips of the parts' pages it holds, in order, as (part, index),
// and the token of the page after it (storage::ClipPageToken: good on every part), empty on the
// last page. Up to `page_size` clips; none after the last clip of a part whose page was cut
// short (its answer limit), since that part's next clips may come before them.
struct MergedClipPage {
  std::vector<std::pair<size_t, size_t>> taken;
  std::string next_page_token;
};
MergedClipPage MergeClipPages(storage::ClipOrder order, int page_size,
                              const std::vector<PartPage>& parts);

// A skeleton's name for people: its root joint's and its first clip's, "Hips (01_01)"; the
// root's alone when it has no clip.
std::string SkeletonName(const storage::SkeletonSummary& skeleton);

struct SpacePage {
  std::vector<std::shared_ptr<const SpaceSnapshot>> spaces;  // in space id order
  std::string next_page_token;                               // empty on the last page
};

absl::StatusOr<SpacePage> ListSpaces(const IndexRegistry& registry, const PageRequest& page);

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_LISTING_H_
