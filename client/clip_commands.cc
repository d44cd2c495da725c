// motiondb clips [--tag T ...] | skeletons [show ID | map ID --slot S=J... --clear S...] | clip
// show ID | clip update ID [--name N] [--tag +T|-T]... | clip delete ID | export ID [--from F
// --to T] -o OUT
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "absl/strings/match.h"
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
  if (clip.has_provenance()) {
    const v1::Provenance& made = clip.provenance();
    nlohmann::json sources = nlohmann::json::array();
    for (const v1::ClipRange& source : made.sources()) {
      sources.push_back({{"clip_id", source.clip_id()},
                         {"first_frame", source.first_frame()},
                         {"last_frame", source.last_frame()}});
    }
    json["provenance"] = {{"operator", made.operator_()},
                          {"space", made.space()},
                          {"sources", sources},
                          {"parameters", nlohmann::json::parse(made.parameters_json(), nullptr,
                                                               /*allow_exceptions=*/false)}};
  }
  return json;
}

// "scale in space body from clip 1 frames 40-300, clip 2 frames 0-10; {...}".
std::string ProvenanceText(const v1::Provenance& made) {
  std::vector<std::string> sources;
  for (const v1::ClipRange& source : made.sources()) {
    sources.push_back(absl::StrFormat("clip %d frames %d-%d", source.clip_id(),
                                      source.first_frame(), source.last_frame()));
  }
  return absl::StrCat(made.operator_(), " in space ", made.space(), " from ",
                      absl::StrJoin(sources, ", "), "; ", made.parameters_json());
}

// What `clip show` and `clip update` print. UpdateClip's answer has no joint names, so then
// they are left out.
void PrintClip(const v1::Clip& clip, bool json) {
  if (json) {
    std::cout << ClipJson(clip).dump() << "\n";
    return;
  }
  absl::PrintF("clip %d: %s (from %s)\n  frames:   %d at %.4f fps, %.3f s\n", clip.clip_id(),
               clip.name(), clip.source_file(), clip.frame_count(), clip.fps(), clip.duration_s());
  absl::PrintF(
      "  skeleton: %d, %d joints%s\n  tags:     %s\n", clip.skeleton_id(), clip.joint_count(),
      clip.joint_names().empty() ? ""
                                 : absl::StrCat(" (", absl::StrJoin(clip.joint_names(), ", "), ")"),
      clip.tags().empty() ? "none" : absl::StrJoin(clip.tags(), ", "));
  if (clip.has_provenance()) absl::PrintF("  made by:  %s\n", ProvenanceText(clip.provenance()));
}

struct ListFlags {
  std::string tag;
  std::string name_contains;
  std::string sort = "id";
  std::optional<int> limit;  // set, or a page token: one page
  std::string page_token;
};

absl::Status ListClips(const ListFlags& flags, bool json, const ServerConnection& connection) {
  v1::ListClipsRequest request;
  request.set_page_size(flags.limit.value_or(1000));
  request.set_page_token(flags.page_token);
  request.set_tag(flags.tag);
  request.set_name_contains(flags.name_contains);
  request.set_sort(flags.sort);
  const bool one_page = flags.limit.has_value() || !flags.page_token.empty();
  nlohmann::json clips = nlohmann::json::array();
  bool first_page = true;
  v1::ListClipsResponse response;
  do {
    MOTIONDB_ASSIGN_OR_RETURN(
        response,
        CallUnary(connection, &v1::ClipService::Stub::ListClips, request,
                  {{"page_size", "--limit"}, {"page_token", "--page-token"}, {"sort", "--sort"}}));
    if (first_page && !json) {
      absl::PrintF("%8s  %-40s %8s %8s %8s %9s  %s\n", "ID", "NAME", "SKELETON", "FRAMES", "FPS",
                   "SECONDS", "TAGS");
    }
    first_page = false;
    for (const v1::Clip& clip : response.clips()) {
      if (json) {
        clips.push_back(ClipJson(clip));
      } else {
        absl::PrintF("%8d  %-40s %8d %8d %8.2f %9.2f  %s\n", clip.clip_id(), clip.name(),
                     clip.skeleton_id(), clip.frame_count(), clip.fps(), clip.duration_s(),
                     absl::StrJoin(clip.tags(), ","));
      }
    }
    request.set_page_token(response.next_page_token());
  } while (!one_page && !request.page_token().empty());
  const std::string& next = response.next_page_token();
  if (json) {
    nlohmann::json listed = {{"clips", clips}};
    if (one_page && !next.empty()) listed["next_page_token"] = next;
    std::cout << listed.dump() << "\n";
  } else if (one_page && !next.empty()) {
    // On stderr, so that stdout stays the table.
    std::cerr << "next page: --page-token " << next << "\n";
  }
  return absl::OkStatus();
}

