// motiondb clips [--tag T] | clip show ID | clip delete ID | export ID [--from F --to T] -o OUT
#include <charconv>
#include <iostream>

#include <nlohmann/json.hpp>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "client/commands.h"
#include "client/server_connection.h"
#include "motiondb/v1/clip_service.grpc.pb.h"
#include "util/file_io.h"
#include "util/status_macros.h"

namespace motiondb::cli {
namespace {

nlohmann::json ClipJson(const v1::Clip& clip) {
  nlohmann::json json = {
      {"clip_id", clip.clip_id()},
      {"name", clip.name()},
      {"source_file", clip.source_file()},
      {"frames", clip.frame_count()},
      {"fps", clip.fps()},
      {"duration_s", clip.duration_s()},
      {"skeleton_id", clip.skeleton_id()},
      {"joint_count", clip.joint_count()},
      {"tags", std::vector<std::string>(clip.tags().begin(), clip.tags().end())}};
  if (clip.joint_names_size() > 0) {
    json["joints"] = std::vector<std::string>(clip.joint_names().begin(), clip.joint_names().end());
  }
  return json;
}

absl::StatusOr<int64_t> ParseClipId(const CommandLine& line, size_t index) {
  if (line.positionals().size() != index + 1) {
    return absl::InvalidArgumentError("expected one clip id");
  }
  const std::string& text = line.positionals()[index];
  int64_t id = 0;
  const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), id);
  if (ec != std::errc() || ptr != text.data() + text.size() || id <= 0) {
    return absl::InvalidArgumentError(absl::StrCat("'", text, "' is not a clip id"));
  }
  return id;
}

absl::Status ListClips(const CommandLine& line, const ServerConnection& connection) {
  if (!line.positionals().empty()) return absl::InvalidArgumentError("unexpected arguments");
  const auto stub = v1::ClipService::NewStub(connection.channel());
  v1::ListClipsRequest request;
  request.set_page_size(1000);
  request.set_tag(line.value("tag").value_or(""));
  nlohmann::json clips = nlohmann::json::array();
  bool first_page = true;
  do {
    v1::ListClipsResponse response;
    MOTIONDB_RETURN_IF_ERROR(Call(connection, [&](grpc::ClientContext* context) {
      return stub->ListClips(context, request, &response);
    }));
    if (first_page && !line.flag("json")) {
      absl::PrintF("%8s  %-40s %8s %8s %9s  %s\n", "ID", "NAME", "FRAMES", "FPS", "SECONDS",
                   "TAGS");
    }
    first_page = false;
    for (const v1::Clip& clip : response.clips()) {
      if (line.flag("json")) {
        clips.push_back(ClipJson(clip));
      } else {
        absl::PrintF("%8d  %-40s %8d %8.2f %9.2f  %s\n", clip.clip_id(), clip.name(),
                     clip.frame_count(), clip.fps(), clip.duration_s(),
                     absl::StrJoin(clip.tags(), ","));
      }
    }
    request.set_page_token(response.next_page_token());
  } while (!request.page_token().empty());
  if (line.flag("json")) std::cout << nlohmann::json{{"clips", clips}}.dump() << "\n";
  return absl::OkStatus();
}

absl::Status ClipSubcommand(const CommandLine& line, const ServerConnection& connection) {
  const std::string subcommand = line.positionals().empty() ? "" : line.positionals()[0];
  if (subcommand != "show" && subcommand != "delete") {
    return absl::InvalidArgumentError("expected 'clip show ID' or 'clip delete ID'");
  }
  MOTIONDB_ASSIGN_OR_RETURN(const int64_t id, ParseClipId(line, 1));
  const auto stub = v1::ClipService::NewStub(connection.channel());
  if (subcommand == "delete") {
    v1::DeleteClipRequest request;
    request.set_clip_id(id);
    v1::DeleteClipResponse response;
    MOTIONDB_RETURN_IF_ERROR(Call(connection, [&](grpc::ClientContext* context) {
      return stub->DeleteClip(context, request, &response);
    }));
    if (line.flag("json")) {
      std::cout << nlohmann::json{{"deleted", id}}.dump() << "\n";
    } else {
      absl::PrintF("deleted clip %d\n", id);
    }
    return absl::OkStatus();
  }
  v1::GetClipRequest request;
  request.set_clip_id(id);
  v1::Clip clip;
  MOTIONDB_RETURN_IF_ERROR(Call(connection, [&](grpc::ClientContext* context) {
    return stub->GetClip(context, request, &clip);
  }));
  if (line.flag("json")) {
    std::cout << ClipJson(clip).dump() << "\n";
  } else {
    absl::PrintF("clip %d: %s (from %s)\n  frames:   %d at %.4f fps, %.3f s\n", clip.clip_id(),
                 clip.name(), clip.source_file(), clip.frame_count(), clip.fps(),
                 clip.duration_s());
    absl::PrintF("  skeleton: %d, %d joints (%s)\n  tags:     %s\n", clip.skeleton_id(),
                 clip.joint_count(), absl::StrJoin(clip.joint_names(), ", "),
                 clip.tags().empty() ? "none" : absl::StrJoin(clip.tags(), ", "));
  }
  return absl::OkStatus();
}

absl::Status Export(const CommandLine& line, const ServerConnection& connection) {
  MOTIONDB_ASSIGN_OR_RETURN(const int64_t id, ParseClipId(line, 0));
  const std::optional<std::string> out = line.value("out");
  if (!out) return absl::InvalidArgumentError("no output file given (-o OUT.bvh)");
  v1::ExportClipRequest request;
  request.mutable_clip()->set_clip_id(id);
  MOTIONDB_ASSIGN_OR_RETURN(const std::optional<int> from, line.integer("from"));
  MOTIONDB_ASSIGN_OR_RETURN(const std::optional<int> to, line.integer("to"));
  if (from) request.mutable_clip()->set_first_frame(*from);
  if (to) request.mutable_clip()->set_last_frame(*to);
  const auto stub = v1::ClipService::NewStub(connection.channel());
  v1::ExportClipResponse response;
  MOTIONDB_RETURN_IF_ERROR(Call(connection, [&](grpc::ClientContext* context) {
    return stub->ExportClip(context, request, &response);
  }));
  MOTIONDB_RETURN_IF_ERROR(WriteFileAtomically(*out, response.bvh()));
  if (line.flag("json")) {
    std::cout << nlohmann::json{{"file", *out},
                                {"clip_id", id},
                                {"first_frame", response.first_frame()},
                                {"last_frame", response.last_frame()},
                                {"bytes", response.bvh().size()}}
                     .dump()
              << "\n";
  } else {
    absl::PrintF("wrote %s: clip %d, frames %d-%d\n", *out, id, response.first_frame(),
                 response.last_frame());
  }
  return absl::OkStatus();
}

}  // namespace

int RunClips(const std::vector<std::string>& args) {
  return RunServerCommand("clips", "motiondb clips [--tag T] [--json] [--server ADDR]", args,
                          {"tag"}, {"json"}, ListClips);
}

int RunClip(const std::vector<std::string>& args) {
  return RunServerCommand("clip", "motiondb clip show|delete ID [--json] [--server ADDR]", args, {},
                          {"json"}, ClipSubcommand);
}

int RunExport(const std::vector<std::string>& args) {
  return RunServerCommand("export",
                          "motiondb export ID [--from F --to T] -o OUT.bvh [--server ADDR]", args,
                          {"from", "to", "out"}, {"json"}, Export);
}

}  // namespace motiondb::cli
