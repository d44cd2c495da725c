// motiondb backup OUT.sqlite [--force] [--json]: a consistent copy of the server's live
// database (ServerService.CreateBackup), written to OUT.sqlite.part and renamed into place only
// when every byte has arrived, so OUT.sqlite is never a partial copy.
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iostream>

#include <nlohmann/json.hpp>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "client/commands.h"
#include "client/server_connection.h"
#include "motiondb/v1/server_service.grpc.pb.h"

namespace motiondb::cli {
namespace {

namespace fs = std::filesystem;

struct BackupFlags {
  std::string out;
  bool force = false;
};

// Receives the copy into `part`; returns its first message (size and counts).
absl::StatusOr<v1::BackupChunk> Receive(const ServerConnection& connection, const fs::path& part,
                                        bool progress_bar) {
  std::ofstream file(part, std::ios::binary | std::ios::trunc);
  if (!file) return absl::FailedPreconditionError(absl::StrCat("cannot write ", part.string()));
  v1::ServerService::Stub stub(connection.channel());
  v1::BackupChunk header, chunk;
  int64_t received = 0;
  const absl::Status status = Call(connection, [&](grpc::ClientContext* context) {
    const std::unique_ptr<grpc::ClientReader<v1::BackupChunk>> reader =
        stub.CreateBackup(context, v1::CreateBackupRequest());
    for (bool first = true; reader->Read(&chunk); first = false) {
      if (first) header = chunk;
      file.write(chunk.data().data(), static_cast<std::streamsize>(chunk.data().size()));
      received += static_cast<int64_t>(chunk.data().size());
      if (progress_bar) {
        std::cerr << absl::StrFormat("\r\033[Kbackup: %.1f of %.1f MiB", received / 1048576.0,
                                     header.total_bytes() / 1048576.0)
                  << std::flush;
      }
      if (!file) context->TryCancel();
    }
    return reader->Finish();
  });
  if (progress_bar) std::cerr << "\n";
  file.close();
  if (!file)
    return absl::ResourceExhaustedError(absl::StrCat("writing ", part.string(), " failed"));
  if (!status.ok()) return status;
  if (received != header.total_bytes()) {
    return absl::DataLossError(absl::StrFormat("the copy arrived with %d of its %d bytes", received,
                                               header.total_bytes()));
  }
  return header;
}

absl::Status Backup(const BackupFlags& flags, bool json, const ServerConnection& connection) {
  const fs::path out = flags.out;
  std::error_code error;
  if (!flags.force && fs::exists(out, error)) {
    return absl::AlreadyExistsError(
        absl::StrCat(out.string(), " exists; pass --force to overwrite it"));
  }
  const fs::path part = out.string() + ".part";
  const absl::StatusOr<v1::BackupChunk> header =
      Receive(connection, part, ::isatty(STDERR_FILENO) && !json);
  if (!header.ok()) {
    fs::remove(part, error);
    return header.status();
  }
  fs::rename(part, out, error);
  if (error) {
    return absl::FailedPreconditionError(
        absl::StrCat("cannot rename ", part.string(), " to ", out.string(), ": ", error.message()));
  }
  const v1::DatabaseCounts& c = header->counts();
  if (json) {
    std::cout << nlohmann::json{{"file", out.string()}, {"bytes", header->total_bytes()},
                                {"clips", c.clips()},   {"frames", c.frames()},
                                {"spaces", c.spaces()}, {"labels", c.labels()}}
                     .dump()
              << "\n";
  } else {
    absl::PrintF("backup: %s, %.1f MiB: %d clips (%d frames), %d spaces, %d labels\n", out.string(),
                 header->total_bytes() / 1048576.0, c.clips(), c.frames(), c.spaces(), c.labels());
  }
  return absl::OkStatus();
}

}  // namespace

void AddBackup(Commands& commands) {
  const GlobalOptions& global = commands.global();
  auto flags = std::make_shared<BackupFlags>();
  CLI::App* backup = commands.AddServer(
      commands.root(), "backup",
      "a consistent copy of the server's database, taken while it serves (start a server on "
      "the file with --db to restore it)",
      [&global, flags](const ServerConnection& connection) {
        return Backup(*flags, global.json, connection);
      });
  backup->add_option("OUT", flags->out, "the file to write (a SQLite database)")->required();
  backup->add_flag("--force", flags->force, "overwrite OUT when it exists");
}

}  // namespace motiondb::cli
