#include "testing/labelled_index.h"

#include <algorithm>
#include <map>
#include <utility>

#include "absl/strings/str_split.h"
#include "core/bvh/bvh_reader.h"
#include "core/space/search_coordinates.h"
#include "util/status_macros.h"

namespace motiondb::testing {
namespace {

// The name's `field`-th '_'-separated field, or the whole stem when it has too few.
std::string NameField(const std::filesystem::path& path, size_t field) {
  const std::vector<std::string> parts = absl::StrSplit(path.stem().string(), '_');
  return parts.size() > field ? parts[field] : path.stem().string();
}

}  // namespace

std::string ContentLabel(const std::filesystem::path& path) { return NameField(path, 1); }

std::string StyleLabel(const std::filesystem::path& path) { return NameField(path, 2); }

absl::StatusOr<std::vector<TrainingClip>> ReadLabelledFolder(const std::filesystem::path& folder,
                                                             std::vector<std::string>* labels,
                                                             Takes takes) {
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::directory_iterator(folder)) {
    if (entry.path().extension() == ".bvh") files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  if (takes != Takes::kAll) {
    std::map<std::pair<std::string, std::string>, int> group_size, seen;
    for (const auto& path : files) ++group_size[{ContentLabel(path), StyleLabel(path)}];
    std::erase_if(files, [&](const std::filesystem::path& path) {
      const std::pair<std::string, std::string> group = {ContentLabel(path), StyleLabel(path)};
      const bool first_half = seen[group]++ < (group_size[group] + 1) / 2;
      return first_half != (takes == Takes::kFirstHalf);
    });
  }
  std::vector<TrainingClip> clips;
  for (const std::filesystem::path& path : files) {
    MOTIONDB_ASSIGN_OR_RETURN(BvhReadResult read, ReadBvhFile(path.string()));
    clips.push_back({path.filename().string(), std::move(read.clip), std::nullopt});
    labels->push_back(ContentLabel(path));
  }
  return clips;
}

absl::StatusOr<LabelledIndex> LoadLabelledIndex(const std::vector<std::filesystem::path>& folders,
                                                const SpaceOptions& space_options,
                                                const LibraryIndexOptions& index_options,
                                                Takes takes) {
  LabelledIndex library;
  std::vector<TrainingClip> clips;
  for (const std::filesystem::path& folder : folders) {
    MOTIONDB_ASSIGN_OR_RETURN(std::vector<TrainingClip> read,
                              ReadLabelledFolder(folder, &library.labels, takes));
    for (TrainingClip& clip : read) {
      library.styles.push_back(StyleLabel(clip.source));
      library.sources.push_back(folder.filename().string());
      clips.push_back(std::move(clip));
    }
  }
  MOTIONDB_ASSIGN_OR_RETURN(MotionSpace space, MotionSpace::Build(clips, space_options));
  library.space = std::make_unique<MotionSpace>(std::move(space));
  std::vector<LibraryClip> projected;
  for (size_t i = 0; i < clips.size(); ++i) {
    MOTIONDB_ASSIGN_OR_RETURN(RowMatrixXf coordinates,
                              SearchCoordinates(*library.space, clips[i].clip));
    projected.push_back(
        {static_cast<int64_t>(i), clips[i].source, {library.labels[i]}, std::move(coordinates)});
  }
  MOTIONDB_ASSIGN_OR_RETURN(
      library.index,
      LibraryIndex::Build(std::move(projected), library.space->sample_rate(), index_options));
  return library;
}

}  // namespace motiondb::testing
