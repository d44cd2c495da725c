// The stored build report: the JSON it writes is the protobuf JSON mapping of
// motiondb.v1.SpaceBuildReport that earlier versions stored, in both directions.
#include "server/space_report.h"

#include <google/protobuf/util/json_util.h>
#include <google/protobuf/util/message_differencer.h>
#include <gtest/gtest.h>

#include <cmath>

#include "server/grpc/space_conversion.h"
#include "tests/synthetic_motion.h"

namespace motiondb::server {
namespace {

using google::protobuf::util::MessageDifferencer;

class SpaceReportTest : public ::testing::Test {
 protected:
  SpaceReportTest()
      : clip_(testing::SyntheticClip(testing::HumanoidSkeleton(/*still_root=*/true),
                                     {.frames = 60, .turn_rate = 0.4})),
        space_(*MotionSpace::Build({{"walk.bvh", clip_, FrameRange{5, 50}}},
                                   {.metric = SpaceMetric::kEigenvalueScaled})) {
    report_ = DescribeSpace(space_);
    report_.weight_preset = WeightPreset::kUniform;
    report_.training = {{7, {5, 50}}, {9000000000, {0, 59}}};
    report_.training_frames = 1234567890123;
    report_.reconstruction_error = {{3, 0.25, 1.5}, {5, 0.125, 0.75}};
    report_.projected_clips = 2;
    report_.build_ms = 12.5;
  }

  static v1::SpaceBuildReport Proto(const SpaceReport& report) {
    v1::SpaceBuildReport proto;
    ToProto(report, &proto);
    return proto;
  }

  Clip clip_;
  MotionSpace space_;
  SpaceReport report_;
};

TEST_F(SpaceReportTest, RoundTripsThroughJson) {
  const SpaceReport read = ReportFromJson(ReportToJson(report_), space_);
  EXPECT_TRUE(MessageDifferencer::Equals(Proto(read), Proto(report_)));
  EXPECT_EQ(read.training[1].clip_id, 9000000000);
  EXPECT_EQ(read.metric, SpaceMetric::kEigenvalueScaled);
}

TEST_F(SpaceReportTest, ReadsTheJsonEarlierVersionsStored) {
  // Earlier versions printed the proto with these options.
  google::protobuf::util::JsonPrintOptions options;
  options.preserve_proto_field_names = true;
  options.always_print_primitive_fields = true;
  std::string stored;
  ASSERT_TRUE(google::protobuf::util::MessageToJsonString(Proto(report_), &stored, options).ok());
  EXPECT_NE(stored.find("\"training_frames\":\"1234567890123\""), std::string::npos) << stored;
  EXPECT_TRUE(MessageDifferencer::Equals(Proto(ReportFromJson(stored, space_)), Proto(report_)));
}

TEST_F(SpaceReportTest, WritesJsonProtobufParses) {
  v1::SpaceBuildReport parsed;
  ASSERT_TRUE(google::protobuf::util::JsonStringToMessage(ReportToJson(report_), &parsed).ok());
  EXPECT_TRUE(MessageDifferencer::Equals(parsed, Proto(report_)));
}

TEST_F(SpaceReportTest, NonFiniteNumbersKeepTheirValue) {
  report_.build_ms = std::nan("");
  report_.reconstruction_error[0].max_rad = INFINITY;
  const SpaceReport read = ReportFromJson(ReportToJson(report_), space_);
  EXPECT_TRUE(std::isnan(read.build_ms));
  EXPECT_EQ(read.reconstruction_error[0].max_rad, INFINITY);
}

TEST_F(SpaceReportTest, UnreadableOrMissingJsonDescribesTheSpace) {
  const v1::SpaceBuildReport described = Proto(DescribeSpace(space_));
  for (const std::string json :
       {"", "not json", "[1, 2]", R"({"dims": "many"})", R"({"pelvis": 3})"}) {
    EXPECT_TRUE(MessageDifferencer::Equals(Proto(ReportFromJson(json, space_)), described)) << json;
  }
}

TEST_F(SpaceReportTest, IgnoresFieldsOfALaterVersion) {
  std::string json = ReportToJson(report_);
  json.insert(1, R"("added_later": {"x": 1}, )");
  EXPECT_TRUE(MessageDifferencer::Equals(Proto(ReportFromJson(json, space_)), Proto(report_)));
}

}  // namespace
}  // namespace motiondb::server
