#include "testing/perturbed_copy.h"

#include <cmath>

#include <gtest/gtest.h>

#include "testing/synthetic_corpus.h"

namespace motiondb {
namespace {

using testing::GenerateSyntheticCorpus;
using testing::SyntheticAction;
using testing::SyntheticCorpusOptions;

Clip ShortClip() {
  SyntheticCorpusOptions options;
  options.fps = 30;
  options.script = {{SyntheticAction::kBothArmsRaise, 2}};
  return GenerateSyntheticCorpus(options)->clips[0];
}

// A copy keeps its frames and skeleton, plays 0.8-1.25x as fast, and every rotation is turned by
// about the requested angle (root mean square over the clip).
TEST(PerturbedCopy, ChangesSpeedAndTurnsEveryRotationALittle) {
  const Clip original = ShortClip();
  std::mt19937_64 rng(5);
  for (const double noise_deg : {1.0, 3.0}) {
    testing::PerturbOptions options;
    options.noise_deg = noise_deg;
    const Clip copy = *testing::PerturbedCopy(original, options, rng);
    ASSERT_EQ(copy.frame_count(), original.frame_count());
    EXPECT_EQ(&copy.skeleton(), &original.skeleton());
    const double speed = original.frame_time() / copy.frame_time();
    EXPECT_GE(speed, 0.8);
    EXPECT_LE(speed, 1.25);
    EXPECT_EQ(copy.positions(), original.positions());
    double sum = 0;
    int count = 0;
    for (int f = 0; f < copy.frame_count(); ++f) {
      for (int j = 0; j < original.skeleton().joint_count(); ++j) {
        const double angle = AngleBetween(copy.rotation(f, j), original.rotation(f, j));
        sum += angle * angle;
        ++count;
      }
    }
    EXPECT_NEAR(std::sqrt(sum / count) * 180 / M_PI, noise_deg, 0.1 * noise_deg);
  }
}

TEST(PerturbedCopy, RefusesBadOptions) {
  const Clip original = ShortClip();
  std::mt19937_64 rng(5);
  for (const testing::PerturbOptions& options :
       {testing::PerturbOptions{0, 1, 1}, testing::PerturbOptions{1.2, 1.1, 1},
        testing::PerturbOptions{1, 11, 1}, testing::PerturbOptions{0.8, 1.25, NAN}}) {
    EXPECT_FALSE(testing::PerturbedCopy(original, options, rng).ok());
  }
}

}  // namespace
}  // namespace motiondb
