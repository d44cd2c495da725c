// ServerInfoService's messages from the database's counts.
#ifndef MOTIONDB_SERVER_GRPC_SERVER_INFO_CONVERSION_H_
#define MOTIONDB_SERVER_GRPC_SERVER_INFO_CONVERSION_H_

#include "motiondb/v1/server_service.pb.h"
#include "storage/database.h"

namespace motiondb::server {

void ToProto(const storage::Counts& counts, v1::DatabaseCounts* out);

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_GRPC_SERVER_INFO_CONVERSION_H_