absl::Status ListSkeletons(bool json, const ServerConnection& connection) {
  MOTIONDB_ASSIGN_OR_RETURN(
      const v1::ListSkeletonsResponse response,
      CallUnary(connection, &v1::ClipService::Stub::ListSkeletons, v1::ListSkeletonsRequest()));
  if (json) {
    nlohmann::json skeletons = nlohmann::json::array();
    for (const v1::Skeleton& skeleton : response.skeletons()) {
      skeletons.push_back({{"skeleton_id", skeleton.skeleton_id()},
                           {"name", skeleton.name()},
                           {"joint_count", skeleton.joint_count()},
                           {"clip_count", skeleton.clip_count()},
                           {"root_joint", skeleton.root_joint()}});
    }
    std::cout << nlohmann::json{{"skeletons", skeletons}}.dump() << "\n";
    return absl::OkStatus();
  }
  absl::PrintF("%8s  %-40s %6s %8s\n", "ID", "NAME", "JOINTS", "CLIPS");
  for (const v1::Skeleton& skeleton : response.skeletons()) {
    absl::PrintF("%8d  %-40s %6d %8d\n", skeleton.skeleton_id(), skeleton.name(),
                 skeleton.joint_count(), skeleton.clip_count());
  }
  return absl::OkStatus();
}

nlohmann::json SkeletonJson(const v1::SkeletonDetail& detail) {
  const v1::Skeleton& skeleton = detail.skeleton();
  nlohmann::json joints = nlohmann::json::array();
  for (const v1::SkeletonJoint& joint : detail.joints()) {
    joints.push_back({{"name", joint.name()}, {"parent", joint.parent()}});
  }
  const v1::HumanoidMap& map = detail.humanoid_map();
  nlohmann::json slots = nlohmann::json::array();
  for (const v1::HumanoidSlot& slot : map.slots()) {
    slots.push_back({{"slot", slot.slot()},
                     {"joint", slot.joint_name()},
                     {"overridden", slot.overridden()},
                     {"required", slot.required()}});
  }
  nlohmann::json pairs = nlohmann::json::array();
  for (const v1::JointPair& pair : map.mirror_pairs()) {
    pairs.push_back({{"left", pair.left_name()}, {"right", pair.right_name()}});
  }
  return {{"skeleton_id", skeleton.skeleton_id()},
          {"name", skeleton.name()},
          {"joint_count", skeleton.joint_count()},
          {"clip_count", skeleton.clip_count()},
          {"joints", joints},
          {"humanoid_map",
           {{"complete", map.complete()},
            {"slots", slots},
            {"missing_slots",
             std::vector<std::string>(map.missing_slots().begin(), map.missing_slots().end())},
            {"mirror_pairs", pairs}}}};
}

// What `skeletons show` and `skeletons map` print: every slot with its joint (or "-"), the
// overrides marked, what is missing, and the mirror pairs.
void PrintSkeleton(const v1::SkeletonDetail& detail, bool json) {
  if (json) {
    std::cout << SkeletonJson(detail).dump() << "\n";
    return;
  }
  const v1::Skeleton& skeleton = detail.skeleton();
  const v1::HumanoidMap& map = detail.humanoid_map();
  absl::PrintF("skeleton %d: %s, %d joints, %d clip%s\n", skeleton.skeleton_id(), skeleton.name(),
               skeleton.joint_count(), skeleton.clip_count(),
               skeleton.clip_count() == 1 ? "" : "s");
  absl::PrintF("humanoid map: %s\n", map.complete()
                                         ? "complete"
                                         : absl::StrCat("incomplete, missing ",
                                                        absl::StrJoin(map.missing_slots(), ", ")));
  for (const v1::HumanoidSlot& slot : map.slots()) {
    absl::PrintF("  %-14s %s%s\n", slot.slot(), slot.joint_name(),
                 slot.overridden() ? "  (override)" : "");
  }
  std::vector<std::string> pairs;
  for (const v1::JointPair& pair : map.mirror_pairs()) {
    pairs.push_back(absl::StrCat(pair.left_name(), "/", pair.right_name()));
  }
  absl::PrintF("mirror pairs (%d): %s\n", map.mirror_pairs_size(),
               pairs.empty() ? "none" : absl::StrJoin(pairs, ", "));
}

