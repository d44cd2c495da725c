// motiondb clips [--tag T] | clip show ID | clip delete ID | export ID [--from F --to T] -o OUT
#include <iostream>
#include <memory>

#include <nlohmann/json.hpp>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "client/commands.h"
#include "client/server_connection.h"
#include "motiondb/v1/clip_service.grpc.pb.h"
#include "util/cli_conventions.h"
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

absl::Status ListClips(const std::string& tag, bool json, const ServerConnection& connection) {
  const auto stub = v1::ClipService::NewStub(connection.channel());
  v1::ListClipsRequest request;
  request.set_page_size(1000);
  request.set_tag(tag);
  nlohmann::json clips = nlohmann::json::array();
  bool first_page = true;
  do {
    v1::ListClipsResponse response;
    MOTIONDB_RETURN_IF_ERROR(Call(connection, [&](grpc::ClientContext* context) {
      return stub->ListClips(context, request, &response);
    }));
    if (first_page && !json) {
      absl::PrintF("%8s  %-40s %8s %8s %9s  %s\n", "ID", "NAME", "FRAMES", "FPS", "SECONDS",
                   "TAGS");
    }
    first_page = false;
    for (const v1::Clip& clip : response.clips()) {
      if (json) {
        clips.push_back(ClipJson(clip));
      } else {
        absl::PrintF("%8d  %-40s %8d %8.2f %9.2f  %s\n", clip.clip_id(), clip.name(),
                     clip.frame_count(), clip.fps(), clip.duration_s(),
                     absl::StrJoin(clip.tags(), ","));
      }
    }
    request.set_page_token(response.next_page_token());
  } while (!request.page_token().empty());
  if (json) std::cout << nlohmann::json{{"clips", clips}}.dump() << "\n";
  return absl::OkStatus();
}

absl::Status ShowClip(int64_t id, bool json, const ServerConnection& connection) {
  const auto stub = v1::ClipService::NewStub(connection.channel());
  v1::GetClipRequest request;
  request.set_clip_id(id);
  v1::Clip clip;
  MOTIONDB_RETURN_IF_ERROR(Call(connection, [&](grpc::ClientContext* context) {
    return stub->GetClip(context, request, &clip);
  }));
  if (json) {
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

absl::Status DeleteClip(int64_t id, bool json, const ServerConnection& connection) {
  const auto stub = v1::ClipService::NewStub(connection.channel());
  v1::DeleteClipRequest request;
  request.set_clip_id(id);
  v1::DeleteClipResponse response;
  MOTIONDB_RETURN_IF_ERROR(Call(connection, [&](grpc::ClientContext* context) {
    return stub->DeleteClip(context, request, &response);
  }));
  if (json) {
    std::cout << nlohmann::json{{"deleted", id}}.dump() << "\n";
  } else {
    absl::PrintF("deleted clip %d\n", id);
  }
  return absl::OkStatus();
}

struct ExportFlags {
  int64_t id = 0;
  FrameRangeFlags range;
  std::string out;
};

absl::Status Export(const ExportFlags& flags, bool json, const ServerConnection& connection) {
  v1::ExportClipRequest request;
  request.mutable_clip()->set_clip_id(flags.id);
  if (flags.range.from) request.mutable_clip()->set_first_frame(*flags.range.from);
  if (flags.range.to) request.mutable_clip()->set_last_frame(*flags.range.to);
  const auto stub = v1::ClipService::NewStub(connection.channel());
  v1::ExportClipResponse response;
  MOTIONDB_RETURN_IF_ERROR(Call(
      connection,
      [&](grpc::ClientContext* context) { return stub->ExportClip(context, request, &response); },
      {{"clip.first_frame", "--from"}, {"clip.last_frame", "--to"}}));
  MOTIONDB_RETURN_IF_ERROR(WriteFileAtomically(flags.out, response.bvh()));
  if (json) {
    std::cout << nlohmann::json{{"file", flags.out},
                                {"clip_id", flags.id},
                                {"first_frame", response.first_frame()},
                                {"last_frame", response.last_frame()},
                                {"bytes", response.bvh().size()}}
                     .dump()
              << "\n";
  } else {
    absl::PrintF("wrote %s: clip %d, frames %d-%d\n", flags.out, flags.id, response.first_frame(),
                 response.last_frame());
  }
  return absl::OkStatus();
}

// A stored clip's id, the positional argument of `clip show`, `clip delete` and `export`.
void AddClipId(CLI::App* command, int64_t* id) {
  command->add_option("ID", *id, "the clip's id (see 'motiondb clips')")
      ->required()
      ->check(WholeAtLeast(1));
}

}  // namespace

void AddClipCommands(Commands& commands) {
  const GlobalOptions& global = commands.global();
  auto tag = std::make_shared<std::string>();
  commands
      .AddServer(commands.root(), "clips", "list the stored clips",
                 [tag, &global](const ServerConnection& connection) {
                   return ListClips(*tag, global.json, connection);
                 })
      ->add_option("--tag", *tag, "only clips tagged T")
      ->type_name("T");

  CLI::App* clip = commands.AddGroup(commands.root(), "clip", "one stored clip: show, delete");
  auto id = std::make_shared<int64_t>(0);  // `show` and `delete` take the same ID; one runs
  AddClipId(commands.AddServer(clip, "show", "a clip's frames, rate, skeleton and tags",
                               [id, &global](const ServerConnection& connection) {
                                 return ShowClip(*id, global.json, connection);
                               }),
            id.get());
  AddClipId(commands.AddServer(clip, "delete", "delete a clip and its projections",
                               [id, &global](const ServerConnection& connection) {
                                 return DeleteClip(*id, global.json, connection);
                               }),
            id.get());

  auto flags = std::make_shared<ExportFlags>();
  CLI::App* exporter = commands.AddServer(commands.root(), "export",
                                          "download a clip, or a range of it, as a BVH file",
                                          [flags, &global](const ServerConnection& connection) {
                                            return Export(*flags, global.json, connection);
                                          });
  AddClipId(exporter, &flags->id);
  AddFrameRangeFlags(exporter, "the clip", &flags->range);
  exporter->add_option("-o,--out", flags->out, "the BVH file to write")
      ->type_name("OUT.bvh")
      ->required();
}

}  // namespace motiondb::cli
