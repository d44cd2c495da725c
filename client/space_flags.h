// The flags `space build` (offline) and `space create` (on the server) share: the options of a
// Motion Curve space (core/space/motion_space.h SpaceOptions).
#ifndef MOTIONDB_CLIENT_SPACE_FLAGS_H_
#define MOTIONDB_CLIENT_SPACE_FLAGS_H_

#include <optional>
#include <string>

#include <CLI/CLI.hpp>

namespace motiondb::cli {

struct SpaceFlags {
  std::optional<double> rate;             // --rate (unset: SpaceOptions' default)
  std::string weights = "mass";           // --weights mass|uniform|FILE.json
  std::optional<double> yaw_rate_weight;  // --yaw-rate-weight
  std::optional<double> root_velocity_weight;  // --root-velocity-weight
  std::string metric = "unit";            // --metric unit|eigen
  bool keep_heading = false;              // --keep-heading
};

// --weights names a preset, not a file of per-joint weights.
inline bool IsWeightPreset(const std::string& weights) {
  return weights == "mass" || weights == "uniform";
}

// Adds --rate, --weights, --yaw-rate-weight, --metric and --keep-heading to `command`.
void AddSpaceFlags(CLI::App* command, SpaceFlags* flags);

}  // namespace motiondb::cli

#endif  // MOTIONDB_CLIENT_SPACE_FLAGS_H_
