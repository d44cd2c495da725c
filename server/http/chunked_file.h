// A streamed file (server/http/api_transcoder.h's FileStream) as an HTTP response: chunked
// (Transfer-Encoding: chunked), each piece written as it arrives, so that a file of any size is
// sent while the server holds about a piece of it.
#ifndef MOTIONDB_SERVER_HTTP_CHUNKED_FILE_H_
#define MOTIONDB_SERVER_HTTP_CHUNKED_FILE_H_

#include <memory>

#include <httplib.h>

#include "server/http/api_transcoder.h"

namespace motiondb::server {

// The stream's head as the response's status and headers; a 200's file then follows in chunks
// once the handler returns. A client that is gone, or stops reading past the socket's write
// timeout, ends the response and cancels the stream's call; a call that fails part way ends the
// response without its last chunk, so that the client sees the file cut short rather than whole.
void SendChunkedFile(std::unique_ptr<FileStream> stream, httplib::Response& response);

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_HTTP_CHUNKED_FILE_H_
