// libFuzzer target: IngestClipStream's reading of an upload from its messages
// (server/grpc/stream_upload.h), parsed chunk by chunk as they arrive: the input is split into
// serialised messages (the first may lack a file name or be missing altogether), chunks split
// anywhere, under small file and buffer limits. Nothing may crash, trip a sanitizer, or
// answer INTERNAL, no chunk may be counted past the limits, and the chunks parsed as they
// arrive must give exactly what the concatenated file gives parsed whole (ReadUpload).
#include <fuzzer/FuzzedDataProvider.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "absl/strings/match.h"
#include "server/grpc/stream_upload.h"
#include "tests/fuzz/fuzz_library.h"

namespace {

using motiondb::v1::IngestClipStreamRequest;

struct Messages {
  std::vector<IngestClipStreamRequest> list;
  size_t next = 0;
  bool Read(IngestClipStreamRequest* message) {
    if (next == list.size()) return false;
    *message = list[next++];
    return true;
  }
};

struct NoWatch {
  void Touch(size_t) {}
  absl::Status Status() const { return absl::OkStatus(); }
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace motiondb;
  FuzzedDataProvider input(data, size);
  server::UploadLimits limits;
  limits.max_bvh_bytes = input.ConsumeIntegralInRange<int64_t>(1, 1 << 16);
  limits.max_buffered_bytes = input.ConsumeIntegralInRange<int64_t>(1, 1 << 16);
  Messages messages;
  while (input.remaining_bytes() > 0 && messages.list.size() < 64) {
    IngestClipStreamRequest message;
    if (input.ConsumeBool()) {
      // Raw bytes: whatever a client's serialiser might send.
      const std::string bytes = input.ConsumeRandomLengthString(4096);
      if (!message.ParseFromString(bytes)) continue;
    } else {
      if (messages.list.empty()) message.set_file_name(input.ConsumeRandomLengthString(32));
      message.set_chunk(input.ConsumeRandomLengthString(8192));
    }
    messages.list.push_back(std::move(message));
  }
  server::UploadBudget budget(limits);
  absl::StatusOr<server::UploadBudget::Ticket> ticket = budget.Admit();
  if (!ticket.ok()) std::abort();
  NoWatch watch;
  absl::StatusOr<server::ReceivedUpload> upload =
      server::ReceiveUpload(messages, watch, limits, *ticket);
  if (budget.buffered_bytes() > limits.max_buffered_bytes) {
    std::fprintf(stderr, "the budget counted %lld bytes over its limit %lld\n",
                 static_cast<long long>(budget.buffered_bytes()),
                 static_cast<long long>(limits.max_buffered_bytes));
    std::abort();
  }
  std::string whole;
  for (const IngestClipStreamRequest& message : messages.list) whole += message.chunk();
  if (!upload.ok()) {
    fuzz::CheckNotInternal(upload.status(), "ReceiveUpload");
    // A parse error met while the chunks arrived must be the whole file's error.
    const std::string name = messages.list.empty() ? "" : messages.list[0].file_name();
    const bool parse_error = !name.empty() &&
                             absl::StartsWith(upload.status().message(), name + ": ") &&
                             static_cast<int64_t>(whole.size()) <= limits.max_bvh_bytes;
    if (parse_error && server::ReadUpload(whole, name, limits).status() != upload.status()) {
      std::fprintf(stderr, "streamed: %s\nwhole: %s\n", upload.status().ToString().c_str(),
                   server::ReadUpload(whole, name, limits).status().ToString().c_str());
      std::abort();
    }
    return 0;
  }
  if (static_cast<int64_t>(whole.size()) > limits.max_bvh_bytes) std::abort();
  // FBX and glTF files are read whole in a child process, on the stream's end as on a unary
  // upload; this target is about BVH read as it arrives.
  if (server::UploadFormat(whole) != MotionFileFormat::kBvh) return 0;
  const absl::StatusOr<server::UploadedFile> streamed = upload->bvh.Finish();
  const absl::StatusOr<server::UploadedFile> read =
      server::ReadUpload(whole, upload->request.file_name, limits);
  fuzz::CheckNotInternal(read.status(), "ReadUpload");
  const bool same =
      streamed.status() == read.status() &&
      (!read.ok() || (streamed->takes[0].clip.rotations() == read->takes[0].clip.rotations() &&
                      streamed->takes[0].clip.positions() == read->takes[0].clip.positions() &&
                      streamed->warnings == read->warnings));
  if (!same) {
    std::fprintf(stderr, "streamed: %s\nwhole: %s\n", streamed.status().ToString().c_str(),
                 read.status().ToString().c_str());
    std::abort();
  }
  return 0;
}
