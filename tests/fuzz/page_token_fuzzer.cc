// libFuzzer target: the list calls' paging and filters (ClipService.ListClips,
// SpaceService.ListSpaces): page sizes, page tokens (opaque to clients, so anything may come
// back), tags, name filters and sort orders, on a small real library. A page that succeeds is
// followed by its next token. Nothing may crash, trip a sanitizer, or answer INTERNAL.
#include <fuzzer/FuzzedDataProvider.h>

#include <cstddef>
#include <cstdint>
#include <string>

#include "server/listing.h"
#include "tests/fuzz/fuzz_library.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace motiondb;
  fuzz::FuzzLibrary& library = fuzz::TheFuzzLibrary();
  FuzzedDataProvider input(data, size);
  server::ClipListRequest clips;
  clips.page.page_size = input.ConsumeIntegral<int>();
  clips.sort = input.ConsumeRandomLengthString(16);
  clips.tag = input.ConsumeRandomLengthString(16);
  clips.name_contains = input.ConsumeRandomLengthString(16);
  clips.skeleton_id = input.ConsumeIntegral<int64_t>();
  clips.descriptor = input.ConsumeRandomLengthString(16);
  clips.page.page_token = input.ConsumeRandomLengthString(64);
  server::PageRequest& page = clips.page;
  const bool spaces = input.ConsumeBool();
  for (int turn = 0; turn < 4; ++turn) {
    std::string next;
    if (spaces) {
      const absl::StatusOr<server::SpacePage> listed = server::ListSpaces(library.registry, page);
      fuzz::CheckNotInternal(listed.status(), "ListSpaces");
      if (!listed.ok()) break;
      next = listed->next_page_token;
    } else {
      const absl::StatusOr<storage::ClipPage> listed =
          server::ListClips(*library.database, clips, server::AnswerLimit());
      fuzz::CheckNotInternal(listed.status(), "ListClips");
      if (!listed.ok()) break;
      next = listed->next_page_token;
    }
    if (next.empty()) break;
    page.page_token = next;
  }
  return 0;
}
