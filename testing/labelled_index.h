// A labelled folder of BVH files (e.g. ../shared/mocap/bandai2-normal) made searchable: a space
// trained on every clip, and every clip's projection indexed. Shared by the retrieval-quality
// test and the search_quality measurement program.
#ifndef MOTIONDB_TESTING_LABELLED_INDEX_H_
#define MOTIONDB_TESTING_LABELLED_INDEX_H_

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "core/index/library_index.h"
#include "core/space/motion_space.h"

namespace motiondb::testing {

struct LabelledIndex {
  std::unique_ptr<MotionSpace> space;
  std::unique_ptr<LibraryIndex> index;
  std::vector<std::string> labels;   // per clip: the file name's content field
  std::vector<std::string> styles;   // per clip: the file name's style field
  std::vector<std::string> sources;  // per clip: the name of the folder it came from
};

// "dataset-2_raise-up-left-hand_normal_003.bvh" -> "raise-up-left-hand".
std::string ContentLabel(const std::filesystem::path& path);
// "dataset-2_raise-up-left-hand_normal_003.bvh" -> "normal".
std::string StyleLabel(const std::filesystem::path& path);

// Which takes of a folder are read, for a held-out split: of each content and style's n files
// in name order, the first ceil(n/2) or the others (a lone take is in the first half).
enum class Takes { kAll, kFirstHalf, kSecondHalf };

// Every *.bvh of `folder` (of `takes`), in name order, as whole training clips named by their
// file names; `labels` gets each one's ContentLabel.
absl::StatusOr<std::vector<TrainingClip>> ReadLabelledFolder(const std::filesystem::path& folder,
                                                             std::vector<std::string>* labels,
                                                             Takes takes = Takes::kAll);

// One space trained on every clip (of `takes`) of every folder, and one index of them all, in
// folder order.
absl::StatusOr<LabelledIndex> LoadLabelledIndex(const std::vector<std::filesystem::path>& folders,
                                                const SpaceOptions& space_options,
                                                const LibraryIndexOptions& index_options,
                                                Takes takes = Takes::kAll);

}  // namespace motiondb::testing

#endif  // MOTIONDB_TESTING_LABELLED_INDEX_H_
