// Synthetic projected libraries for the search tests: smooth random curves with a distinctive
// pattern planted at known places, some of them time-stretched.
#ifndef MOTIONDB_TESTS_SEARCH_TEST_DATA_H_
#define MOTIONDB_TESTS_SEARCH_TEST_DATA_H_

#include <cstdint>
#include <vector>

#include "core/index/library_index.h"
#include "core/motion/matrix.h"

namespace motiondb::testing {

// A smooth random curve of `frames` x `dims` with values of about +/- 1.
RowMatrixXf SmoothNoise(int64_t frames, int dims, uint32_t seed);

// The pattern: a raise-and-return bump far from the noise, sampled in `frames` frames (so a
// longer pattern is the same motion performed more slowly).
RowMatrixXf Pattern(int frames, int dims);

// Pattern(frames, dims) with its middle pose held for `hold` more frames.
RowMatrixXf HeldPattern(int frames, int hold, int dims);

// Eight clips at 120 Hz of 3000 frames of smooth noise (ids 0-7), the first six holding
// HeldPattern(240, 480, dims) (the query Pattern(240, dims) with its middle pose held 4 s).
std::vector<LibraryClip> HeldPoseClips(int dims);

// Writes `pattern` into `curve` starting at `at`.
void Plant(RowMatrixXf& curve, const RowMatrixXf& pattern, int64_t at);

// The mean distance over the first `dims` coordinates between each query row and the clip row
// `path` gives it: a warp's score, recomputed from its path.
double MeanPathDistance(const RowMatrixXf& query, const RowMatrixXf& clip,
                        const std::vector<int64_t>& path, int dims);

}  // namespace motiondb::testing

#endif  // MOTIONDB_TESTS_SEARCH_TEST_DATA_H_
