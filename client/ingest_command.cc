// motiondb ingest PATH... [--tag T]... [--recursive] [--json]
// Uploads BVH files, or the .bvh files of folders, to the server. Each file's error is listed
// while the others continue; the exit code is 1 if any failed.
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <iostream>
#include <memory>

#include <nlohmann/json.hpp>

#include "absl/strings/str_format.h"
#include "client/commands.h"
#include "client/server_connection.h"
#include "motiondb/v1/clip_service.grpc.pb.h"
#include "util/file_io.h"

namespace motiondb::cli {
namespace {

namespace fs = std::filesystem;

// Files larger than this are streamed in chunks of this size.
constexpr size_t kChunkBytes = 1 << 20;
// Larger than any BVH file a studio will have; the server has its own limit.
constexpr int64_t kMaxFileBytes = int64_t{4} << 30;

bool IsBvh(const fs::path& path) {
  std::string extension = path.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(), ::tolower);
  return extension == ".bvh";
}

// The files named, and the .bvh files of the folders named (their subfolders too with
// `recursive`), sorted within each folder. Paths that do not exist are kept, to fail later.
std::vector<fs::path> ExpandPaths(const std::vector<std::string>& paths, bool recursive) {
  std::vector<fs::path> files;
  for (const std::string& name : paths) {
    std::error_code error;
    if (!fs::is_directory(name, error)) {
      files.emplace_back(name);
      continue;
    }
    std::vector<fs::path> found;
    const auto add = [&](const fs::directory_entry& entry) {
      if (entry.is_regular_file() && IsBvh(entry.path())) found.push_back(entry.path());
    };
    if (recursive) {
      for (const auto& entry : fs::recursive_directory_iterator(name, error)) add(entry);
    } else {
      for (const auto& entry : fs::directory_iterator(name, error)) add(entry);
    }
    std::sort(found.begin(), found.end());
    files.insert(files.end(), found.begin(), found.end());
  }
  return files;
}

grpc::Status Upload(const ServerConnection& connection, v1::ClipService::Stub& stub,
                    const fs::path& path, const std::string& bytes,
                    const std::vector<std::string>& tags, v1::IngestClipResponse* response) {
  const std::unique_ptr<grpc::ClientContext> context = connection.NewContext();
  if (bytes.size() <= kChunkBytes) {
    v1::IngestClipRequest request;
    request.set_file_name(path.filename().string());
    request.set_bvh(bytes);
    for (const std::string& tag : tags) request.add_tags(tag);
    return stub.IngestClip(context.get(), request, response);
  }
  std::unique_ptr<grpc::ClientWriter<v1::IngestClipStreamRequest>> writer =
      stub.IngestClipStream(context.get(), response);
  v1::IngestClipStreamRequest header;
  header.set_file_name(path.filename().string());
  for (const std::string& tag : tags) header.add_tags(tag);
  bool open = writer->Write(header);
  for (size_t at = 0; open && at < bytes.size(); at += kChunkBytes) {
    v1::IngestClipStreamRequest chunk;
    chunk.set_chunk(bytes.substr(at, kChunkBytes));
    open = writer->Write(chunk);
  }
  writer->WritesDone();
  return writer->Finish();
}

struct IngestFlags {
  std::vector<std::string> paths;
  std::vector<std::string> tags;
  bool recursive = false;
};

absl::Status Ingest(const IngestFlags& flags, bool json, const ServerConnection& connection) {
  const std::unique_ptr<v1::ClipService::Stub> stub =
      v1::ClipService::NewStub(connection.channel());
  const std::vector<fs::path> files = ExpandPaths(flags.paths, flags.recursive);
  const bool progress_bar = ::isatty(STDERR_FILENO) && !json;
  nlohmann::json ingested = nlohmann::json::array(), failed = nlohmann::json::array();
  for (size_t i = 0; i < files.size(); ++i) {
    const fs::path& path = files[i];
    std::string error;
    v1::IngestClipResponse response;
    if (absl::StatusOr<std::string> bytes = ReadFileBytes(path.string(), kMaxFileBytes);
        !bytes.ok()) {
      error = std::string(bytes.status().message());
    } else if (const grpc::Status status =
                   Upload(connection, *stub, path, *bytes, flags.tags, &response);
               !status.ok()) {
      error = DescribeError(status, connection.address());
    }
    if (progress_bar) std::cerr << "\r\033[K";
    if (!error.empty()) {
      std::cerr << "motiondb ingest: " << path.string() << ": " << error << "\n";
      failed.push_back({{"file", path.string()}, {"error", error}});
    } else {
      const v1::Clip& clip = response.clip();
      ingested.push_back({{"file", path.string()},
                          {"clip_id", clip.clip_id()},
                          {"name", clip.name()},
                          {"frames", clip.frame_count()},
                          {"fps", clip.fps()},
                          {"warnings", std::vector<std::string>(response.warnings().begin(),
                                                                response.warnings().end())}});
      for (const std::string& warning : response.warnings()) {
        std::cerr << "motiondb ingest: " << path.string() << ": warning: " << warning << "\n";
      }
    }
    if (progress_bar) {
      const int width = 30, done = static_cast<int>(width * (i + 1) / files.size());
      std::cerr << absl::StrFormat("[%s%s] %zu/%zu %s", std::string(done, '#'),
                                   std::string(width - done, ' '), i + 1, files.size(),
                                   path.filename().string())
                << std::flush;
    } else if (!json && error.empty()) {
      std::cout << absl::StrFormat("[%zu/%zu] %s -> clip %d (%d frames)\n", i + 1, files.size(),
                                   path.string(), response.clip().clip_id(),
                                   response.clip().frame_count());
    }
  }
  if (progress_bar) std::cerr << "\n";
  if (json) {
    std::cout << nlohmann::json{{"ingested", ingested}, {"failed", failed}}.dump() << "\n";
  } else {
    std::cout << absl::StrFormat("ingested %zu of %zu files", ingested.size(), files.size())
              << (failed.empty() ? "" : absl::StrFormat(", %zu failed", failed.size())) << "\n";
  }
  return failed.empty() ? absl::OkStatus() : ReportedFailure();
}

}  // namespace

void AddIngest(Commands& commands) {
  auto flags = std::make_shared<IngestFlags>();
  const GlobalOptions& global = commands.global();
  CLI::App* ingest = commands.AddServer(commands.root(), "ingest",
                                        "upload BVH files, or the .bvh files of folders",
                                        [flags, &global](const ServerConnection& connection) {
                                          return Ingest(*flags, global.json, connection);
                                        });
  ingest->add_option("PATH", flags->paths, "BVH files or folders")->required();
  ingest->add_option("--tag", flags->tags, "tag every clip with T; repeat for more")
      ->type_name("T")
      ->allow_extra_args(false);
  ingest->add_flag("--recursive", flags->recursive, "the folders' subfolders too");
}

}  // namespace motiondb::cli
