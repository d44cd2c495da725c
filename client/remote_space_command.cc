// motiondb space create NAME [--train CLIP[:FROM-TO]]... [options] | list | show NAME |
// delete NAME: Motion Curve spaces on the server (`space build` is the offline command).
#include <iostream>
#include <memory>

#include <nlohmann/json.hpp>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "client/clip_range_arg.h"
#include "client/commands.h"
#include "client/server_connection.h"
#include "client/space_flags.h"
#include "core/space/learned_metric.h"
#include "motiondb/v1/space_service.grpc.pb.h"
#include "util/cli_conventions.h"
#include "util/file_io.h"
#include "util/status_macros.h"

namespace motiondb::cli {
namespace {

struct CreateFlags {
  std::string name;
  std::vector<std::string> train;  // CLIP_ID[:FROM-TO]
  std::optional<int64_t> skeleton;
  std::vector<int64_t> skeletons;  // a space over several
  SpaceFlags space;
  bool learned_metric = false;
  std::optional<double> learned_metric_shrink;
};

absl::StatusOr<v1::CreateSpaceRequest> CreateRequest(const CreateFlags& flags) {
  v1::CreateSpaceRequest request;
  request.set_name(flags.name);
  for (const std::string& spec : flags.train) {
    MOTIONDB_ASSIGN_OR_RETURN(*request.add_training(), ParseClipRange(spec));
  }
  const SpaceFlags& space = flags.space;
  if (space.rate) request.set_sample_rate(*space.rate);
  if (space.yaw_rate_weight) request.set_yaw_rate_weight(*space.yaw_rate_weight);
  if (space.root_velocity_weight) request.set_root_velocity_weight(*space.root_velocity_weight);
  if (flags.skeleton) request.set_skeleton_id(*flags.skeleton);
  for (const int64_t id : flags.skeletons) request.add_skeleton_ids(id);
  request.set_keep_heading(space.keep_heading);
  if (!IsWeightPreset(space.weights)) {
    MOTIONDB_ASSIGN_OR_RETURN(*request.mutable_weights_json(),
                              ReadFileBytes(space.weights, 1 << 20));
  } else {
    request.set_weight_preset(space.weights == "mass" ? v1::WEIGHT_PRESET_MASS
                                                      : v1::WEIGHT_PRESET_UNIFORM);
  }
  request.set_metric(space.metric == "unit" ? v1::SPACE_METRIC_UNIT
                                            : v1::SPACE_METRIC_EIGENVALUE_SCALED);
  if (flags.learned_metric) {
    v1::LearnedMetric* learned = request.mutable_learned_metric();
    if (flags.learned_metric_shrink) learned->set_shrink(*flags.learned_metric_shrink);
  }
  return request;
}

// The flags that set CreateSpaceRequest's fields, for the server's errors.
FlagNames CreateFlagNames(const CreateFlags& flags) {
  FlagNames names = {{"skeleton_ids", "--skeletons"},
                     {"skeleton_id", "--skeleton"},
                     {"sample_rate", "--rate"},
                     {"yaw_rate_weight", "--yaw-rate-weight"},
                     {"root_velocity_weight", "--root-velocity-weight"},
                     {"weights_json", "--weights"},
                     {"weight_preset", "--weights"},
                     {"metric", "--metric"},
                     {"learned_metric.shrink", "--learned-metric-shrink"},
                     {"learned_metric", "--learned-metric"}};
  for (size_t i = 0; i < flags.train.size(); ++i) {
    const std::string field = absl::StrCat("training[", i, "]");
    const std::string flag = absl::StrCat("--train ", flags.train[i]);
    names.insert(names.end(), {{field, flag},
                               {field + ".first_frame", flag + ": frame"},
                               {field + ".last_frame", flag + ": frame"}});
  }
  return names;
}

nlohmann::json SpaceJson(const v1::Space& space) {
  const v1::SpaceBuildReport& report = space.report();
  nlohmann::json errors = nlohmann::json::array();
  for (const v1::ReconstructionError& e : report.reconstruction_error()) {
    errors.push_back({{"dims", e.dims()}, {"mean_rad", e.mean_rad()}, {"max_rad", e.max_rad()}});
  }
  nlohmann::json out = {
      {"name", space.name()},
      {"space_id", space.space_id()},
      {"skeleton_id", space.skeleton_id()},
      {"representation", space.representation()},
      {"skeleton_ids",
       std::vector<int64_t>(space.skeleton_ids().begin(), space.skeleton_ids().end())},
      {"dims", report.dims()},
      {"sample_rate", report.sample_rate()},
      {"heading_removed", report.heading_removed()},
      {"root_velocity_weight", report.root_velocity_weight()},
      {"training_frames", report.training_frames()},
      {"projected_clips", report.projected_clips()},
      // The resident index, current after later ingests and deletes; the report is the
      // build's.
      {"clips", space.index().clips()},
      {"frames", space.index().frames()},
      {"explained_variance",
       std::vector<double>(report.explained_variance().begin(), report.explained_variance().end())},
      {"reconstruction_error", errors}};
  if (report.has_learned_metric()) {
    out["learned_metric"] = {{"shrink", report.learned_metric().shrink()},
                             {"examples", report.learned_metric().examples()},
                             {"descriptors", report.learned_metric().descriptors()}};
  }
  return out;
}

void PrintSpace(const v1::Space& space) {
  const v1::SpaceBuildReport& report = space.report();
  absl::PrintF("space %s (id %d, skeleton %d): %d dims at %g Hz, heading %s, pelvis %s\n",
               space.name(), space.space_id(), space.skeleton_id(), report.dims(),
               report.sample_rate(), report.heading_removed() ? "removed" : "kept",
               report.pelvis());
  if (space.skeleton_ids_size() > 0) {
    absl::PrintF("  over skeletons %s (%s)\n", absl::StrJoin(space.skeleton_ids(), ", "),
                 space.representation());
  }
  absl::PrintF("  trained on %d ranges (%d frames); %d clips projected when built\n",
               report.training_size(), report.training_frames(), report.projected_clips());
  absl::PrintF("  index: %d clips, %d frames\n", space.index().clips(), space.index().frames());
  if (report.has_learned_metric()) {
    absl::PrintF("  search metric learned from %d labelled ranges of %d descriptors (shrink %g)\n",
                 report.learned_metric().examples(), report.learned_metric().descriptors(),
                 report.learned_metric().shrink());
  }
  double cumulative = 0;
  absl::PrintF("  explained variance:");
  for (int i = 0; i < report.explained_variance_size() && i < 10; ++i) {
    cumulative += report.explained_variance(i);
    absl::PrintF(" %.3f", cumulative);
  }
  absl::PrintF(" (cumulative, first 10 dims)\n  reconstruction error (rad): ");
  for (const v1::ReconstructionError& e : report.reconstruction_error()) {
    absl::PrintF("%d dims %.4f/%.4f  ", e.dims(), e.mean_rad(), e.max_rad());
  }
  absl::PrintF("(mean/max)\n");
}

void PrintSpaceOrJson(const v1::Space& space, bool json) {
  if (json) {
    std::cout << SpaceJson(space).dump() << "\n";
  } else {
    PrintSpace(space);
  }
}

absl::Status Create(const CreateFlags& flags, bool json, const ServerConnection& connection) {
  MOTIONDB_ASSIGN_OR_RETURN(const v1::CreateSpaceRequest request, CreateRequest(flags));
  MOTIONDB_ASSIGN_OR_RETURN(
      const v1::Space space,
      CallUnary(connection, &v1::SpaceService::Stub::CreateSpace, request, CreateFlagNames(flags)));
  PrintSpaceOrJson(space, json);
  return absl::OkStatus();
}

absl::Status ListSpaces(bool json, const ServerConnection& connection) {
  MOTIONDB_ASSIGN_OR_RETURN(
      const v1::ListSpacesResponse response,
      CallUnary(connection, &v1::SpaceService::Stub::ListSpaces, v1::ListSpacesRequest()));
  nlohmann::json spaces = nlohmann::json::array();
  for (const v1::Space& space : response.spaces()) {
    if (json) {
      spaces.push_back(SpaceJson(space));
    } else {
      absl::PrintF("%-24s skeleton %d, %d dims at %g Hz, %d clips\n", space.name(),
                   space.skeleton_id(), space.report().dims(), space.report().sample_rate(),
                   space.index().clips());
    }
  }
  if (json) std::cout << nlohmann::json{{"spaces", spaces}}.dump() << "\n";
  return absl::OkStatus();
}

absl::Status Show(const std::string& name, bool json, const ServerConnection& connection) {
  v1::GetSpaceRequest request;
  request.set_name(name);
  MOTIONDB_ASSIGN_OR_RETURN(const v1::Space space,
                            CallUnary(connection, &v1::SpaceService::Stub::GetSpace, request));
  PrintSpaceOrJson(space, json);
  return absl::OkStatus();
}

absl::Status DeleteSpace(const std::string& name, bool json, const ServerConnection& connection) {
  v1::DeleteSpaceRequest request;
  request.set_name(name);
  MOTIONDB_RETURN_IF_ERROR(
      CallUnary(connection, &v1::SpaceService::Stub::DeleteSpace, request).status());
  std::cout << (json ? nlohmann::json{{"deleted", name}}.dump()
                     : absl::StrCat("deleted space ", name))
            << "\n";
  return absl::OkStatus();
}

}  // namespace

void AddRemoteSpace(Commands& commands, CLI::App* space) {
  const GlobalOptions& global = commands.global();
  auto create = std::make_shared<CreateFlags>();
  CLI::App* create_command =
      commands.AddServer(space, "create", "build a space from stored clips; index every clip in it",
                         [create, &global](const ServerConnection& connection) {
                           return Create(*create, global.json, connection);
                         });
  create_command->add_option("NAME", create->name, "the new space (letters, digits, '.', '_', '-')")
      ->required();
  create_command
      ->add_option("--train", create->train,
                   "a clip to learn from (default: all), or frames FROM..TO of it")
      ->type_name("CLIP_ID[:FROM-TO]")
      ->allow_extra_args(false)
      ->check(ClipRangeCheck());
  create_command->add_option("--skeleton", create->skeleton, "the skeleton (default: --train's)")
      ->type_name("ID")
      ->check(WholeAtLeast(1));
  create_command
      ->add_option("--skeletons", create->skeletons,
                   "a space over several skeletons, in canonical bone directions: their ids")
      ->type_name("ID,ID,...")
      ->delimiter(',')
      ->check(WholeAtLeast(1))
      ->excludes("--skeleton");
  AddSpaceFlags(create_command, &create->space);
  create_command->add_flag(
      "--learned-metric", create->learned_metric,
      "search in a metric learned from the stored manual labels: what differs between clips of "
      "one descriptor (take, performer, style) counts less");
  create_command
      ->add_option("--learned-metric-shrink", create->learned_metric_shrink,
                   "with --learned-metric: how far, in [0, 1)")
      ->type_name("S")
      ->default_str(absl::StrCat(LearnedMetricOptions().shrink))
      ->check(NumberAtLeast(0))  // and below 1, which the server checks
      ->needs("--learned-metric");

  commands.AddServer(space, "list", "list the server's spaces",
                     [&global](const ServerConnection& connection) {
                       return ListSpaces(global.json, connection);
                     });
  // `show` and `delete` take the same NAME; one of them runs.
  auto name = std::make_shared<std::string>();
  commands
      .AddServer(space, "show", "a space's build report",
                 [name, &global](const ServerConnection& connection) {
                   return Show(*name, global.json, connection);
                 })
      ->add_option("NAME", *name, "the space")
      ->required();
  commands
      .AddServer(space, "delete", "delete a space and its projections",
                 [name, &global](const ServerConnection& connection) {
                   return DeleteSpace(*name, global.json, connection);
                 })
      ->add_option("NAME", *name, "the space")
      ->required();
}

}  // namespace motiondb::cli
