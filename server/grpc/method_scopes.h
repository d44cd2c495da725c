// The scope (util/token_file.h) each motiondb method needs: read for what only reads
// (search, lists, exports, curves), write for what adds or changes (ingest, labels, jobs,
// spaces, edits), admin for deletes and backups, cluster for what a router asks of a shard node
// (motiondb.shard.v1). The HTTP face asks the same table for the route's method.
#ifndef MOTIONDB_SERVER_GRPC_METHOD_SCOPES_H_
#define MOTIONDB_SERVER_GRPC_METHOD_SCOPES_H_

#include "absl/strings/string_view.h"
#include "util/token_file.h"

namespace motiondb::server {

// Whether `method` ("/pkg.Service/Method") is one of motiondb.v1's or motiondb.shard.v1's
// (a cluster's router calls those on its shard nodes), which the service-side
// check guards (server/grpc/access_control.h); gRPC's own services (health, reflection) are
// guarded by the port's credentials.
bool IsMotionDbMethod(absl::string_view method);

// The scope `method` needs; admin for a method the table does not name (a new one must be
// added to it: tests/access_control_test.cc checks that every method is).
TokenScope RequiredScope(absl::string_view method);

// Whether the table names `method` (for that test).
bool HasScopeEntry(absl::string_view method);

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_GRPC_METHOD_SCOPES_H_
