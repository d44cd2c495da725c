// Propagation's pure parts (server/propagation.h): which candidate ranges are kept.
#include "server/propagation.h"

#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace motiondb::server {
namespace {

storage::LabelRecord Range(int64_t first, int64_t last, double value, double score = 0.1) {
  storage::LabelRecord label;
  label.clip_id = 1;
  label.first_frame = first;
  label.last_frame = last;
  label.descriptor = "raise";
  label.value = value;
  label.score = score;
  label.origin = storage::LabelOrigin::kPropagated;
  return label;
}

// Overlap is measured against the shorter range: a long weaker range holding a stronger short
// one is dropped (against the long one's own length it shares only a fifth).
TEST(KeepStrongest, DropsALongWeakerRangeAroundAStrongerShortOne) {
  const std::vector<storage::LabelRecord> kept =
      KeepStrongest({Range(0, 99, 0.5), Range(40, 59, 0.9)}, {});
  ASSERT_EQ(kept.size(), 1u);
  EXPECT_EQ(kept[0].first_frame, 40);
  EXPECT_EQ(kept[0].last_frame, 59);
}

TEST(KeepStrongest, ALongCandidateDoesNotWriteOverAManualRange) {
  storage::LabelRecord manual = Range(40, 59, 1.0);
  manual.origin = storage::LabelOrigin::kManual;
  EXPECT_TRUE(KeepStrongest({Range(0, 99, 0.5)}, {manual}).empty());
}

TEST(KeepStrongest, KeepsRangesSharingHalfOrLessOfTheShorterOne) {
  // 10 shared frames of a 20-frame range: exactly half, kept.
  const std::vector<storage::LabelRecord> kept =
      KeepStrongest({Range(0, 99, 0.5), Range(90, 109, 0.9)}, {});
  EXPECT_EQ(kept.size(), 2u);
}

}  // namespace
}  // namespace motiondb::server
