// libFuzzer target: SpaceService.CreateSpace's request handling. The input is a serialised
// motiondb.v1.CreateSpaceRequest (names, skeleton, training ranges, weights JSON, presets,
// rates, dimensions); it is converted as the gRPC face converts it and, when that succeeds, the
// space is built from a small real library (TheSmallFuzzLibrary) (server::BuildSpace writes
// nothing). Nothing may crash, trip a sanitizer, or answer INTERNAL.
#include <chrono>
#include <cstddef>
#include <cstdint>

#include "motiondb/v1/space_service.pb.h"
#include "server/grpc/space_conversion.h"
#include "server/space_builder.h"
#include "tests/fuzz/fuzz_library.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace motiondb;
  fuzz::FuzzLibrary& library = fuzz::TheSmallFuzzLibrary();
  v1::CreateSpaceRequest request;
  if (!request.ParseFromArray(data, static_cast<int>(size))) return 0;
  const absl::StatusOr<server::SpaceRequest> space = server::FromProto(request);
  if (!space.ok()) {
    fuzz::CheckNotInternal(space.status(), "FromProto(CreateSpaceRequest)");
    return 0;
  }
  if (const absl::Status name = server::ValidateSpaceName(space->name); !name.ok()) {
    fuzz::CheckNotInternal(name, "ValidateSpaceName");
    return 0;
  }
  const auto stop_at = std::chrono::steady_clock::now() + std::chrono::milliseconds(500);
  const absl::StatusOr<server::BuiltSpace> built = server::BuildSpace(
      *library.database, *space, [stop_at] { return std::chrono::steady_clock::now() > stop_at; });
  fuzz::CheckNotInternal(built.status(), "BuildSpace");
  return 0;
}
