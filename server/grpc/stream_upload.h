// The messages of an IngestClipStream read into the upload they carry: the first names the
// file (checked before more is read), and every message may carry a chunk, counted against the
// file's limit and the budget of all uploads and parsed as it arrives (StreamedUpload), so a
// malformed file is refused at the chunk that shows it.
//
// `Reader`: anything with bool Read(v1::IngestClipStreamRequest*) (grpc::ServerReader, or a
// fuzzer's messages). `Activity`: Touch(bytes) as each message arrives and Status() once reading
// stops (StreamWatchdog::Watch, whose status says when the watchdog ended the stream).
#ifndef MOTIONDB_SERVER_GRPC_STREAM_UPLOAD_H_
#define MOTIONDB_SERVER_GRPC_STREAM_UPLOAD_H_

#include <cstdint>
#include <string>
#include <utility>

#include "absl/status/statusor.h"
#include "motiondb/v1/clip_service.pb.h"
#include "server/clip_ingest.h"
#include "server/grpc/clip_conversion.h"
#include "server/upload/streamed_upload.h"
#include "server/upload/upload.h"
#include "server/upload/upload_budget.h"
#include "util/status_macros.h"

namespace motiondb::server {

struct ReceivedUpload {
  IngestRequest request;
  StreamedUpload bvh;  // every chunk appended, not finished: the caller checks the call first
};

template <typename Reader, typename Activity>
absl::StatusOr<ReceivedUpload> ReceiveUpload(Reader& reader, Activity& activity,
                                             const UploadLimits& limits,
                                             UploadBudget::Ticket& ticket) {
  v1::IngestClipStreamRequest message;
  if (!reader.Read(&message)) {
    MOTIONDB_RETURN_IF_ERROR(activity.Status());
    return absl::InvalidArgumentError("the stream is empty: the first message needs file_name");
  }
  MOTIONDB_ASSIGN_OR_RETURN(IngestRequest request, FromProto(message));
  // Refused before the upload is read: a stream without a file name would be read in vain.
  MOTIONDB_RETURN_IF_ERROR(ClipName(request).status());
  StreamedUpload bvh(request.file_name, limits);
  ReceivedUpload upload{std::move(request), std::move(bvh)};
  do {
    activity.Touch(message.chunk().size());
    MOTIONDB_RETURN_IF_ERROR(upload.bvh.Append(message.chunk(), ticket));
  } while (reader.Read(&message));
  MOTIONDB_RETURN_IF_ERROR(activity.Status());
  return upload;
}

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_GRPC_STREAM_UPLOAD_H_
