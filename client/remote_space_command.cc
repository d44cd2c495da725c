// motiondb space create NAME [--train CLIP[:FROM-TO]]... [options] | list | show NAME |
// delete NAME: Motion Curve spaces on the server (`space build` is the offline command).
#include <iostream>

#include <nlohmann/json.hpp>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_split.h"
#include "client/commands.h"
#include "client/server_connection.h"
#include "motiondb/v1/space_service.grpc.pb.h"
#include "util/file_io.h"
#include "util/status_macros.h"

namespace motiondb::cli {
namespace {

constexpr char kUsage[] =
    "motiondb space create NAME [--train CLIP_ID[:FROM-TO]]... [--rate R]\n"
    "        [--weights mass|uniform|FILE.json] [--keep-heading] [--yaw-rate-weight W]\n"
    "        [--metric unit|eigen] [--skeleton ID]\n"
    "    | motiondb space list | space show NAME | space delete NAME   [--json] [--server ADDR]";

// "12" or "12:30-90" (frames at the clip's own rate, inclusive).
absl::StatusOr<v1::ClipRange> ParseTraining(const std::string& spec) {
  v1::ClipRange range;
  const std::vector<std::string> parts = absl::StrSplit(spec, ':');
  int64_t id = 0;
  if (parts.size() > 2 || !absl::SimpleAtoi(parts[0], &id)) {
    return absl::InvalidArgumentError(
        absl::StrCat("--train expects CLIP_ID or CLIP_ID:FROM-TO, got '", spec, "'"));
  }
  range.set_clip_id(id);
  if (parts.size() == 2) {
    const std::vector<std::string> bounds = absl::StrSplit(parts[1], '-');
    int first = 0, last = 0;
    if (bounds.size() != 2 || !absl::SimpleAtoi(bounds[0], &first) ||
        !absl::SimpleAtoi(bounds[1], &last)) {
      return absl::InvalidArgumentError(
          absl::StrCat("--train expects CLIP_ID:FROM-TO, got '", spec, "'"));
    }
    range.set_first_frame(first);
    range.set_last_frame(last);
  }
  return range;
}

absl::StatusOr<v1::CreateSpaceRequest> CreateRequest(const CommandLine& line) {
  v1::CreateSpaceRequest request;
  request.set_name(line.positionals()[1]);
  for (const std::string& spec : line.values("train")) {
    MOTIONDB_ASSIGN_OR_RETURN(*request.add_training(), ParseTraining(spec));
  }
  MOTIONDB_ASSIGN_OR_RETURN(const std::optional<double> rate, line.number("rate"));
  if (rate) request.set_sample_rate(*rate);
  MOTIONDB_ASSIGN_OR_RETURN(const std::optional<double> yaw, line.number("yaw-rate-weight"));
  if (yaw) request.set_yaw_rate_weight(*yaw);
  MOTIONDB_ASSIGN_OR_RETURN(const std::optional<int> skeleton, line.integer("skeleton"));
  if (skeleton) request.set_skeleton_id(*skeleton);
  request.set_keep_heading(line.flag("keep-heading"));
  const std::string weights = line.value("weights").value_or("mass");
  if (weights == "mass") {
    request.set_weight_preset(v1::WEIGHT_PRESET_MASS);
  } else if (weights == "uniform") {
    request.set_weight_preset(v1::WEIGHT_PRESET_UNIFORM);
  } else {
    MOTIONDB_ASSIGN_OR_RETURN(*request.mutable_weights_json(), ReadFileBytes(weights, 1 << 20));
  }
  const std::string metric = line.value("metric").value_or("unit");
  if (metric != "unit" && metric != "eigen") {
    return absl::InvalidArgumentError("--metric must be unit or eigen");
  }
  request.set_metric(metric == "unit" ? v1::SPACE_METRIC_UNIT : v1::SPACE_METRIC_EIGENVALUE_SCALED);
  return request;
}

nlohmann::json SpaceJson(const v1::Space& space) {
  const v1::SpaceBuildReport& report = space.report();
  nlohmann::json errors = nlohmann::json::array();
  for (const v1::ReconstructionError& e : report.reconstruction_error()) {
    errors.push_back({{"dims", e.dims()}, {"mean_rad", e.mean_rad()}, {"max_rad", e.max_rad()}});
  }
  return {{"name", space.name()},
          {"space_id", space.space_id()},
          {"skeleton_id", space.skeleton_id()},
          {"dims", report.dims()},
          {"sample_rate", report.sample_rate()},
          {"heading_removed", report.heading_removed()},
          {"training_frames", report.training_frames()},
          {"projected_clips", report.projected_clips()},
          {"explained_variance", std::vector<double>(report.explained_variance().begin(),
                                                     report.explained_variance().end())},
          {"reconstruction_error", errors}};
}

void PrintSpace(const v1::Space& space) {
  const v1::SpaceBuildReport& report = space.report();
  absl::PrintF("space %s (id %d, skeleton %d): %d dims at %g Hz, heading %s, pelvis %s\n",
               space.name(), space.space_id(), space.skeleton_id(), report.dims(),
               report.sample_rate(), report.heading_removed() ? "removed" : "kept",
               report.pelvis());
  absl::PrintF("  trained on %d ranges (%d frames); %d clips projected\n", report.training_size(),
               report.training_frames(), report.projected_clips());
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

absl::Status Space(const CommandLine& line, const ServerConnection& connection) {
  const std::vector<std::string>& args = line.positionals();
  const std::string sub = args.empty() ? "" : args[0];
  const size_t wanted = sub == "list" ? 1 : 2;
  if ((sub != "create" && sub != "list" && sub != "show" && sub != "delete") ||
      args.size() != wanted) {
    return absl::InvalidArgumentError(absl::StrCat("usage: ", kUsage));
  }
  const auto stub = v1::SpaceService::NewStub(connection.channel());
  const bool json = line.flag("json");
  if (sub == "list") {
    v1::ListSpacesResponse response;
    MOTIONDB_RETURN_IF_ERROR(Call(connection, [&](grpc::ClientContext* context) {
      return stub->ListSpaces(context, v1::ListSpacesRequest(), &response);
    }));
    nlohmann::json spaces = nlohmann::json::array();
    for (const v1::Space& space : response.spaces()) {
      if (json) {
        spaces.push_back(SpaceJson(space));
      } else {
        absl::PrintF("%-24s skeleton %d, %d dims at %g Hz, %d clips\n", space.name(),
                     space.skeleton_id(), space.report().dims(), space.report().sample_rate(),
                     space.report().projected_clips());
      }
    }
    if (json) std::cout << nlohmann::json{{"spaces", spaces}}.dump() << "\n";
    return absl::OkStatus();
  }
  if (sub == "delete") {
    v1::DeleteSpaceRequest request;
    request.set_name(args[1]);
    v1::DeleteSpaceResponse response;
    MOTIONDB_RETURN_IF_ERROR(Call(connection, [&](grpc::ClientContext* context) {
      return stub->DeleteSpace(context, request, &response);
    }));
    std::cout << (json ? nlohmann::json{{"deleted", args[1]}}.dump()
                       : absl::StrCat("deleted space ", args[1]))
              << "\n";
    return absl::OkStatus();
  }
  v1::Space space;
  if (sub == "show") {
    v1::GetSpaceRequest request;
    request.set_name(args[1]);
    MOTIONDB_RETURN_IF_ERROR(Call(connection, [&](grpc::ClientContext* context) {
      return stub->GetSpace(context, request, &space);
    }));
  } else {
    MOTIONDB_ASSIGN_OR_RETURN(const v1::CreateSpaceRequest request, CreateRequest(line));
    MOTIONDB_RETURN_IF_ERROR(Call(connection, [&](grpc::ClientContext* context) {
      return stub->CreateSpace(context, request, &space);
    }));
  }
  if (json) {
    std::cout << SpaceJson(space).dump() << "\n";
  } else {
    PrintSpace(space);
  }
  return absl::OkStatus();
}

}  // namespace

int RunRemoteSpace(const std::vector<std::string>& args) {
  return RunServerCommand("space", kUsage, args,
                          {"train", "rate", "weights", "yaw-rate-weight", "metric", "skeleton"},
                          {"keep-heading", "json"}, Space);
}

}  // namespace motiondb::cli
