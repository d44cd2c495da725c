#include "server/http/chunked_file.h"

#include <string>
#include <utility>

namespace motiondb::server {

void SendChunkedFile(std::unique_ptr<FileStream> stream, httplib::Response& response) {
  const HttpReply& head = stream->head();
  response.status = head.status;
  for (const auto& [name, value] : head.headers) response.set_header(name, value);
  if (head.status != 200) {
    response.set_content(head.body, head.content_type);
    return;
  }
  // Shared by the provider and the releaser, which httplib keeps until the response is done;
  // the releaser drops the stream (cancelling a call not read to its end) as soon as it is.
  auto shared = std::make_shared<std::unique_ptr<FileStream>>(std::move(stream));
  const std::string content_type = head.content_type;
  response.set_chunked_content_provider(
      content_type,
      [shared](size_t /*offset*/, httplib::DataSink& sink) {
        FileStream& file = **shared;
        if (!sink.is_writable()) return false;
        std::string piece;
        if (file.Next(&piece)) return sink.write(piece.data(), piece.size());
        if (!file.ok()) return false;
        sink.done();
        return true;
      },
      [shared](bool /*success*/) { shared->reset(); });
}

}  // namespace motiondb::server
