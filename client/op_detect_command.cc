// motiondb op detect fit NAME --space S --example CLIP... | run MODEL CLIP | list | delete NAME:
// pose detection (thesis 3.4) through EditService's pose models.
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "absl/strings/ascii.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/strip.h"
#include "client/clip_range_arg.h"
#include "client/commands.h"
#include "client/op_flags.h"
#include "client/server_connection.h"
#include "motiondb/v1/edit_service.grpc.pb.h"
#include "util/byte_coding.h"
#include "util/cli_conventions.h"
#include "util/status_macros.h"

namespace motiondb::cli {
namespace {

using Stub = v1::EditService::Stub;

struct FitFlags {
  std::string name, space;
  std::vector<std::string> examples;
  std::optional<int> components, dims, max_iterations;
  std::optional<uint64_t> seed;
  std::optional<double> quantile;
  std::string covariance = "full";
};

// "full", "diagonal" or "spherical", as --covariance takes them.
std::string CovarianceName(v1::CovarianceType type) {
  return absl::AsciiStrToLower(
      absl::StripPrefix(v1::CovarianceType_Name(type), "COVARIANCE_TYPE_"));
}

nlohmann::json ModelJson(const v1::PoseModel& model) {
  return {{"name", model.name()},
          {"space", model.space()},
          {"dims", model.dims()},
          {"components", model.components()},
          {"covariance", CovarianceName(model.covariance())},
          {"threshold", model.threshold()},
          {"log_likelihood", model.log_likelihood()},
          {"iterations", model.iterations()}};
}

void PrintModel(const v1::PoseModel& model) {
  absl::PrintF(
      "pose model %s (space %s): %d Gaussians, %s covariance, %d dims; threshold %.3f, "
      "mean log-likelihood %.3f after %d EM iterations\n",
      model.name(), model.space(), model.components(), CovarianceName(model.covariance()),
      model.dims(), model.threshold(), model.log_likelihood(), model.iterations());
}

absl::Status Fit(const FitFlags& flags, bool json, const ServerConnection& connection) {
  v1::CreatePoseModelRequest request;
  request.set_name(flags.name);
  request.set_space(flags.space);
  FlagNames names = {{"components", "--components"},
                     {"dims", "--dims"},
                     {"threshold_quantile", "--quantile"},
                     {"max_iterations", "--iterations"},
                     {"examples", "--example"}};
  for (size_t i = 0; i < flags.examples.size(); ++i) {
    MOTIONDB_ASSIGN_OR_RETURN(*request.add_examples(), ParseClipRange(flags.examples[i]));
    names.push_back({absl::StrCat("examples[", i, "]"), "--example " + flags.examples[i]});
  }
  if (flags.components) request.set_components(*flags.components);
  if (flags.dims) request.set_dims(*flags.dims);
  if (flags.seed) request.set_seed(*flags.seed);
  if (flags.quantile) request.set_threshold_quantile(*flags.quantile);
  if (flags.max_iterations) request.set_max_iterations(*flags.max_iterations);
  v1::CovarianceType type = v1::COVARIANCE_TYPE_FULL;
  v1::CovarianceType_Parse("COVARIANCE_TYPE_" + absl::AsciiStrToUpper(flags.covariance), &type);
  request.set_covariance(type);
  MOTIONDB_ASSIGN_OR_RETURN(const v1::PoseModel model,
                            CallUnary(connection, &Stub::CreatePoseModel, request, names));
  if (json) {
    std::cout << ModelJson(model).dump() << "\n";
  } else {
    PrintModel(model);
  }
  return absl::OkStatus();
}

struct RunFlags {
  std::string model, clip;
  std::optional<double> threshold;
  double min_duration_s = 0;
  bool curve = false;
};

absl::Status Run(const RunFlags& flags, bool json, const ServerConnection& connection) {
  v1::DetectPoseRequest request;
  request.set_model(flags.model);
  MOTIONDB_ASSIGN_OR_RETURN(*request.mutable_clip(), ParseClipRange(flags.clip));
  if (flags.threshold) request.set_threshold(*flags.threshold);
  request.set_min_duration_s(flags.min_duration_s);
  MOTIONDB_ASSIGN_OR_RETURN(const v1::DetectPoseResponse response,
                            CallUnary(connection, &Stub::DetectPose, request,
                                      {{"clip.first_frame", flags.clip + ": frame"},
                                       {"clip.last_frame", flags.clip + ": frame"},
                                       {"threshold", "--threshold"},
                                       {"min_duration_s", "--min-duration"}}));
  std::vector<float> curve(response.log_likelihood().size() / sizeof(float));
  ReadFloat32s(response.log_likelihood(), curve.size(), curve.data());
  if (json) {
    nlohmann::json intervals = nlohmann::json::array();
    for (const v1::DetectedInterval& i : response.intervals()) {
      intervals.push_back({{"first_frame", i.first_frame()},
                           {"last_frame", i.last_frame()},
                           {"start_s", i.start_s()},
                           {"end_s", i.end_s()},
                           {"peak_frame", i.peak_frame()},
                           {"peak", i.peak()}});
    }
    nlohmann::json out = {{"threshold", response.threshold()}, {"intervals", intervals}};
    if (flags.curve) {
      out["sample_rate"] = response.sample_rate();
      out["log_likelihood"] = curve;
    }
    std::cout << out.dump() << "\n";
    return absl::OkStatus();
  }
  absl::PrintF("%d intervals at or above %.3f in frames %d-%d\n", response.intervals_size(),
               response.threshold(), response.first_frame(), response.last_frame());
  for (const v1::DetectedInterval& i : response.intervals()) {
    absl::PrintF("  frames %d-%d (%.3f-%.3f s), peak %.3f at frame %d\n", i.first_frame(),
                 i.last_frame(), i.start_s(), i.end_s(), i.peak(), i.peak_frame());
  }
  if (flags.curve) {
    for (size_t k = 0; k < curve.size(); ++k) {
      absl::PrintF("%.4f %.4f\n", k / response.sample_rate(), curve[k]);
    }
  }
  return absl::OkStatus();
}

absl::Status ListPoseModels(const std::string& space, bool json,
                            const ServerConnection& connection) {
  v1::ListPoseModelsRequest request;
  request.set_space(space);
  MOTIONDB_ASSIGN_OR_RETURN(const v1::ListPoseModelsResponse response,
                            CallUnary(connection, &Stub::ListPoseModels, request));
  if (json) {
    nlohmann::json models = nlohmann::json::array();
    for (const v1::PoseModel& model : response.models()) models.push_back(ModelJson(model));
    std::cout << nlohmann::json{{"models", models}}.dump() << "\n";
  } else {
    for (const v1::PoseModel& model : response.models()) PrintModel(model);
  }
  return absl::OkStatus();
}

absl::Status DeletePoseModel(const std::string& name, bool json,
                             const ServerConnection& connection) {
  v1::DeletePoseModelRequest request;
  request.set_name(name);
  MOTIONDB_RETURN_IF_ERROR(CallUnary(connection, &Stub::DeletePoseModel, request).status());
  if (json) {
    std::cout << nlohmann::json{{"deleted", name}}.dump() << "\n";
  } else {
    absl::PrintF("deleted pose model %s\n", name);
  }
  return absl::OkStatus();
}

void AddFit(Commands& commands, CLI::App* detect) {
  auto flags = std::make_shared<FitFlags>();
  const GlobalOptions& global = commands.global();
  CLI::App* fit = commands.AddServer(
      detect, "fit", "fit a Mixture of Gaussians to example poses and keep it by name",
      [flags, &global](const ServerConnection& c) { return Fit(*flags, global.json, c); });
  fit->add_option("NAME", flags->name, "the model's name")->required();
  fit->add_option("--space", flags->space, "the space")->type_name("NAME")->required();
  fit->add_option("--example", flags->examples,
                  "example poses: ID:FRAME or every frame of ID:FROM-TO; repeat")
      ->type_name("CLIP")
      ->allow_extra_args(false)
      ->required()
      ->check(ClipRangeCheck());
  fit->add_option("--components", flags->components, "Gaussians (default 2)")->type_name("K");
  OneOf(fit->add_option("--covariance", flags->covariance, "the covariances' shape"),
        {"full", "diagonal", "spherical"})
      ->capture_default_str();
  fit->add_option("--dims", flags->dims, "the truncation (default 3)")->type_name("N");
  fit->add_option("--seed", flags->seed, "seeds the fit (default 1)")->type_name("N");
  fit->add_option(
         "--quantile", flags->quantile,
         "the default threshold: this quantile of the examples' held-out scores (default 0)")
      ->type_name("Q");
  fit->add_option("--iterations", flags->max_iterations, "EM iterations at most (default 200)")
      ->type_name("N");
}

void AddRun(Commands& commands, CLI::App* detect) {
  auto flags = std::make_shared<RunFlags>();
  const GlobalOptions& global = commands.global();
  CLI::App* run = commands.AddServer(
      detect, "run", "where a clip assumes a model's pose: its log-likelihood and intervals",
      [flags, &global](const ServerConnection& c) { return Run(*flags, global.json, c); });
  run->add_option("MODEL", flags->model, "the model's name")->required();
  AddClipArgument(run, "CLIP", &flags->clip, kOpClipHelp);
  run->add_option("--threshold", flags->threshold, "log-likelihood to reach (default: the model's)")
      ->type_name("T");
  run->add_option("--min-duration", flags->min_duration_s, "shortest interval, seconds")
      ->type_name("S")
      ->capture_default_str();
  run->add_flag("--curve", flags->curve, "also the log-likelihood at every sample");
}

}  // namespace

void AddOpDetect(Commands& commands, CLI::App* op) {
  CLI::App* detect =
      commands.AddGroup(op, "detect", "pose detection (3.4): fit, run, list, delete models");
  AddFit(commands, detect);
  AddRun(commands, detect);
  const GlobalOptions& global = commands.global();
  auto space = std::make_shared<std::string>();
  CLI::App* list = commands.AddServer(detect, "list", "the pose models",
                                      [space, &global](const ServerConnection& c) {
                                        return ListPoseModels(*space, global.json, c);
                                      });
  list->add_option("--space", *space, "only this space's")->type_name("NAME");
  auto name = std::make_shared<std::string>();
  commands
      .AddServer(detect, "delete", "delete a pose model",
                 [name, &global](const ServerConnection& c) {
                   return DeletePoseModel(*name, global.json, c);
                 })
      ->add_option("NAME", *name, "the model's name")
      ->required();
}

}  // namespace motiondb::cli
