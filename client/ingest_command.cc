// motiondb ingest PATH... [--tag T]... [--recursive] [--name N] [--on-conflict error|skip|replace]
// [--json]
// Uploads motion files (BVH, FBX, glTF), or those of folders, to the server: a clip a BVH, a
// clip a take of an FBX or glTF file. Each file's error is listed while the others continue;
// the exit code is 1 if any failed.
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
#include "util/cli_conventions.h"
#include "util/file_io.h"

namespace motiondb::cli {
namespace {

namespace fs = std::filesystem;

// Files larger than this are streamed in chunks of this size.
constexpr size_t kChunkBytes = 1 << 20;
// Larger than any motion file a studio will have; the server has its own limit.
constexpr int64_t kMaxFileBytes = int64_t{4} << 30;

bool IsMotionFile(const fs::path& path) {
  std::string extension = path.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(), ::tolower);
  return extension == ".bvh" || extension == ".fbx" || extension == ".glb" || extension == ".gltf";
}

// A file to upload, and the clip name to ask for: empty for a file named directly (the server
// takes its base name), else its path relative to the folder named, without its extension, so that
// takes of one name in several session folders ("session1/take_001") do not collide.
struct FileToIngest {
  fs::path path;
  std::string name;
};

// The files named, and the motion files of the folders named (their subfolders too with
// `recursive`), sorted within each folder. Paths that do not exist are kept, to fail later.
std::vector<FileToIngest> ExpandPaths(const std::vector<std::string>& paths, bool recursive) {
  std::vector<FileToIngest> files;
  for (const std::string& name : paths) {
    std::error_code error;
    if (!fs::is_directory(name, error)) {
      files.push_back({fs::path(name), ""});
      continue;
    }
    std::vector<FileToIngest> found;
    const auto add = [&](const fs::directory_entry& entry) {
      if (!entry.is_regular_file() || !IsMotionFile(entry.path())) return;
      // generic_string: '/' between the segments whatever the platform writes.
      found.push_back({entry.path(),
                       entry.path().lexically_relative(name).replace_extension().generic_string()});
    };
    if (recursive) {
      for (const auto& entry : fs::recursive_directory_iterator(name, error)) add(entry);
    } else {
      for (const auto& entry : fs::directory_iterator(name, error)) add(entry);
    }
    std::sort(found.begin(), found.end(),
              [](const FileToIngest& a, const FileToIngest& b) { return a.path < b.path; });
    files.insert(files.end(), found.begin(), found.end());
  }
  return files;
}

struct IngestFlags {
  std::vector<std::string> paths;
  std::vector<std::string> tags;
  bool recursive = false;
  std::string name;         // overrides the clip name of a single file
  std::string on_conflict;  // empty: the server's default
};

v1::OnConflict OnConflictOf(const std::string& flag) {
  return flag == "error"     ? v1::ON_CONFLICT_ERROR
         : flag == "skip"    ? v1::ON_CONFLICT_SKIP
         : flag == "replace" ? v1::ON_CONFLICT_REPLACE
                             : v1::ON_CONFLICT_UNSPECIFIED;
}

// What both request messages carry besides the bytes: IngestClipRequest and the first
// IngestClipStreamRequest have the same fields.
template <typename Request>
void FillHeader(const FileToIngest& file, const IngestFlags& flags, Request* request) {
  request->set_file_name(file.path.filename().string());
  request->set_name(flags.name.empty() ? file.name : flags.name);
  for (const std::string& tag : flags.tags) request->add_tags(tag);
  request->set_on_conflict(OnConflictOf(flags.on_conflict));
}

grpc::Status Upload(const ServerConnection& connection, v1::ClipService::Stub& stub,
                    const FileToIngest& file, const std::string& bytes, const IngestFlags& flags,
                    v1::IngestClipResponse* response) {
  const std::unique_ptr<grpc::ClientContext> context = connection.NewContext();
  if (bytes.size() <= kChunkBytes) {
    v1::IngestClipRequest request;
    FillHeader(file, flags, &request);
    request.set_bvh(bytes);
    return stub.IngestClip(context.get(), request, response);
  }
  std::unique_ptr<grpc::ClientWriter<v1::IngestClipStreamRequest>> writer =
      stub.IngestClipStream(context.get(), response);
  v1::IngestClipStreamRequest header;
  FillHeader(file, flags, &header);
  bool open = writer->Write(header);
  for (size_t at = 0; open && at < bytes.size(); at += kChunkBytes) {
    v1::IngestClipStreamRequest chunk;
    chunk.set_chunk(bytes.substr(at, kChunkBytes));
    open = writer->Write(chunk);
  }
  writer->WritesDone();
  return writer->Finish();
}

// "stored", "skipped" or "replaced", as --json gives it.
std::string ResultName(v1::IngestResult result) {
  switch (result) {
    case v1::INGEST_RESULT_SKIPPED:
      return "skipped";
    case v1::INGEST_RESULT_REPLACED:
      return "replaced";
    default:
      return "stored";
  }
}

// The human line's outcome: "stored", "skipped (identical)", "replaced clip 4". Under the
// default policy a skip means the stored clip has the same content; under --on-conflict skip it
// only means the name was taken.
std::string DescribeResult(const v1::IngestClipResponse& response, const std::string& on_conflict) {
  switch (response.result()) {
    case v1::INGEST_RESULT_SKIPPED:
      return on_conflict.empty() ? "skipped (identical)" : "skipped (name taken)";
    case v1::INGEST_RESULT_REPLACED:
      return absl::StrFormat("replaced clip %d", response.replaced_clip_id());
    default:
      return "stored";
  }
}

absl::Status Ingest(const IngestFlags& flags, bool json, const ServerConnection& connection) {
  const std::unique_ptr<v1::ClipService::Stub> stub =
      v1::ClipService::NewStub(connection.channel());
  const std::vector<FileToIngest> files = ExpandPaths(flags.paths, flags.recursive);
  if (!flags.name.empty() && files.size() != 1) {
    return absl::InvalidArgumentError(
        absl::StrFormat("--name names one clip, but the paths hold %d files", files.size()));
  }
  const bool progress_bar = ::isatty(STDERR_FILENO) && !json;
  nlohmann::json ingested = nlohmann::json::array(), failed = nlohmann::json::array();
  for (size_t i = 0; i < files.size(); ++i) {
    const fs::path& path = files[i].path;
    std::string error;
    v1::IngestClipResponse response;
    if (absl::StatusOr<std::string> bytes = ReadFileBytes(path.string(), kMaxFileBytes);
        !bytes.ok()) {
      error = std::string(bytes.status().message());
    } else if (const grpc::Status status =
                   Upload(connection, *stub, files[i], *bytes, flags, &response);
               !status.ok()) {
      error = DescribeError(status, connection.address());
    }
    if (progress_bar) std::cerr << "\r\033[K";
    if (!error.empty()) {
      std::cerr << "motiondb ingest: " << path.string() << ": " << error << "\n";
      failed.push_back({{"file", path.string()}, {"error", error}});
    } else {
      // A file of several takes answers with a clip for each.
      std::vector<const v1::IngestClipResponse*> takes = {&response};
      for (const v1::IngestClipResponse& take : response.more_takes()) takes.push_back(&take);
      for (const v1::IngestClipResponse* take : takes) {
        const v1::Clip& clip = take->clip();
        ingested.push_back({{"file", path.string()},
                            {"clip_id", clip.clip_id()},
                            {"name", clip.name()},
                            {"result", ResultName(take->result())},
                            {"frames", clip.frame_count()},
                            {"fps", clip.fps()},
                            {"warnings", std::vector<std::string>(take->warnings().begin(),
                                                                  take->warnings().end())}});
        if (!take->take().empty()) ingested.back()["take"] = take->take();
        if (take->result() == v1::INGEST_RESULT_REPLACED) {
          ingested.back()["replaced_clip_id"] = take->replaced_clip_id();
        }
        for (const std::string& warning : take->warnings()) {
          std::cerr << "motiondb ingest: " << path.string() << ": warning: " << warning << "\n";
        }
        if (!json && !progress_bar) {
          std::cout << absl::StrFormat("[%zu/%zu] %s -> clip %d '%s' (%d frames): %s\n", i + 1,
                                       files.size(), path.string(), clip.clip_id(), clip.name(),
                                       clip.frame_count(),
                                       DescribeResult(*take, flags.on_conflict));
        }
      }
      if (const v1::FileFacts& facts = response.file(); !json && !facts.up_axis().empty()) {
        std::cout << absl::StrFormat(
            "  %s, %g m a unit, %s up%s%s\n", facts.format(), facts.unit_m(), facts.up_axis(),
            facts.generator().empty() ? "" : ", written by ", facts.generator());
      }
    }
    if (progress_bar) {
      const int width = 30, done = static_cast<int>(width * (i + 1) / files.size());
      std::cerr << absl::StrFormat("[%s%s] %zu/%zu %s", std::string(done, '#'),
                                   std::string(width - done, ' '), i + 1, files.size(),
                                   path.filename().string())
                << std::flush;
    }
  }
  if (progress_bar) std::cerr << "\n";
  if (json) {
    std::cout << nlohmann::json{{"ingested", ingested}, {"failed", failed}}.dump() << "\n";
  } else {
    std::cout << absl::StrFormat("ingested %zu of %zu files", files.size() - failed.size(),
                                 files.size())
              << (failed.empty() ? "" : absl::StrFormat(", %zu failed", failed.size())) << "\n";
  }
  return failed.empty() ? absl::OkStatus() : ReportedFailure();
}

}  // namespace

