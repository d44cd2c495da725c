// libFuzzer target: SearchService.Search's request handling. The input is a serialised
// motiondb.v1.SearchRequest; it is converted as the gRPC face converts it and, when that
// succeeds, run against a small real library (tests/fuzz/fuzz_library.h): every parameter and
// range, stored-clip and uploaded-BVH queries, filters. Nothing may crash, trip a sanitizer, or
// answer INTERNAL.
#include <chrono>
#include <cstddef>
#include <cstdint>

#include "motiondb/v1/search_service.pb.h"
#include "server/grpc/search_conversion.h"
#include "server/search_runner.h"
#include "tests/fuzz/fuzz_library.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace motiondb;
  fuzz::FuzzLibrary& library = fuzz::TheFuzzLibrary();
  v1::SearchRequest request;
  if (!request.ParseFromArray(data, static_cast<int>(size))) return 0;
  const absl::StatusOr<server::SearchRequest> search = server::FromProto(request);
  if (!search.ok()) {
    fuzz::CheckNotInternal(search.status(), "FromProto(SearchRequest)");
    return 0;
  }
  server::UploadLimits limits;
  limits.max_bvh_bytes = 1 << 20;
  const server::SearchRunner runner(library.registry, *library.database, limits);
  // A bound on each run, as a deadline bounds a call: large but valid parameters are slow,
  // not wrong.
  const auto stop_at = std::chrono::steady_clock::now() + std::chrono::milliseconds(200);
  const absl::StatusOr<server::SearchOutcome> outcome =
      runner.Run(*search, [stop_at] { return std::chrono::steady_clock::now() > stop_at; });
  fuzz::CheckNotInternal(outcome.status(), "SearchRunner::Run");
  return 0;
}
