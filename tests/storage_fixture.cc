#include "tests/storage_fixture.h"

#include <algorithm>
#include <cmath>

#include "core/motion/rotation.h"
#include "tests/clip_builder.h"

namespace motiondb::storage {

std::tuple<int64_t, int64_t, int64_t, int64_t, int64_t, int64_t> AsTuple(const Counts& c) {
  return {c.skeletons, c.clips, c.frames, c.spaces, c.projections, c.labels};
}

std::shared_ptr<const Skeleton> Rescaled(const Skeleton& skeleton, double scale) {
  std::vector<Joint> joints = skeleton.joints();
  for (Joint& joint : joints) {
    joint.offset *= scale;
    if (joint.end_site) *joint.end_site *= scale;
  }
  return std::make_shared<const Skeleton>(*Skeleton::Create(std::move(joints)));
}

Clip Motion(std::shared_ptr<const Skeleton> skeleton, int frames, int seed) {
  return testing::MakeClip(
      std::move(skeleton), frames, 1.0 / 120.0,
      [seed](int f, int j) {
        return Quat(
            Eigen::AngleAxisd(0.37 * f + 1.1 * j + seed,
                              Eigen::Vector3d(1.0, 0.3 * j, 0.1 * seed + 0.2).normalized()));
      },
      [seed](int f, int j) { return Eigen::Vector3d(0.013 * f - 7.1, 91.7 + j, 3.3 * seed); });
}

Page Sized(int page_size) {
  Page page;
  page.page_size = page_size;
  return page;
}

ClipRecord Named(const std::string& name, std::vector<std::string> tags) {
  ClipRecord record;
  record.name = name;
  record.source_file = name + ".bvh";
  record.tags = std::move(tags);
  return record;
}

void ExpectSameLayout(const Skeleton& a, const Skeleton& b) {
  ASSERT_EQ(a.joint_count(), b.joint_count());
  for (int j = 0; j < a.joint_count(); ++j) {
    EXPECT_EQ(a.joint(j).name, b.joint(j).name);
    EXPECT_EQ(a.joint(j).parent, b.joint(j).parent);
    EXPECT_EQ(a.joint(j).offset, b.joint(j).offset);
    EXPECT_EQ(a.joint(j).channels, b.joint(j).channels);
    EXPECT_EQ(a.joint(j).end_site, b.joint(j).end_site);
  }
}

void ExpectSameFrames(const Clip& expected, const Clip& actual) {
  EXPECT_EQ(actual.frame_time(), expected.frame_time());
  ASSERT_EQ(actual.frame_count(), expected.frame_count());
  ExpectSameLayout(expected.skeleton(), actual.skeleton());
  double worst_angle = 0.0;
  for (int f = 0; f < expected.frame_count(); ++f) {
    for (int j = 0; j < expected.skeleton().joint_count(); ++j) {
      worst_angle =
          std::max(worst_angle, AngleBetween(expected.rotation(f, j), actual.rotation(f, j)));
    }
  }
  EXPECT_LT(worst_angle, 1e-6);
  const RowMatrixXd& p = expected.positions();
  ASSERT_EQ(actual.positions().rows(), p.rows());
  ASSERT_EQ(actual.positions().cols(), p.cols());
  for (Eigen::Index i = 0; i < p.size(); ++i) {
    EXPECT_NEAR(actual.positions().data()[i], p.data()[i],
                1e-6 * std::max(1.0, std::abs(p.data()[i])));
  }
}

LabelRecord Manual(int64_t clip_id, int64_t first, int64_t last, const std::string& descriptor,
                   double value) {
  LabelRecord label;
  label.clip_id = clip_id;
  label.first_frame = first;
  label.last_frame = last;
  label.descriptor = descriptor;
  label.value = value;
  return label;
}

std::vector<int64_t> IdsOf(const std::vector<LabelRecord>& labels) {
  std::vector<int64_t> ids;
  for (const LabelRecord& label : labels) ids.push_back(label.label_id);
  return ids;
}

absl::StatusOr<std::vector<int64_t>> IdsOf(const absl::StatusOr<AddedLabels>& added) {
  if (!added.ok()) return added.status();
  return IdsOf(added->labels);
}

StorageSpaceTest::LabelledLibrary StorageSpaceTest::InsertLabelledLibrary() {
  LabelledLibrary library;
  library.walk = Insert(Named("walk"), walk_);
  library.wave = Insert(Named("wave"), wave_);
  const int64_t skeleton = Db().GetClipRecord(library.walk)->skeleton_id;
  library.space_id =
      *Db().InsertSpace(SpaceNamed("body", skeleton), space_,
                        {ProjectionOf(library.walk, walk_), ProjectionOf(library.wave, wave_)});
  library.manual = *IdsOf(Db().AddLabels(
      {Manual(library.walk, 0, 9, "kick", 1), Manual(library.walk, 20, 29, "wave", 0.8)}));
  return library;
}

}  // namespace motiondb::storage