void AddIngest(Commands& commands) {
  auto flags = std::make_shared<IngestFlags>();
  const GlobalOptions& global = commands.global();
  CLI::App* ingest = commands.AddServer(commands.root(), "ingest",
                                        "upload motion files (BVH, FBX, glTF), or those of folders",
                                        [flags, &global](const ServerConnection& connection) {
                                          return Ingest(*flags, global.json, connection);
                                        });
  ingest->add_option("PATH", flags->paths, "BVH, FBX, .glb or .gltf files, or folders")->required();
  ingest->add_option("--tag", flags->tags, "tag every clip with T; repeat for more")
      ->type_name("T")
      ->allow_extra_args(false);
  ingest->add_flag("--recursive", flags->recursive,
                   "the folders' subfolders too; a clip found in a folder is named by its path "
                   "relative to the folder, without its extension (session1/take_001); a take of "
                   "a file of several takes (FBX, glTF) stores each as NAME/TAKE");
  ingest->add_option("--name", flags->name, "the clip's name instead of the file's (one file only)")
      ->type_name("N");
  OneOf(ingest->add_option("--on-conflict", flags->on_conflict,
                           "when a clip of the name exists: refuse, keep it, or replace it "
                           "(default: skip it if its content is identical, refuse otherwise)"),
        {"error", "skip", "replace"});
}

}  // namespace motiondb::cli
