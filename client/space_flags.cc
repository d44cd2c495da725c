#include "client/space_flags.h"

#include <filesystem>

#include "absl/strings/str_cat.h"
#include "core/space/motion_space.h"
#include "util/cli_conventions.h"

namespace motiondb::cli {

void AddSpaceFlags(CLI::App* command, SpaceFlags* flags) {
  const SpaceOptions defaults;
  command
      ->add_option(
          "--rate", flags->rate,
          absl::StrCat("sample rate of the clips in the space, in Hz, at most ", kMaxSpaceRate))
      ->type_name("R")
      ->default_str(absl::StrCat(defaults.sample_rate))
      ->check(NumberAbove(0));
  command->add_option("--weights", flags->weights, "joint weights: a preset, or a JSON file")
      ->type_name("mass|uniform|FILE.json")
      ->capture_default_str()
      ->check(CLI::Validator(
          [](const std::string& value) -> std::string {
            std::error_code error;
            if (IsWeightPreset(value) || std::filesystem::is_regular_file(value, error)) {
              return "";
            }
            return absl::StrCat("expected mass, uniform or a JSON file, got '", value, "'");
          },
          ""));
  command
      ->add_option("--yaw-rate-weight", flags->yaw_rate_weight,
                   "weight of the yaw-rate dimension (rad/s)")
      ->type_name("W")
      ->default_str(absl::StrCat(defaults.yaw_rate_weight))
      ->check(NumberAbove(0));
  command
      ->add_option("--root-velocity-weight", flags->root_velocity_weight,
                   "weight of the two root-velocity dimensions (leg lengths/s); 0: none")
      ->type_name("W")
      ->default_str(absl::StrCat(defaults.root_velocity_weight))
      ->check(NumberAtLeast(0));
  OneOf(command->add_option("--metric", flags->metric,
                            "distance: plain Euclidean, or scaled by eigenvalue"),
        {"unit", "eigen"})
      ->capture_default_str();
  command->add_flag("--keep-heading", flags->keep_heading,
                    "keep the body's facing (no yaw-rate dimension)");
  command->footer(
      "--weights FILE.json holds {\"Joint\": weight, ...}, overriding the mass preset's weights.\n"
      "Frame numbers count from 0 at the clip's own rate; ranges are inclusive.");
}

}  // namespace motiondb::cli