absl::Status ShowSkeleton(int64_t id, bool json, const ServerConnection& connection) {
  v1::GetSkeletonRequest request;
  request.set_skeleton_id(id);
  MOTIONDB_ASSIGN_OR_RETURN(const v1::SkeletonDetail detail,
                            CallUnary(connection, &v1::ClipService::Stub::GetSkeleton, request));
  PrintSkeleton(detail, json);
  return absl::OkStatus();
}

struct MapFlags {
  int64_t id = 0;
  std::vector<std::string> slots;  // each "SLOT=JOINT"
  std::vector<std::string> clear;
};

absl::Status MapSkeleton(const MapFlags& flags, bool json, const ServerConnection& connection) {
  v1::MapSkeletonRequest request;
  request.set_skeleton_id(flags.id);
  FlagNames names;
  for (const std::string& slot : flags.slots) {
    const size_t equals = slot.find('=');
    names.emplace_back(absl::StrCat("set[", request.set_size(), "].slot"),
                       absl::StrCat("--slot ", slot));
    names.emplace_back(absl::StrCat("set[", request.set_size(), "].joint"),
                       absl::StrCat("--slot ", slot));
    v1::SlotOverride* set = request.add_set();
    set->set_slot(slot.substr(0, equals));
    set->set_joint(slot.substr(equals + 1));
  }
  for (const std::string& slot : flags.clear) {
    names.emplace_back(absl::StrCat("clear[", request.clear_size(), "]"),
                       absl::StrCat("--clear ", slot));
    request.add_clear(slot);
  }
  MOTIONDB_ASSIGN_OR_RETURN(
      const v1::SkeletonDetail detail,
      CallUnary(connection, &v1::ClipService::Stub::MapSkeleton, request, names));
  PrintSkeleton(detail, json);
  return absl::OkStatus();
}

absl::Status ShowClip(int64_t id, bool json, const ServerConnection& connection) {
  v1::GetClipRequest request;
  request.set_clip_id(id);
  MOTIONDB_ASSIGN_OR_RETURN(const v1::Clip clip,
                            CallUnary(connection, &v1::ClipService::Stub::GetClip, request));
  PrintClip(clip, json);
  return absl::OkStatus();
}

struct UpdateFlags {
  int64_t id = 0;
  std::optional<std::string> name;
  std::vector<std::string> tags;  // each "+T" (add) or "-T" (remove)
};

absl::Status UpdateClip(const UpdateFlags& flags, bool json, const ServerConnection& connection) {
  v1::UpdateClipRequest request;
  request.set_clip_id(flags.id);
  if (flags.name) request.set_name(*flags.name);
  FlagNames names = {{"name", "--name"}};
  for (const std::string& tag : flags.tags) {
    // The server names the tag by its place in add_tags or remove_tags.
    const bool add = tag[0] == '+';
    const int at = add ? request.add_tags_size() : request.remove_tags_size();
    names.emplace_back(absl::StrCat(add ? "add_tags[" : "remove_tags[", at, "]"),
                       absl::StrCat("--tag ", tag));
    *(add ? request.add_add_tags() : request.add_remove_tags()) = tag.substr(1);
  }
  MOTIONDB_ASSIGN_OR_RETURN(
      const v1::Clip clip,
      CallUnary(connection, &v1::ClipService::Stub::UpdateClip, request, names));
  PrintClip(clip, json);
  return absl::OkStatus();
}

absl::Status DeleteClip(int64_t id, bool json, const ServerConnection& connection) {
  v1::DeleteClipRequest request;
  request.set_clip_id(id);
  MOTIONDB_RETURN_IF_ERROR(
      CallUnary(connection, &v1::ClipService::Stub::DeleteClip, request).status());
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
  std::string format;  // empty: by the file's extension (.gltf, .glb), else BVH
};

