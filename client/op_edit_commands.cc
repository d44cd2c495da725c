// motiondb op fill-gap | scale | translate | smooth: transitions and curve edits of EditService
// (issue 16), the edits under a gate, on chosen dimensions, with joint limits and freezes.
#include <memory>
#include <optional>
#include <string>

#include "absl/strings/str_format.h"
#include "client/clip_range_arg.h"
#include "client/commands.h"
#include "client/op_flags.h"
#include "client/server_connection.h"
#include "motiondb/v1/edit_service.grpc.pb.h"
#include "util/cli_conventions.h"
#include "util/status_macros.h"

namespace motiondb::cli {
namespace {

using Stub = v1::EditService::Stub;

// --- fill-gap ------------------------------------------------------------------------------

struct FillGapFlags {
  OpOutputFlags output;
  std::string first, second;
  std::optional<double> gap_s, damping;
  std::optional<int> slope_limit;
  double overlap_s = 0, smoothing = 0;
  std::string method = "hermite";
  bool no_align = false;
};

absl::Status FillGap(const FillGapFlags& flags, bool json, const ServerConnection& connection) {
  v1::FillGapRequest request;
  request.set_space(flags.output.space);
  MOTIONDB_ASSIGN_OR_RETURN(*request.mutable_first(), ParseClipRange(flags.first));
  MOTIONDB_ASSIGN_OR_RETURN(*request.mutable_second(), ParseClipRange(flags.second));
  if (flags.gap_s) request.set_gap_s(*flags.gap_s);
  if (flags.damping) request.set_damping(*flags.damping);
  request.set_method(flags.method == "linear" ? v1::GAP_METHOD_LINEAR : v1::GAP_METHOD_HERMITE);
  request.set_derivative_smoothing(flags.smoothing);
  request.set_overlap_s(flags.overlap_s);
  request.set_no_align(flags.no_align);
  if (flags.slope_limit) request.set_slope_limit(*flags.slope_limit);
  SetOutput(flags.output, request.mutable_output());
  MOTIONDB_ASSIGN_OR_RETURN(
      const v1::FillGapResponse response,
      CallUnary(connection, &Stub::FillGap, request,
                OpFlagNames({{"gap_s", "--gap"},
                             {"overlap_s", "--overlap"},
                             {"damping", "--damping"},
                             {"derivative_smoothing", "--derivative-smoothing"},
                             {"slope_limit", "--slope-limit"}},
                            {{"first", flags.first}, {"second", flags.second}})));
  nlohmann::json seams = nlohmann::json::array();
  for (const v1::SeamJump& seam : response.seams()) {
    seams.push_back({{"mean_rad_s", seam.mean_rad_s()},
                     {"max_rad_s", seam.max_rad_s()},
                     {"linear_mean_rad_s", seam.linear_mean_rad_s()},
                     {"linear_max_rad_s", seam.linear_max_rad_s()}});
  }
  return ReportResult(
      response.result(), flags.output, json,
      {{"transition_frames", response.transition_frames()},
       {"seams", seams},
       {"warp_score", response.warp_score()}},
      [&] {
        if (flags.overlap_s > 0) {
          absl::PrintF("overlap of %d frames blended, warp score %.4f\n",
                       response.transition_frames(), response.warp_score());
        }
        for (int i = 0; i < response.seams_size(); ++i) {
          const v1::SeamJump& seam = response.seams(i);
          absl::PrintF(
              "seam %d: joint-velocity jump %.3f rad/s mean, %.3f max (linear: %.3f, %.3f)\n",
              i + 1, seam.mean_rad_s(), seam.max_rad_s(), seam.linear_mean_rad_s(),
              seam.linear_max_rad_s());
        }
      });
}

void AddFillGap(Commands& commands, CLI::App* op) {
  auto flags = std::make_shared<FillGapFlags>();
  const GlobalOptions& global = commands.global();
  CLI::App* command = commands.AddServer(
      op, "fill-gap",
      "join two clips: Hermite interpolation across a gap (4.3), or a time-aligned blend of an "
      "overlap",
      [flags, &global](const ServerConnection& c) { return FillGap(*flags, global.json, c); });
  AddClipArgument(command, "FIRST", &flags->first, kOpClipHelp);
  AddClipArgument(command, "SECOND", &flags->second, kOpClipHelp);
  AddOpOutputFlags(command, &flags->output);
  command->add_option("--gap", flags->gap_s, "seconds between the clips (default 0.5)")
      ->type_name("S");
  OneOf(command->add_option("--method", flags->method, "across the gap"), {"hermite", "linear"})
      ->capture_default_str();
  command->add_option("--damping", flags->damping, "v of eq. 4.4, 0..1 (default 1)")
      ->type_name("V");
  command
      ->add_option("--derivative-smoothing", flags->smoothing,
                   "Haar level smoothing the clips before their end velocities are taken")
      ->type_name("L")
      ->capture_default_str();
  command
      ->add_option("--overlap", flags->overlap_s,
                   "instead: SECOND overlaps FIRST's end by S seconds, blended after a time warp")
      ->type_name("S");
  command->add_flag("--no-align", flags->no_align, "blend the overlap frame for frame");
  command
      ->add_option("--slope-limit", flags->slope_limit,
                   "the overlap's time warp: the most frames of one clip to a frame of the other, "
                   "1..8 (default 2)")
      ->type_name("N");
}

// --- scale, translate, smooth ----------------------------------------------------------------

struct CurveFlags {
  OpOutputFlags output;
  std::string clip;
  ScopeFlags scope;
};

// Fills the fields every curve edit request has.
template <typename Request>
absl::Status SetCurveEdit(const CurveFlags& flags, Request* request) {
  request->set_space(flags.output.space);
  MOTIONDB_ASSIGN_OR_RETURN(*request->mutable_clip(), ParseClipRange(flags.clip));
  MOTIONDB_RETURN_IF_ERROR(
      SetScope(flags.scope, request->mutable_scope(), request->mutable_constraints()));
  SetOutput(flags.output, request->mutable_output());
  return absl::OkStatus();
}

CLI::App* AddCurveCommand(Commands& commands, CLI::App* op, const std::string& name,
                          const std::string& description, CurveFlags* flags,
                          std::function<absl::Status(const ServerConnection&)> body) {
  CLI::App* command = commands.AddServer(op, name, description, std::move(body));
  AddClipArgument(command, "CLIP", &flags->clip, kOpClipHelp);
  AddOpOutputFlags(command, &flags->output);
  AddScopeFlags(command, &flags->scope);
  return command;
}

absl::Status ReportEdit(const v1::EditResponse& response, const CurveFlags& flags, bool json) {
  return ReportResult(response.result(), flags.output, json, nlohmann::json::object(), [] {});
}

struct ScaleFlags {
  CurveFlags curve;
  std::optional<double> factor;
  std::string about = "origin";
  std::vector<double> sigmoid;  // THRESHOLD,WIDTH
};

absl::Status Scale(const ScaleFlags& flags, bool json, const ServerConnection& connection) {
  v1::ScaleRequest request;
  MOTIONDB_RETURN_IF_ERROR(SetCurveEdit(flags.curve, &request));
  if (flags.factor) request.set_factor(*flags.factor);
  request.set_centre(flags.about == "mean" ? v1::SCALE_CENTRE_SELECTION_MEAN
                                           : v1::SCALE_CENTRE_ORIGIN);
  if (!flags.sigmoid.empty()) {
    request.mutable_sigmoid()->set_threshold(flags.sigmoid[0]);
    request.mutable_sigmoid()->set_width(flags.sigmoid[1]);
  }
  MOTIONDB_ASSIGN_OR_RETURN(
      const v1::EditResponse response,
      CallUnary(connection, &Stub::Scale, request,
                OpFlagNames({{"factor", "--factor"},
                             {"sigmoid.threshold", "--sigmoid THRESHOLD"},
                             {"sigmoid.width", "--sigmoid WIDTH"}},
                            {{"clip", flags.curve.clip}}, &flags.curve.scope)));
  return ReportEdit(response, flags.curve, json);
}

struct TranslateFlags {
  CurveFlags curve;
  std::string toward, axis_from, axis_to;
  std::optional<double> amount;
};

absl::Status Translate(const TranslateFlags& flags, bool json, const ServerConnection& connection) {
  v1::TranslateRequest request;
  MOTIONDB_RETURN_IF_ERROR(SetCurveEdit(flags.curve, &request));
  if (!flags.toward.empty()) {
    MOTIONDB_ASSIGN_OR_RETURN(*request.mutable_target(), ParseClipRange(flags.toward));
  }
  if (!flags.axis_from.empty()) {
    MOTIONDB_ASSIGN_OR_RETURN(*request.mutable_axis_from(), ParseClipRange(flags.axis_from));
  }
  if (!flags.axis_to.empty()) {
    MOTIONDB_ASSIGN_OR_RETURN(*request.mutable_axis_to(), ParseClipRange(flags.axis_to));
  }
  if (flags.amount) request.set_amount(*flags.amount);
  MOTIONDB_ASSIGN_OR_RETURN(const v1::EditResponse response,
                            CallUnary(connection, &Stub::Translate, request,
                                      OpFlagNames({{"target", "--toward"},
                                                   {"axis_from", "--axis-from"},
                                                   {"axis_to", "--axis-to"},
                                                   {"amount", "--amount"}},
                                                  {{"clip", flags.curve.clip},
                                                   {"target", flags.toward},
                                                   {"axis_from", flags.axis_from},
                                                   {"axis_to", flags.axis_to}},
                                                  &flags.curve.scope)));
  return ReportEdit(response, flags.curve, json);
}

struct SmoothFlags {
  CurveFlags curve;
  std::optional<double> level;
};

absl::Status Smooth(const SmoothFlags& flags, bool json, const ServerConnection& connection) {
  v1::SmoothRequest request;
  MOTIONDB_RETURN_IF_ERROR(SetCurveEdit(flags.curve, &request));
  if (flags.level) request.set_level(*flags.level);
  MOTIONDB_ASSIGN_OR_RETURN(
      const v1::EditResponse response,
      CallUnary(
          connection, &Stub::Smooth, request,
          OpFlagNames({{"level", "--level"}}, {{"clip", flags.curve.clip}}, &flags.curve.scope)));
  return ReportEdit(response, flags.curve, json);
}

}  // namespace

void AddOpEditCommands(Commands& commands, CLI::App* op) {
  const GlobalOptions& global = commands.global();
  AddFillGap(commands, op);

  auto scale = std::make_shared<ScaleFlags>();
  CLI::App* scaler = AddCurveCommand(
      commands, op, "scale", "exaggerate or subdue a clip by scaling its curve (5.3)",
      &scale->curve,
      [scale, &global](const ServerConnection& c) { return Scale(*scale, global.json, c); });
  scaler->add_option("--factor", scale->factor, "> 1 exaggerates, < 1 subdues (default 1.5)")
      ->type_name("F");
  OneOf(scaler->add_option("--about", scale->about,
                           "the centre: the space's origin, or the "
                           "gated selection's mean"),
        {"origin", "mean"})
      ->capture_default_str();
  scaler
      ->add_option("--sigmoid", scale->sigmoid,
                   "scale only poses farther than THRESHOLD from the centre (S(d))")
      ->type_name("THRESHOLD,WIDTH")
      ->delimiter(',')
      ->expected(2);

  auto translate = std::make_shared<TranslateFlags>();
  CLI::App* mover = AddCurveCommand(
      commands, op, "translate",
      "move a clip's curve toward a pose, or along the axis between two poses (5.4)",
      &translate->curve, [translate, &global](const ServerConnection& c) {
        return Translate(*translate, global.json, c);
      });
  mover->add_option("--toward", translate->toward, kOpPoseHelp)->type_name("POSE");
  mover->add_option("--axis-from", translate->axis_from, kOpPoseHelp)->type_name("POSE");
  mover->add_option("--axis-to", translate->axis_to, kOpPoseHelp)->type_name("POSE");
  mover
      ->add_option("--amount", translate->amount,
                   "1 takes the mean onto the pose, or moves by the whole axis (default 0.5)")
      ->type_name("A");

  auto smooth = std::make_shared<SmoothFlags>();
  CLI::App* smoother = AddCurveCommand(
      commands, op, "smooth", "Haar-wavelet smoothing of a clip's curve (5.5.1)", &smooth->curve,
      [smooth, &global](const ServerConnection& c) { return Smooth(*smooth, global.json, c); });
  smoother->add_option("--level", smooth->level, "levels of detail removed, 0..64 (default 1)")
      ->type_name("L");
}

}  // namespace motiondb::cli
