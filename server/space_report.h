// A space's build report: what the space is (dimensions, rate, heading, metric, joint weights,
// explained variance) and how it was built (training ranges, reconstruction error, timing).
// Stored as JSON in storage::SpaceRecord::build_report_json, so that GetSpace returns exactly
// what CreateSpace did. The JSON is the protobuf JSON mapping of motiondb.v1.SpaceBuildReport
// with the .proto field names (int64 as strings, enums by name), as earlier versions stored it.
#ifndef MOTIONDB_SERVER_SPACE_REPORT_H_
#define MOTIONDB_SERVER_SPACE_REPORT_H_

#include <cstdint>
#include <string>
#include <vector>

#include "core/motion/clip.h"
#include "core/space/joint_weights.h"
#include "core/space/motion_space.h"

namespace motiondb::server {

struct JointWeightReport {
  std::string joint;
  double weight = 0;
};

// A training range as used: a stored clip and explicit frames at its own rate.
struct TrainingReport {
  int64_t clip_id = 0;
  FrameRange frames;
};

struct SpaceReport {
  int dims = 0;
  int joint_count = 0;
  std::string pelvis;  // the joint whose yaw is the body's facing
  double sample_rate = 0;
  bool heading_removed = false;
  double yaw_rate_weight = 0;       // 0 when the heading is kept
  double root_velocity_weight = 0;  // 0 without root-velocity dimensions
  SpaceMetric metric = SpaceMetric::kUnit;
  WeightPreset weight_preset = WeightPreset::kMass;
  std::vector<JointWeightReport> joint_weights;  // in skeleton order, as used
  std::vector<TrainingReport> training;
  int64_t training_frames = 0;             // at the space rate
  std::vector<double> explained_variance;  // per dimension; sums to 1
  std::vector<ReconstructionError> reconstruction_error;
  int64_t projected_clips = 0;
  // With a learned metric (server/learned_metric_fit.h): its shrink and what it was fitted on;
  // 0 examples without one.
  double learned_metric_shrink = 0;
  int64_t learned_metric_examples = 0;
  int64_t learned_metric_descriptors = 0;
  double build_ms = 0;
};

// The fields that follow from the space alone (the rest stay at their defaults).
SpaceReport DescribeSpace(const MotionSpace& space);

std::string ReportToJson(const SpaceReport& report);
// The stored report; DescribeSpace(space) when the JSON is missing or unreadable (a space stored
// by another tool), so that a report always has the space's own facts. Unknown fields (a report
// written by a later version) are ignored.
SpaceReport ReportFromJson(const std::string& json, const MotionSpace& space);

}  // namespace motiondb::server

#endif  // MOTIONDB_SERVER_SPACE_REPORT_H_