// The export's format: --format, else the output file's extension.
std::string ExportFormatOf(const ExportFlags& flags) {
  if (!flags.format.empty()) return flags.format;
  for (const char* format : {"gltf", "glb"}) {
    if (absl::EndsWithIgnoreCase(flags.out, absl::StrCat(".", format))) return format;
  }
  return "bvh";
}

// ExportClipStream: the file written as its pieces arrive, so that a clip of any size exports
// while the client holds a piece of it; renamed into place only once whole.
absl::Status Export(const ExportFlags& flags, bool json, const ServerConnection& connection) {
  v1::ExportClipRequest request;
  request.mutable_clip()->set_clip_id(flags.id);
  if (flags.range.from) request.mutable_clip()->set_first_frame(*flags.range.from);
  if (flags.range.to) request.mutable_clip()->set_last_frame(*flags.range.to);
  request.set_format(ExportFormatOf(flags));
  v1::ClipService::Stub stub(connection.channel());
  AtomicFileWriter file(flags.out);
  absl::Status written;
  v1::ExportClipResponse first, piece;
  int64_t bytes = 0;
  const absl::Status called =
      Call(connection,
           [&](grpc::ClientContext* context) {
             const std::unique_ptr<grpc::ClientReader<v1::ExportClipResponse>> reader =
                 stub.ExportClipStream(context, request);
             for (bool at_first = true; reader->Read(&piece); at_first = false) {
               if (at_first) {
                 first.set_first_frame(piece.first_frame());
                 first.set_last_frame(piece.last_frame());
               }
               bytes += static_cast<int64_t>(piece.bvh().size());
               if (written.ok()) written = file.Append(piece.bvh());
               if (!written.ok()) context->TryCancel();
             }
             return reader->Finish();
           },
           {{"clip.first_frame", "--from"}, {"clip.last_frame", "--to"}});
  // A file that failed to write cancelled the call: its error is the one to tell.
  MOTIONDB_RETURN_IF_ERROR(written);
  MOTIONDB_RETURN_IF_ERROR(called);
  MOTIONDB_RETURN_IF_ERROR(file.Commit());
  if (json) {
    std::cout << nlohmann::json{{"file", flags.out},
                                {"clip_id", flags.id},
                                {"first_frame", first.first_frame()},
                                {"last_frame", first.last_frame()},
                                {"bytes", bytes}}
                     .dump()
              << "\n";
  } else {
    absl::PrintF("wrote %s: clip %d, frames %d-%d\n", flags.out, flags.id, first.first_frame(),
                 first.last_frame());
  }
  return absl::OkStatus();
}

// A stored clip's id, the positional argument of `clip show`, `clip delete` and `export`.
void AddClipId(CLI::App* command, int64_t* id) {
  command->add_option("ID", *id, "the clip's id (see 'motiondb clips')")
      ->required()
      ->check(WholeAtLeast(1));
}

// A stored skeleton's id, the positional argument of `skeletons show` and `skeletons map`.
void AddSkeletonId(CLI::App* command, int64_t* id) {
  command->add_option("ID", *id, "the skeleton's id (see 'motiondb skeletons')")
      ->required()
      ->check(WholeAtLeast(1));
}

}  // namespace

