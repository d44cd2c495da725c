#include "client/op_flags.h"

#include <cmath>
#include <iostream>
#include <tuple>
#include <utility>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_split.h"
#include "client/clip_range_arg.h"
#include "util/cli_conventions.h"
#include "util/file_io.h"
#include "util/status_macros.h"

namespace motiondb::cli {
namespace {

absl::Status AddJointValues(const std::vector<std::string>& texts, const std::string& flag,
                            google::protobuf::Map<std::string, double>* values) {
  for (const std::string& text : texts) {
    MOTIONDB_ASSIGN_OR_RETURN(const auto joint_value, ParseJointValue(text, flag));
    (*values)[joint_value.first] = joint_value.second;
  }
  return absl::OkStatus();
}

}  // namespace

void AddClipArgument(CLI::App* command, const std::string& name, std::string* spec,
                     const std::string& help) {
  command->add_option(name, *spec, help)->required()->check(ClipRangeCheck());
}

void AddOpOutputFlags(CLI::App* command, OpOutputFlags* flags) {
  command->add_option("--space", flags->space, "the space to work in")
      ->type_name("NAME")
      ->required();
  command->add_option("-o,--out", flags->out, "write the result as BVH ('-': standard output)")
      ->type_name("OUT.bvh");
  command->add_option("--store", flags->store, "keep the result as a clip of this name")
      ->type_name("NAME");
  command->add_option("--tag", flags->tags, "a tag of the stored clip; repeat for more")
      ->type_name("T")
      ->allow_extra_args(false);
}

void SetOutput(const OpOutputFlags& flags, v1::EditOutput* output) {
  output->set_store_name(flags.store);
  for (const std::string& tag : flags.tags) output->add_store_tags(tag);
}

void AddScopeFlags(CLI::App* command, ScopeFlags* flags) {
  const std::string group = "Where the edit applies (thesis fig. 5.2, 5.7)";
  command->add_option("--gate", flags->gate, "edit only from T0 to T1 s (of the clip's time)")
      ->type_name("T0,T1")
      ->delimiter(',')
      ->expected(2)
      ->group(group);
  command->add_option("--lead-in", flags->lead_in, "seconds the gate ramps up before T0")
      ->type_name("S")
      ->check(NumberAtLeast(0))
      ->capture_default_str()
      ->group(group);
  command->add_option("--lead-out", flags->lead_out, "seconds the gate ramps down after T1")
      ->type_name("S")
      ->check(NumberAtLeast(0))
      ->capture_default_str()
      ->group(group);
  command->add_option("--only-dims", flags->dims, "change only these dimensions (from 0)")
      ->type_name("D,...")
      ->delimiter(',')
      ->group(group);
  command->add_option("--freeze", flags->freeze, "keep this joint as in the source; repeatable")
      ->type_name("JOINT")
      ->allow_extra_args(false)
      ->group(group);
  command
      ->add_option("--joint-weight", flags->joint_weights,
                   "the share of the edit a joint takes, 0..1; repeatable")
      ->type_name("JOINT=W")
      ->allow_extra_args(false)
      ->group(group);
  command
      ->add_option("--max-angle", flags->max_angles,
                   "the most a joint may turn from the space's mean for it, radians; repeatable")
      ->type_name("JOINT=RAD")
      ->allow_extra_args(false)
      ->group(group);
  command
      ->add_option("--limit-from-source", flags->limit_margin,
                   "limit every other joint to (1 + M) x the largest turn the source makes")
      ->type_name("M")
      ->check(NumberAtLeast(0))
      ->group(group);
}

absl::Status SetScope(const ScopeFlags& flags, v1::EditScope* scope,
                      v1::JointConstraints* constraints) {
  if (!flags.gate.empty()) {
    v1::Gate* gate = scope->mutable_gate();
    gate->set_start_s(flags.gate[0]);
    gate->set_end_s(flags.gate[1]);
    gate->set_lead_in_s(flags.lead_in);
    gate->set_lead_out_s(flags.lead_out);
  } else if (flags.lead_in > 0 || flags.lead_out > 0) {
    return absl::InvalidArgumentError("--lead-in and --lead-out shape a --gate; give one");
  }
  for (const int d : flags.dims) scope->add_dims(d);
  for (const std::string& joint : flags.freeze) (*constraints->mutable_edit_weights())[joint] = 0;
  MOTIONDB_RETURN_IF_ERROR(
      AddJointValues(flags.joint_weights, "--joint-weight", constraints->mutable_edit_weights()));
  MOTIONDB_RETURN_IF_ERROR(
      AddJointValues(flags.max_angles, "--max-angle", constraints->mutable_max_angles()));
  if (flags.limit_margin) constraints->set_source_margin(*flags.limit_margin);
  return absl::OkStatus();
}

FlagNames OpFlagNames(FlagNames more, const FlagNames& ranges, const ScopeFlags* scope) {
  FlagNames names = {{"scope.gate.start_s", "--gate T0"},
                     {"scope.gate.end_s", "--gate T1"},
                     {"scope.gate.lead_in_s", "--lead-in"},
                     {"scope.gate.lead_out_s", "--lead-out"},
                     {"scope.gate", "--gate"},
                     {"constraints.edit_weights", "--joint-weight"},
                     {"constraints.max_angles", "--max-angle"},
                     {"constraints.source_margin", "--limit-from-source"},
                     {"output.store_name", "--store"}};
  names.insert(names.end(), more.begin(), more.end());
  for (const auto& [field, spec] : ranges) {
    names.insert(names.end(), {{field + ".first_frame", spec + ": frame"},
                               {field + ".last_frame", spec + ": frame"}});
    // A plain word ("clip", "first") is prose too ("the clip's frames"); only an indexed field
    // stands for its argument alone.
    if (field.find('[') != std::string::npos) names.push_back({field, spec});
  }
  if (scope == nullptr) return names;
  for (size_t i = 0; i < scope->dims.size(); ++i) {
    names.push_back({absl::StrCat("scope.dims[", i, "]"), "--only-dims"});
  }
  // The server names a joint's constraint as constraints.edit_weights[JOINT] or
  // constraints.max_angles[JOINT].
  for (const std::string& joint : scope->freeze) {
    names.push_back({absl::StrCat("constraints.edit_weights[", joint, "]"), "--freeze " + joint});
  }
  for (const auto& [flag, field, texts] :
       {std::tuple{"--joint-weight", "constraints.edit_weights", &scope->joint_weights},
        std::tuple{"--max-angle", "constraints.max_angles", &scope->max_angles}}) {
    for (const std::string& text : *texts) {
      const std::string joint = text.substr(0, text.rfind('='));
      names.push_back({absl::StrCat(field, "[", joint, "]"), absl::StrCat(flag, " ", joint)});
    }
  }
  return names;
}

absl::StatusOr<std::pair<double, double>> ParsePoint(const std::string& text,
                                                     const std::string& what) {
  const std::vector<std::string> parts = absl::StrSplit(text, ',');
  double x = 0, y = 0;
  // SimpleAtod reads "nan" and "inf" too; a point of the plane is two finite numbers.
  if (parts.size() != 2 || !absl::SimpleAtod(parts[0], &x) || !absl::SimpleAtod(parts[1], &y) ||
      !std::isfinite(x) || !std::isfinite(y)) {
    return absl::InvalidArgumentError(
        absl::StrCat(what, ": expected X,Y (two finite numbers), got '", text, "'"));
  }
  return std::make_pair(x, y);
}

absl::Status ReportResult(const v1::EditResult& result, const OpOutputFlags& flags, bool json,
                          nlohmann::json extra, const std::function<void()>& print) {
  if (flags.out == "-") {
    std::cout << result.bvh();
    return absl::OkStatus();
  }
  if (!flags.out.empty()) MOTIONDB_RETURN_IF_ERROR(WriteFileAtomically(flags.out, result.bvh()));
  if (json) {
    extra["frames"] = result.frames();
    extra["fps"] = result.fps();
    if (!flags.out.empty()) extra["file"] = flags.out;
    if (result.has_stored()) {
      extra["stored"] = {{"clip_id", result.stored().clip_id()}, {"name", result.stored().name()}};
    }
    std::cout << extra.dump() << "\n";
    return absl::OkStatus();
  }
  absl::PrintF("%d frames at %g fps\n", result.frames(), result.fps());
  if (!flags.out.empty()) absl::PrintF("wrote %s\n", flags.out);
  if (result.has_stored()) {
    absl::PrintF("stored as clip %d '%s'\n", result.stored().clip_id(), result.stored().name());
  }
  print();
  return absl::OkStatus();
}

}  // namespace motiondb::cli
