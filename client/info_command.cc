// motiondb info [--json]: the server's version, contents and resident indices. Exits 0 only
// when the server answers, so it doubles as a health probe (docker/).
#include <iostream>

#include <nlohmann/json.hpp>

#include "absl/strings/str_format.h"
#include "client/commands.h"
#include "client/server_connection.h"
#include "motiondb/v1/server_service.grpc.pb.h"
#include "util/status_macros.h"

namespace motiondb::cli {
namespace {

absl::Status Info(bool json, const ServerConnection& connection) {
  MOTIONDB_ASSIGN_OR_RETURN(
      const v1::ServerInfo info,
      CallUnary(connection, &v1::ServerService::Stub::GetServerInfo, v1::GetServerInfoRequest()));
  const v1::DatabaseCounts& c = info.counts();
  if (json) {
    nlohmann::json indices = nlohmann::json::array();
    for (const v1::SpaceIndexInfo& index : info.indices()) indices.push_back(index.space());
    std::cout << nlohmann::json{{"version", info.version()},
                                {"uptime_s", info.uptime_s()},
                                {"clips", c.clips()},
                                {"frames", c.frames()},
                                {"skeletons", c.skeletons()},
                                {"spaces", c.spaces()},
                                {"projections", c.projections()},
                                {"index_bytes", info.index_bytes()},
                                {"indexed_spaces", indices},
                                {"auth_required", info.auth_required()},
                                {"tls", info.tls()}}
                     .dump()
              << "\n";
  } else {
    absl::PrintF("motiondb-server %s at %s, up %.0f s\n", info.version(), connection.address(),
                 info.uptime_s());
    absl::PrintF("  %d clips (%d frames), %d skeletons, %d spaces, %d cached projections\n",
                 c.clips(), c.frames(), c.skeletons(), c.spaces(), c.projections());
    absl::PrintF("  resident indices: %d spaces, %.1f MiB\n", info.indices_size(),
                 info.index_bytes() / 1048576.0);
  }
  return absl::OkStatus();
}

}  // namespace

void AddInfo(Commands& commands) {
  const GlobalOptions& global = commands.global();
  commands.AddServer(
      commands.root(), "info", "the server's version, contents and indices (a health probe)",
      [&global](const ServerConnection& connection) { return Info(global.json, connection); });
}

}  // namespace motiondb::cli
