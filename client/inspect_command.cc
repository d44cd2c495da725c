// motiondb inspect FILE... [--json]
#include <cstdio>
#include <iostream>
#include <memory>

#include <nlohmann/json.hpp>

#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "client/commands.h"
#include "core/bvh/bvh_reader.h"

namespace motiondb::cli {
namespace {

nlohmann::json Describe(const std::string& path, const BvhReadResult& result) {
  const Clip& clip = result.clip;
  nlohmann::json joints = nlohmann::json::array();
  for (const Joint& joint : clip.skeleton().joints()) joints.push_back(joint.name);
  return {
      {"file", path},
      {"joint_count", clip.skeleton().joint_count()},
      {"joints", std::move(joints)},
      {"channel_count", clip.skeleton().channel_count()},
      {"frames", clip.frame_count()},
      {"frame_time", clip.frame_time()},
      {"fps", clip.fps()},
      {"duration_s", clip.duration_s()},
      {"warnings", result.warnings},
  };
}

void PrintClipSummary(const std::string& path, const BvhReadResult& result) {
  const Clip& clip = result.clip;
  std::vector<std::string> names;
  for (const Joint& joint : clip.skeleton().joints()) names.push_back(joint.name);
  absl::PrintF("%s\n", path);
  absl::PrintF("  joints:   %d (%s)\n", clip.skeleton().joint_count(), absl::StrJoin(names, ", "));
  absl::PrintF("  channels: %d per frame\n", clip.skeleton().channel_count());
  absl::PrintF("  frames:   %d\n", clip.frame_count());
  absl::PrintF("  fps:      %.4f (frame time %g s)\n", clip.fps(), clip.frame_time());
  absl::PrintF("  duration: %.3f s\n", clip.duration_s());
  absl::PrintF("  warnings: %s\n",
               result.warnings.empty() ? "none" : absl::StrJoin(result.warnings, "; "));
}

}  // namespace

void AddInspect(Commands& commands) {
  auto files = std::make_shared<std::vector<std::string>>();
  const GlobalOptions& global = commands.global();
  CLI::App* inspect = commands.AddOffline(
      commands.root(), "inspect", "describe BVH files: joints, channels, frames, fps, warnings",
      /*json=*/true, [files, &global]() -> absl::Status {
        int failures = 0;
        for (const std::string& path : *files) {
          const absl::StatusOr<BvhReadResult> result = ReadBvhFile(path);
          if (!result.ok()) {
            std::cerr << "motiondb inspect: " << result.status().message() << "\n";
            ++failures;
          } else if (global.json) {
            std::cout << Describe(path, *result).dump() << "\n";
          } else {
            PrintClipSummary(path, *result);
          }
        }
        return failures == 0 ? absl::OkStatus() : ReportedFailure();
      });
  inspect->add_option("FILE", *files, "BVH files")->required();
}

}  // namespace motiondb::cli
