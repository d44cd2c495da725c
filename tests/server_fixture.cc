#include "tests/server_fixture.h"

#include "core/bvh/bvh_writer.h"
#include "tests/clip_builder.h"

namespace motiondb {

const SyntheticCorpus& Humanoid() {
  static const SyntheticCorpus* const library = [] {
    SyntheticCorpusOptions options;
    options.seed = 7;
    options.script = {{SyntheticAction::kRightArmRaise, 4},
                      {SyntheticAction::kLeftArmRaise, 4},
                      {SyntheticAction::kBothArmsRaise, 3},
                      {SyntheticAction::kShrug, 3}};
    options.max_clip_duration_s = 20;
    options.threads = 2;
    absl::StatusOr<SyntheticCorpus> generated = GenerateSyntheticCorpus(options);
    EXPECT_TRUE(generated.ok()) << generated.status();
    return new SyntheticCorpus(*std::move(generated));
  }();
  return *library;
}

const SyntheticSegment& FirstRaise() { return Humanoid().segments.front(); }

std::string BvhText(const Clip& clip) {
  absl::StatusOr<std::string> text = WriteBvh(clip);
  EXPECT_TRUE(text.ok()) << text.status();
  return text.ok() ? *text : "";
}

Clip ChainClip(double speed) {
  return testing::MakeClip(
      testing::ChainSkeleton(), 61, 1.0 / 30,
      [speed](int f, int j) {
        return Quat(Eigen::AngleAxisd(speed * f * (j + 1), Eigen::Vector3d::UnitY()));
      },
      [](int f, int) { return Eigen::Vector3d(0.1 * f, 90, 0); });
}

v1::SearchRequest ClipQuery(const std::string& space, int64_t clip_id, int first, int last) {
  v1::SearchRequest request;
  request.set_space(space);
  request.mutable_clip()->set_clip_id(clip_id);
  request.mutable_clip()->set_first_frame(first);
  request.mutable_clip()->set_last_frame(last);
  request.set_exclude_query(false);
  return request;
}

}  // namespace motiondb
