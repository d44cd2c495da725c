#include "server/frame_conversion.h"

#include <gtest/gtest.h>

namespace motiondb::server {
namespace {

// SpaceFramesWithin turns "a hit's own frames reach into the range" into a comparison of space
// frames: for every pair of rates and every range, a space range a..b reaches into the range at
// the clip's rate exactly when a <= last and b >= first.
TEST(FrameConversion, SpaceFramesWithinAreExactlyThoseWhoseHitsOverlap) {
  struct Rates {
    double fps, rate;
    int frames;
  };
  for (const Rates& r : {Rates{120, 30, 97}, Rates{30, 30, 40}, Rates{24, 30, 33},
                         Rates{100, 30, 61}, Rates{29.97, 60, 25}}) {
    SCOPED_TRACE(testing::Message() << r.fps << " fps into " << r.rate);
    const int64_t space_frames =
        static_cast<int64_t>(std::llround((r.frames - 1) * r.rate / r.fps)) + 1;
    const FrameConversion conversion(r.fps, r.frames, r.rate, space_frames);
    for (int first = 0; first < r.frames; ++first) {
      for (int last = first; last < r.frames; ++last) {
        const auto [lo, hi] = conversion.SpaceFramesWithin({first, last});
        ASSERT_GE(hi, lo - 1);
        for (int64_t a = 0; a < space_frames; ++a) {
          for (int64_t b = a; b < space_frames; ++b) {
            const bool overlaps =
                conversion.ToOriginal(a) <= last && conversion.ToOriginal(b) >= first;
            ASSERT_EQ(overlaps, a <= hi && b >= lo)
                << first << ".." << last << " against " << a << ".." << b;
          }
        }
      }
    }
  }
}

}  // namespace
}  // namespace motiondb::server
