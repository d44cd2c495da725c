// motiondb op reconstruct | interpolate | blend | fill-gap | scale | translate | smooth: the
// Motion Curve operators of EditService (issue 16) on stored clips; `op detect` is in
// op_detect_command.cc.
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "client/clip_range_arg.h"
#include "client/commands.h"
#include "client/op_flags.h"
#include "client/server_connection.h"
#include "motiondb/v1/edit_service.grpc.pb.h"
#include "util/cli_conventions.h"
#include "util/file_io.h"
#include "util/status_macros.h"

namespace motiondb::cli {
namespace {

using Stub = v1::EditService::Stub;

// --- reconstruct ---------------------------------------------------------------------------

struct ReconstructFlags {
  OpOutputFlags output;
  std::string clip;
  std::optional<int> dims;
  bool curve = false;
};

absl::Status Reconstruct(const ReconstructFlags& flags, bool json,
                         const ServerConnection& connection) {
  v1::ReconstructRequest request;
  request.set_space(flags.output.space);
  MOTIONDB_ASSIGN_OR_RETURN(*request.mutable_clip(), ParseClipRange(flags.clip));
  if (flags.dims) request.set_dims(*flags.dims);
  request.set_error_curve(flags.curve);
  SetOutput(flags.output, request.mutable_output());
  MOTIONDB_ASSIGN_OR_RETURN(const v1::ReconstructResponse response,
                            CallUnary(connection, &Stub::Reconstruct, request,
                                      OpFlagNames({{"dims", "--dims"}}, {{"clip", flags.clip}})));
  nlohmann::json joints = nlohmann::json::array(), curve = nlohmann::json::array();
  for (const v1::JointError& joint : response.joints()) {
    joints.push_back(
        {{"joint", joint.joint()}, {"mean_rad", joint.mean_rad()}, {"max_rad", joint.max_rad()}});
  }
  for (const v1::ReconstructionError& level : response.curve()) {
    curve.push_back(
        {{"dims", level.dims()}, {"mean_rad", level.mean_rad()}, {"max_rad", level.max_rad()}});
  }
  return ReportResult(response.result(), flags.output, json,
                      {{"dims", response.dims()},
                       {"mean_rad", response.mean_rad()},
                       {"max_rad", response.max_rad()},
                       {"joints", joints},
                       {"curve", curve}},
                      [&] {
                        absl::PrintF(
                            "reconstructed from %d dimensions: error %.4f rad mean, %.4f rad max\n",
                            response.dims(), response.mean_rad(), response.max_rad());
                        for (const v1::JointError& joint : response.joints()) {
                          absl::PrintF("  %-24s %.4f mean  %.4f max\n", joint.joint(),
                                       joint.mean_rad(), joint.max_rad());
                        }
                        for (const v1::ReconstructionError& level : response.curve()) {
                          absl::PrintF("  n = %3d: %.4f mean  %.4f max\n", level.dims(),
                                       level.mean_rad(), level.max_rad());
                        }
                      });
}

void AddReconstruct(Commands& commands, CLI::App* op) {
  auto flags = std::make_shared<ReconstructFlags>();
  const GlobalOptions& global = commands.global();
  CLI::App* command = commands.AddServer(
      op, "reconstruct", "rebuild a clip from its first n dimensions, with the error (3.3.4)",
      [flags, &global](const ServerConnection& c) { return Reconstruct(*flags, global.json, c); });
  AddClipArgument(command, "CLIP", &flags->clip, kOpClipHelp);
  AddOpOutputFlags(command, &flags->output);
  command->add_option("--dims", flags->dims, "dimensions kept (default: all)")
      ->type_name("N")
      ->check(WholeAtLeast(1));
  command->add_flag("--curve", flags->curve, "also the error for every number of dimensions");
}

// --- interpolate ---------------------------------------------------------------------------

struct InterpolateFlags {
  OpOutputFlags output;
  std::string from, to;
  std::vector<double> t;
  std::optional<int> steps, dims;
  std::string method = "mc-lerp";
  std::string other_out;
};

absl::Status Interpolate(const InterpolateFlags& flags, bool json,
                         const ServerConnection& connection) {
  v1::InterpolateRequest request;
  request.set_space(flags.output.space);
  MOTIONDB_ASSIGN_OR_RETURN(*request.mutable_from(), ParseClipRange(flags.from));
  MOTIONDB_ASSIGN_OR_RETURN(*request.mutable_to(), ParseClipRange(flags.to));
  for (const double t : flags.t) request.add_t(t);
  if (flags.steps) request.set_steps(*flags.steps);
  if (flags.dims) request.set_dims(*flags.dims);
  request.set_method(flags.method == "slerp" ? v1::INTERPOLATION_METHOD_SLERP
                                             : v1::INTERPOLATION_METHOD_MC_LERP);
  SetOutput(flags.output, request.mutable_output());
  MOTIONDB_ASSIGN_OR_RETURN(
      const v1::InterpolateResponse response,
      CallUnary(connection, &Stub::Interpolate, request,
                OpFlagNames({{"t", "--t"}, {"steps", "--steps"}, {"dims", "--dims"}},
                            {{"from", flags.from}, {"to", flags.to}})));
  if (!flags.other_out.empty()) {
    MOTIONDB_RETURN_IF_ERROR(WriteFileAtomically(flags.other_out, response.other_bvh()));
  }
  nlohmann::json steps = nlohmann::json::array();
  for (const v1::InterpolationStep& step : response.steps()) {
    steps.push_back({{"t", step.t()},
                     {"mean_rad", step.mean_rad()},
                     {"max_rad", step.max_rad()},
                     {"curve_distance", step.curve_distance()}});
  }
  return ReportResult(response.result(), flags.output, json,
                      {{"method", flags.method},
                       {"steps", steps},
                       {"mean_rad", response.mean_rad()},
                       {"max_rad", response.max_rad()}},
                      [&] {
                        absl::PrintF("MC-LERP vs SLERP: %.4f rad mean, %.4f rad max\n",
                                     response.mean_rad(), response.max_rad());
                        for (const v1::InterpolationStep& step : response.steps()) {
                          absl::PrintF("  t = %.3f: %.4f mean  %.4f max  curve distance %.4f\n",
                                       step.t(), step.mean_rad(), step.max_rad(),
                                       step.curve_distance());
                        }
                      });
}

void AddInterpolate(Commands& commands, CLI::App* op) {
  auto flags = std::make_shared<InterpolateFlags>();
  const GlobalOptions& global = commands.global();
  CLI::App* command = commands.AddServer(
      op, "interpolate", "two poses by MC-LERP and per-joint SLERP, and their difference (4.1)",
      [flags, &global](const ServerConnection& c) { return Interpolate(*flags, global.json, c); });
  AddClipArgument(command, "FROM", &flags->from, kOpPoseHelp);
  AddClipArgument(command, "TO", &flags->to, kOpPoseHelp);
  AddOpOutputFlags(command, &flags->output);
  command->add_option("--t", flags->t, "the parameters, each 0..1 (default: --steps of them)")
      ->type_name("T,...")
      ->delimiter(',');
  command->add_option("--steps", flags->steps, "evenly spaced t from 0 to 1 (default 11)")
      ->type_name("N");
  command->add_option("--dims", flags->dims, "dimensions MC-LERP uses (default: all)")
      ->type_name("N");
  OneOf(command->add_option("--method", flags->method, "the result's method"), {"mc-lerp", "slerp"})
      ->capture_default_str();
  command->add_option("--other-out", flags->other_out, "write the other method's poses as BVH")
      ->type_name("FILE.bvh");
}

// --- blend ---------------------------------------------------------------------------------

struct BlendFlags {
  OpOutputFlags output;
  std::vector<std::string> poses;  // ID:FRAME@X,Y
  std::vector<std::string> path;   // X,Y
  std::optional<int> frames_per_segment;
  std::optional<double> epsilon;
};

absl::Status Blend(const BlendFlags& flags, bool json, const ServerConnection& connection) {
  v1::BlendRequest request;
  request.set_space(flags.output.space);
  for (const std::string& spec : flags.poses) {
    const size_t at = spec.find('@');
    if (at == std::string::npos) {
      return absl::InvalidArgumentError(
          absl::StrCat("--pose: expected ID:FRAME@X,Y, got '", spec, "'"));
    }
    v1::PlanarPose* pose = request.add_poses();
    MOTIONDB_ASSIGN_OR_RETURN(*pose->mutable_pose(), ParseClipRange(spec.substr(0, at)));
    MOTIONDB_ASSIGN_OR_RETURN(const auto point, ParsePoint(spec.substr(at + 1), "--pose"));
    pose->set_x(point.first);
    pose->set_y(point.second);
  }
  for (const std::string& text : flags.path) {
    MOTIONDB_ASSIGN_OR_RETURN(const auto point, ParsePoint(text, "--path"));
    v1::PlanePoint* out = request.add_path();
    out->set_x(point.first);
    out->set_y(point.second);
  }
  if (flags.frames_per_segment) request.set_frames_per_segment(*flags.frames_per_segment);
  if (flags.epsilon) request.set_epsilon(*flags.epsilon);
  SetOutput(flags.output, request.mutable_output());
  FlagNames ranges;
  for (size_t i = 0; i < flags.poses.size(); ++i) {
    ranges.push_back({absl::StrCat("poses[", i, "].pose"), flags.poses[i]});
  }
  MOTIONDB_ASSIGN_OR_RETURN(const v1::BlendResponse response,
                            CallUnary(connection, &Stub::Blend, request,
                                      OpFlagNames({{"poses", "--pose"},
                                                   {"path", "--path"},
                                                   {"frames_per_segment", "--frames-per-segment"},
                                                   {"epsilon", "--epsilon"}},
                                                  ranges)));
  nlohmann::json weights = nlohmann::json::array();
  for (const v1::BlendWeights& frame : response.frames()) {
    weights.push_back(std::vector<double>(frame.weights().begin(), frame.weights().end()));
  }
  return ReportResult(response.result(), flags.output, json, {{"weights", weights}}, [&] {
    constexpr int kShown = 10;  // --json has them all
    for (int k = 0; k < response.frames_size() && k < kShown; ++k) {
      std::string row;
      for (const double w : response.frames(k).weights()) absl::StrAppendFormat(&row, " %.3f", w);
      absl::PrintF("  frame %d weights:%s\n", k, row);
    }
    if (response.frames_size() > kShown) {
      absl::PrintF("  ... %d frames more (--json lists every frame's)\n",
                   response.frames_size() - kShown);
    }
  });
}

void AddBlend(Commands& commands, CLI::App* op) {
  auto flags = std::make_shared<BlendFlags>();
  const GlobalOptions& global = commands.global();
  CLI::App* command = commands.AddServer(
      op, "blend", "poses placed on a plane, blended along a path of points (4.2)",
      [flags, &global](const ServerConnection& c) { return Blend(*flags, global.json, c); });
  AddOpOutputFlags(command, &flags->output);
  command->add_option("--pose", flags->poses, "a pose and its place on the plane; repeat")
      ->type_name("ID:FRAME@X,Y")
      ->allow_extra_args(false)
      ->required();
  command->add_option("--path", flags->path, "a point of the path, a frame each; repeat")
      ->type_name("X,Y")
      ->allow_extra_args(false)
      ->required();
  command
      ->add_option("--frames-per-segment", flags->frames_per_segment,
                   "frames from each path point to the next (default 1)")
      ->type_name("N");
  command->add_option("--epsilon", flags->epsilon, "eq. 4.2's epsilon (default 1e-6)")
      ->type_name("E");
}

}  // namespace

void AddOpCommands(Commands& commands) {
  CLI::App* op = commands.AddGroup(
      commands.root(), "op",
      "the Motion Curve operators on stored clips: reconstruct, interpolate, blend, fill-gap, "
      "scale, translate, smooth, detect");
  AddReconstruct(commands, op);
  AddInterpolate(commands, op);
  AddBlend(commands, op);
  AddOpEditCommands(commands, op);
  AddOpDetect(commands, op);
}

}  // namespace motiondb::cli