void AddClipCommands(Commands& commands) {
  const GlobalOptions& global = commands.global();
  auto list = std::make_shared<ListFlags>();
  CLI::App* clips = commands.AddServer(commands.root(), "clips", "list the stored clips",
                                       [list, &global](const ServerConnection& connection) {
                                         return ListClips(*list, global.json, connection);
                                       });
  clips->add_option("--tag", list->tag, "only clips tagged T")->type_name("T");
  clips->add_option("--name-contains", list->name_contains, "only clips whose name holds S")
      ->type_name("S");
  OneOf(clips->add_option("--sort", list->sort, "the order"), {"id", "name", "created"})
      ->capture_default_str();
  clips->add_option("--limit", list->limit, "one page of at most N clips (default: all clips)")
      ->type_name("N")
      ->check(WholeAtLeast(1));
  clips
      ->add_option("--page-token", list->page_token,
                   "the page after the one that printed T (with the same --sort)")
      ->type_name("T");
  clips->footer(
      "With --limit or --page-token, one page is listed and the next page's token, when there\n"
      "is one, printed: on stderr, or as next_page_token with --json.");

  CLI::App* skeletons = commands.AddServer(
      commands.root(), "skeletons",
      "list the skeletons: joint hierarchies that clips and spaces share; show or map one",
      [&global](const ServerConnection& connection) {
        return ListSkeletons(global.json, connection);
      });
  skeletons->require_subcommand(0, 1);
  auto skeleton_id = std::make_shared<int64_t>(0);
  AddSkeletonId(commands.AddServer(skeletons, "show",
                                   "a skeleton's joints, humanoid map and left/right pairs",
                                   [skeleton_id, &global](const ServerConnection& connection) {
                                     return ShowSkeleton(*skeleton_id, global.json, connection);
                                   }),
                skeleton_id.get());
  auto map = std::make_shared<MapFlags>();
  CLI::App* mapper = commands.AddServer(
      skeletons, "map", "give slots of a skeleton's humanoid map their joints by hand",
      [map, &global](const ServerConnection& connection) {
        return MapSkeleton(*map, global.json, connection);
      });
  AddSkeletonId(mapper, &map->id);
  mapper
      ->add_option("--slot", map->slots,
                   "SLOT=JOINT: the slot (LeftHand, Hips, ...) is played by the joint of that "
                   "name; repeat for more")
      ->type_name("SLOT=JOINT")
      ->allow_extra_args(false)
      ->check(CLI::Validator(
          [](const std::string& slot) -> std::string {
            if (slot.find('=') != std::string::npos) return "";
            return "'" + slot + "' is not SLOT=JOINT";
          },
          ""));
  mapper
      ->add_option("--clear", map->clear,
                   "hand the slot back to the automatic map; repeat for more")
      ->type_name("SLOT")
      ->allow_extra_args(false);
  mapper->footer(
      "Slots: Hips, Spine, Chest, Neck, Head, and Left... and Right... Shoulder, UpperArm,\n"
      "LowerArm, Hand, UpperLeg, LowerLeg, Foot, Toes. The overrides are stored; the automatic\n"
      "map fills the other slots around them.");

  CLI::App* clip =
      commands.AddGroup(commands.root(), "clip", "one stored clip: show, update, delete");
  auto id = std::make_shared<int64_t>(0);  // `show` and `delete` take the same ID; one runs
  AddClipId(commands.AddServer(clip, "show", "a clip's frames, rate, skeleton and tags",
                               [id, &global](const ServerConnection& connection) {
                                 return ShowClip(*id, global.json, connection);
                               }),
            id.get());
  auto update = std::make_shared<UpdateFlags>();
  CLI::App* updater = commands.AddServer(clip, "update", "rename a clip, add or remove its tags",
                                         [update, &global](const ServerConnection& connection) {
                                           return UpdateClip(*update, global.json, connection);
                                         });
  AddClipId(updater, &update->id);
  updater->add_option("--name", update->name, "the clip's new name")->type_name("N");
  updater->add_option("--tag", update->tags, "+T adds tag T, -T removes it; repeat for more")
      ->type_name("+T|-T")
      ->allow_extra_args(false)
      ->check(CLI::Validator(
          [](const std::string& tag) -> std::string {
            if (tag.size() >= 2 && (tag[0] == '+' || tag[0] == '-')) return "";
            return "'" + tag + "' is neither +TAG (add) nor -TAG (remove)";
          },
          ""));
  AddClipId(commands.AddServer(clip, "delete", "delete a clip and its projections",
                               [id, &global](const ServerConnection& connection) {
                                 return DeleteClip(*id, global.json, connection);
                               }),
            id.get());

  auto flags = std::make_shared<ExportFlags>();
  CLI::App* exporter = commands.AddServer(commands.root(), "export",
                                          "download a clip, or a range of it (a hit), as a BVH "
                                          "or glTF file",
                                          [flags, &global](const ServerConnection& connection) {
                                            return Export(*flags, global.json, connection);
                                          });
  AddClipId(exporter, &flags->id);
  AddFrameRangeFlags(exporter, "the clip", &flags->range);
  exporter->add_option("-o,--out", flags->out, "the file to write")
      ->type_name("OUT.bvh")
      ->required();
  OneOf(exporter->add_option("--format", flags->format,
                             "bvh, gltf (its buffer embedded) or glb (binary glTF), which "
                             "three.js and DCCs read (default: by OUT's extension, else bvh)"),
        {"bvh", "gltf", "glb"});
}

}  // namespace motiondb::cli
