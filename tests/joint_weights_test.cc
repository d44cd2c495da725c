// Joint weights (SPEC §3): the mass preset, uniform, overrides by name, and bad weights.
#include "core/space/joint_weights.h"

#include <cmath>
#include <limits>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "absl/strings/str_cat.h"
#include "tests/synthetic_motion.h"

namespace motiondb {
namespace {

using ::testing::HasSubstr;

// Root (still) -> Hips (placement offset 90) -> Spine (10) -> Head (10, End Site 5);
// Hips -> Leg (10) -> Foot (40, zero End Site).
Skeleton SmallSkeleton() {
  std::vector<Joint> joints(6);
  const auto set = [&](int j, const char* name, int parent, Eigen::Vector3d offset) {
    joints[j].name = name;
    joints[j].parent = parent;
    joints[j].offset = offset;
    joints[j].channels = {Channel::kZrotation, Channel::kXrotation, Channel::kYrotation};
  };
  set(0, "Root", -1, Eigen::Vector3d::Zero());
  set(1, "Hips", 0, Eigen::Vector3d(0, 90, 0));
  set(2, "Spine", 1, Eigen::Vector3d(0, 10, 0));
  set(3, "Head", 2, Eigen::Vector3d(0, 6, 8));
  joints[3].end_site = Eigen::Vector3d(0, 5, 0);
  set(4, "Leg", 1, Eigen::Vector3d(10, 0, 0));
  set(5, "Foot", 4, Eigen::Vector3d(0, -40, 0));
  joints[5].end_site = Eigen::Vector3d::Zero();
  return *Skeleton::Create(std::move(joints));
}

TEST(JointWeightsTest, MassIsTheBoneLengthBelowTheJointNormalisedAndFloored) {
  const absl::StatusOr<Eigen::VectorXd> weights = ComputeJointWeights(SmallSkeleton());
  ASSERT_TRUE(weights.ok()) << weights.status();
  // Below Hips: Spine 10 + Head 10 + End Site 5 + Leg 10 + Foot 40 = 75; the Root -> Hips
  // offset is a placement and does not count.
  Eigen::VectorXd expected(6);
  expected << 75.0 / 75, 75.0 / 75, 15.0 / 75, 5.0 / 75, 40.0 / 75, 0.05;
  EXPECT_TRUE(weights->isApprox(expected, 1e-12)) << weights->transpose();
}

TEST(JointWeightsTest, FloorIsAFractionOfTheLargest) {
  JointWeightOptions options;
  options.floor = 0.2;
  const Eigen::VectorXd weights = *ComputeJointWeights(SmallSkeleton(), options);
  EXPECT_DOUBLE_EQ(weights[3], 0.2);  // Head: 5 / 75 < 0.2
  EXPECT_DOUBLE_EQ(weights[5], 0.2);  // Foot: zero length
  EXPECT_DOUBLE_EQ(weights[2], 0.2);  // Spine: 15 / 75 = 0.2
  EXPECT_DOUBLE_EQ(weights.maxCoeff(), 1.0);
}

TEST(JointWeightsTest, HumanoidLegsOutweighArms) {
  const auto skeleton = testing::HumanoidSkeleton(/*still_root=*/true);
  const Eigen::VectorXd weights = *ComputeJointWeights(*skeleton);
  EXPECT_DOUBLE_EQ(weights[skeleton->FindJoint("Hips")], 1.0);
  EXPECT_GT(weights[skeleton->FindJoint("UpperLeg_L")], weights[skeleton->FindJoint("UpperArm_L")]);
  EXPECT_DOUBLE_EQ(weights[skeleton->FindJoint("Hand_L")], 0.05);
  EXPECT_TRUE((weights.array() > 0).all());
}

TEST(JointWeightsTest, UniformAndOverrides) {
  JointWeightOptions options;
  options.preset = WeightPreset::kUniform;
  EXPECT_EQ(*ComputeJointWeights(SmallSkeleton(), options), Eigen::VectorXd::Ones(6));
  options.overrides = {{"Leg", 4.0}, {"Foot", 0.25}};
  const Eigen::VectorXd uniform = *ComputeJointWeights(SmallSkeleton(), options);
  EXPECT_DOUBLE_EQ(uniform[4], 4.0);
  EXPECT_DOUBLE_EQ(uniform[5], 0.25);
  EXPECT_DOUBLE_EQ(uniform[2], 1.0);
  options.preset = WeightPreset::kMass;
  const Eigen::VectorXd mass = *ComputeJointWeights(SmallSkeleton(), options);
  EXPECT_DOUBLE_EQ(mass[4], 4.0);  // overrides are final, not rescaled
  EXPECT_DOUBLE_EQ(mass[2], 15.0 / 75);
}

TEST(JointWeightsTest, SkeletonWithoutBoneLengthIsUniform) {
  std::vector<Joint> joints(3);
  for (int j = 0; j < 3; ++j) {
    joints[j].name = absl::StrCat("j", j);
    joints[j].parent = j - 1;
  }
  EXPECT_EQ(*ComputeJointWeights(*Skeleton::Create(joints)), Eigen::VectorXd::Ones(3));
}

TEST(JointWeightsTest, RejectsBadWeights) {
  const Skeleton skeleton = SmallSkeleton();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  for (const double bad : {0.0, -1.0, nan, inf}) {
    JointWeightOptions options;
    options.overrides = {{"Leg", bad}};
    const absl::StatusOr<Eigen::VectorXd> weights = ComputeJointWeights(skeleton, options);
    ASSERT_FALSE(weights.ok()) << bad;
    EXPECT_EQ(weights.status().code(), absl::StatusCode::kInvalidArgument);
    EXPECT_THAT(weights.status().message(), HasSubstr("'Leg'"));
    EXPECT_THAT(weights.status().message(), HasSubstr("finite and positive"));
  }
  JointWeightOptions unknown;
  unknown.overrides = {{"Tail", 1.0}};
  const absl::StatusOr<Eigen::VectorXd> weights = ComputeJointWeights(skeleton, unknown);
  ASSERT_FALSE(weights.ok());
  EXPECT_THAT(weights.status().message(), HasSubstr("unknown joint 'Tail'"));
  for (const double floor : {0.0, -0.1, 1.5, nan}) {
    JointWeightOptions options;
    options.floor = floor;
    EXPECT_FALSE(ComputeJointWeights(skeleton, options).ok()) << floor;
  }
}

TEST(JointWeightsTest, PresetNames) {
  EXPECT_EQ(*ParseWeightPreset("mass"), WeightPreset::kMass);
  EXPECT_EQ(*ParseWeightPreset("uniform"), WeightPreset::kUniform);
  EXPECT_EQ(WeightPresetName(WeightPreset::kUniform), "uniform");
  EXPECT_THAT(ParseWeightPreset("heavy").status().message(), HasSubstr("'heavy'"));
}

TEST(JointWeightsTest, ParsesJsonOverrides) {
  const absl::StatusOr<std::map<std::string, double>> overrides =
      ParseWeightOverrides(R"({"Leg": 3, "Foot": 0.5, "Joint With Space": 1e-3})");
  ASSERT_TRUE(overrides.ok()) << overrides.status();
  EXPECT_EQ(*overrides, (std::map<std::string, double>{
                            {"Leg", 3.0}, {"Foot", 0.5}, {"Joint With Space", 1e-3}}));
  EXPECT_TRUE(ParseWeightOverrides("{}")->empty());
}

TEST(JointWeightsTest, RejectsBadJson) {
  const struct {
    const char* json;
    const char* message;
  } cases[] = {
      {"", "invalid JSON"},
      {"{\"Leg\": 1", "invalid JSON"},
      {"[1, 2]", "expected a JSON object"},
      {"3", "expected a JSON object"},
      {R"({"Leg": null})", "'Leg' is missing or not a number"},
      {R"({"Leg": "heavy"})", "'Leg' is missing or not a number"},
      {R"({"Leg": [1]})", "'Leg' is missing or not a number"},
      {R"({"Leg": 0})", "finite and positive"},
      {R"({"Leg": -2.5})", "finite and positive"},
      {R"({"Leg": NaN})", "invalid JSON"},
      {R"({"Leg": 1e999})", "invalid JSON"},
  };
  for (const auto& c : cases) {
    const absl::StatusOr<std::map<std::string, double>> overrides = ParseWeightOverrides(c.json);
    ASSERT_FALSE(overrides.ok()) << c.json;
    EXPECT_THAT(overrides.status().message(), HasSubstr(c.message)) << c.json;
  }
}

}  // namespace
}  // namespace motiondb
