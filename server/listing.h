// Pages of clips and of spaces, as every list call of the API pages them (SPEC §7, AIP-158
// style): page_size 0 (unset) means 100, more than 1000 is read as 1000, negative is
// INVALID_ARGUMENT; page tokens are opaque to clients and stable while items come and go.
#ifndef MOTIONDB_SERVER_LISTING_H_
#define MOTIONDB_SERVER_LISTING_H_

#include <memory>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "server/index_registry.h"
#include "storage/database.h"

namespace motiondb::server {

struct PageRequest {
  int page_size = 0;
  std::string page_token;  // empty for the first page
};

absl::StatusOr<storage::ClipPage> ListClips(storage::Database& database, const PageRequest& page,
                                            const std::string& tag);

struct SpacePage {
  std::vector<std::shared_ptr<const SpaceSnapshot>> spaces;  // in space id order
  std::string next_page_token;                               // empty on the last page
};

absl::StatusOr<SpacePage> ListSpaces(const IndexRegistry& registry, const PageRequest& page);

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_LISTING_H_
