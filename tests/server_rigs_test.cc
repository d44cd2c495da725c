// A space over several skeletons through the real binary (issue 40 item 3): Bandai takes and
// the same takes re-rigged (testing/rerigged_copy.h: renamed joints, an extra spine joint, no
// toes, another rotation order and rest pose, 3-channel joints, another scale, Z up) in one
// space; each take's range finds its re-rigged copy's same frames first and the other way
// round, a take ingested after the space joins it, an upload of either rig searches it (also
// with its mirror), propagation runs in it, and a skeleton that lacks slots is refused naming
// them.
#include <optional>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_replace.h"
#include "core/bvh/bvh_reader.h"
#include "core/motion/humanoid_map.h"
#include "google/protobuf/text_format.h"
#include "testing/corpus_paths.h"
#include "testing/rerigged_copy.h"
#include "testing/server_process.h"
#include "testing/synthetic_corpus.h"
#include "tests/server_fixture.h"

namespace motiondb {
namespace {

using ::testing::HasSubstr;
using testing::ServerProcess;

// Bandai takes of several actions, one style: a copy must be told from the other actions.
const std::vector<std::string>& Takes() {
  static const auto* takes = new std::vector<std::string>{
      "walk_active_001", "run_active_001",   "bow_active_001",       "bye_active_001",
      "dash_active_001", "guide_active_001", "walk-back_active_001", "walk-left_active_001"};
  return *takes;
}

struct Rigs {
  std::vector<Clip> originals, copies;
};

std::optional<Rigs> LoadRigs() {
  const std::optional<std::filesystem::path> dir = testing::MocapDir();
  if (!dir) return std::nullopt;
  Rigs rigs;
  for (const std::string& take : Takes()) {
    absl::StatusOr<BvhReadResult> read =
        ReadBvhFile((*dir / "bandai1" / ("dataset-1_" + take + ".bvh")).string());
    if (!read.ok()) return std::nullopt;
    absl::StatusOr<Clip> copy = testing::ReriggedCopy(read->clip);
    EXPECT_TRUE(copy.ok()) << copy.status();
    if (!copy.ok()) return std::nullopt;
    rigs.originals.push_back(read->clip);
    rigs.copies.push_back(*std::move(copy));
  }
  return rigs;
}

// The clip and frames of the first result of a search of `query`'s frames 10..60.
v1::SearchResult First(Client& client, int64_t query) {
  v1::SearchRequest request;
  request.set_space("rigs");
  request.mutable_clip()->set_clip_id(query);
  request.mutable_clip()->set_first_frame(10);
  request.mutable_clip()->set_last_frame(60);
  request.set_max_results(5);
  v1::SearchResponse response;
  const grpc::Status status = client.Search(request, &response);
  EXPECT_TRUE(status.ok()) << status.error_message();
  EXPECT_GE(response.results_size(), 1);
  return response.results_size() > 0 ? response.results(0) : v1::SearchResult();
}

TEST_F(ServerTest, TakesAndTheirReriggedCopiesFindEachOtherInASpaceOverBothSkeletons) {
  const std::optional<Rigs> rigs = LoadRigs();
  if (!rigs) GTEST_SKIP() << "../shared/mocap/bandai1 is absent; skipped";
  ServerProcess* server = StartServer();
  ASSERT_NE(server, nullptr);
  Client client(testing::InsecureChannel(server->address()));
  const size_t late = Takes().size() - 1;  // its copy is ingested after the space is built
  std::vector<int64_t> originals, copies(Takes().size(), -1);
  for (size_t i = 0; i < Takes().size(); ++i) {
    originals.push_back(client.IngestOrFail(Takes()[i] + ".bvh", BvhText(rigs->originals[i])));
    if (i != late) {
      copies[i] = client.IngestOrFail("rerig-" + Takes()[i] + ".bvh", BvhText(rigs->copies[i]));
    }
  }
  v1::GetClipRequest get;
  get.set_clip_id(originals[0]);
  v1::Clip original_clip, copy_clip;
  ASSERT_TRUE(client.clips().GetClip(client.Context().get(), get, &original_clip).ok());
  get.set_clip_id(copies[0]);
  ASSERT_TRUE(client.clips().GetClip(client.Context().get(), get, &copy_clip).ok());
  ASSERT_NE(original_clip.skeleton_id(), copy_clip.skeleton_id());

  v1::CreateSpaceRequest create;
  create.set_name("rigs");
  create.add_skeleton_ids(original_clip.skeleton_id());
  create.add_skeleton_ids(copy_clip.skeleton_id());
  v1::Space space;
  grpc::Status status = client.CreateSpace(create, &space);
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_THAT(space.skeleton_ids(),
              ::testing::ElementsAre(original_clip.skeleton_id(), copy_clip.skeleton_id()));
  EXPECT_EQ(space.report().projected_clips(), static_cast<int64_t>(2 * Takes().size() - 1));

  copies[late] =
      client.IngestOrFail("rerig-" + Takes()[late] + ".bvh", BvhText(rigs->copies[late]));
  for (size_t i = 0; i < Takes().size(); ++i) {
    for (const auto& [query, want] :
         {std::pair{originals[i], copies[i]}, std::pair{copies[i], originals[i]}}) {
      const v1::SearchResult first = First(client, query);
      EXPECT_EQ(first.clip_id(), want) << Takes()[i] << ": found " << first.clip_name();
      // The same frames: the copy keeps the take's frame numbering.
      EXPECT_NEAR(first.start_frame(), 10, 3) << Takes()[i];
      EXPECT_NEAR(first.end_frame(), 60, 3) << Takes()[i];
    }
  }

  // An upload of the re-rigged skeleton searches the space too; its copy and original are first.
  v1::SearchRequest upload;
  upload.set_space("rigs");
  upload.mutable_bvh()->set_bvh(BvhText(rigs->copies[2]));
  upload.set_max_results(2);
  upload.set_explain(true);
  v1::SearchResponse found;
  status = client.Search(upload, &found);
  ASSERT_TRUE(status.ok()) << status.error_message();
  ASSERT_EQ(found.results_size(), 2);
  EXPECT_THAT((std::vector<int64_t>{found.results(0).clip_id(), found.results(1).clip_id()}),
              ::testing::UnorderedElementsAre(originals[2], copies[2]));
  // Explained by the humanoid's slots, whichever rig: each bone by its slot, the shoulder line
  // by both shoulders, and the heading's two extra parts.
  std::vector<std::string> parts;
  for (const v1::JointShare& part : found.results(0).explanation().joints()) {
    parts.push_back(part.name());
    EXPECT_TRUE(ParseHumanoidSlot(part.name()).has_value() || part.name() == "Shoulders" ||
                part.name() == "yaw rate" || part.name() == "root velocity")
        << part.name();
  }
  EXPECT_THAT(parts, ::testing::IsSupersetOf({"LeftUpperLeg", "RightLowerArm", "Spine"}));

  // Propagation runs in the space: a label on the walk reaches the walk's re-rigged copy.
  AddLabelsOrFail(client, {FrameLabel(originals[0], 10, 90, "walk", 1.0)});
  v1::StartPropagationRequest propagate = Propagation({"walk"});
  propagate.set_space("rigs");
  const v1::Job started = StartOrFail(client, propagate);
  const v1::Job ended = PollJob(client, started.job_id());
  ASSERT_EQ(ended.state(), v1::JOB_STATE_SUCCEEDED) << ended.error();
  bool reached_copy = false;
  for (const v1::Label& label : Propagated(client)) {
    reached_copy = reached_copy || (label.clip_id() == copies[0] && label.first_frame() < 90 &&
                                    label.last_frame() > 10);
  }
  EXPECT_TRUE(reached_copy);

  // A mirrored search runs there too: the upload still finds its take and copy first, unmarked
  // (a bow is nearly its own mirror, so its mirror's hits follow them), each result marked by
  // the half that found it.
  upload.set_mirror(true);
  upload.set_max_results(6);
  status = client.Search(upload, &found);
  ASSERT_TRUE(status.ok()) << status.error_message();
  ASSERT_GE(found.results_size(), 2);
  EXPECT_FALSE(found.results(0).mirrored());
  EXPECT_THAT((std::vector<int64_t>{found.results(0).clip_id(), found.results(1).clip_id()}),
              ::testing::UnorderedElementsAre(originals[2], copies[2]));
}

// A rig whose sides are mislabelled: `bvh` with Left and Right swapped in every joint's name.
std::string SidesSwapped(const std::string& bvh) {
  return absl::StrReplaceAll(
      absl::StrReplaceAll(absl::StrReplaceAll(bvh, {{"Left", "\x01"}}), {{"Right", "Left"}}),
      {{"\x01", "Right"}});
}

// A skeleton's map changed under a space over several skeletons re-projects its clips there:
// the humanoid library's map given its sides swapped makes its clips what a rig with the
// sides' names swapped captures, so that such a rig's upload of a library range finds that
// range exactly. A change that would leave a slot the bones need empty is refused and changes
// nothing.
TEST_F(ServerTest, AMapChangeProjectsTheSkeletonsClipsAgainInSpacesOverSeveralSkeletons) {
  ServerProcess* server = StartServer();
  ASSERT_NE(server, nullptr);
  Client client(testing::InsecureChannel(server->address()));
  const std::vector<int64_t> ids = IngestHumanoid(client);
  const v1::Space space = CreateBonesSpace(client, ids[0]);
  ASSERT_EQ(space.skeleton_ids_size(), 1);
  const int64_t skeleton_id = space.skeleton_ids(0);

  const testing::SyntheticSegment* raise = nullptr;
  for (const testing::SyntheticSegment& segment : Humanoid().segments) {
    if (segment.action == testing::SyntheticAction::kLeftArmRaise) raise = &segment;
  }
  ASSERT_NE(raise, nullptr);
  const absl::StatusOr<Clip> range =
      Humanoid().clips[raise->clip].Slice({raise->first_frame, raise->last_frame});
  ASSERT_TRUE(range.ok());
  v1::SearchRequest request;
  request.set_space("bones");
  request.mutable_bvh()->set_bvh(SidesSwapped(BvhText(*range)));
  request.set_max_results(1);
  v1::SearchResponse before;
  grpc::Status status = client.Search(request, &before);
  ASSERT_TRUE(status.ok()) << status.error_message();
  ASSERT_EQ(before.results_size(), 1);
  // The range as the library's own rig captured it: what "found exactly" scores (the range's
  // ends smooth its velocities otherwise than the whole clip's do).
  v1::SearchRequest own = request;
  own.mutable_bvh()->set_bvh(BvhText(*range));
  v1::SearchResponse exact;
  status = client.Search(own, &exact);
  ASSERT_TRUE(status.ok()) << status.error_message();
  ASSERT_EQ(exact.results_size(), 1);
  ASSERT_EQ(exact.results(0).clip_id(), ids[raise->clip]);

  const auto map = [&](const std::string& text, v1::SkeletonDetail* detail) {
    v1::MapSkeletonRequest change;
    EXPECT_TRUE(google::protobuf::TextFormat::ParseFromString(text, &change));
    change.set_skeleton_id(skeleton_id);
    return client.clips().MapSkeleton(client.Context().get(), change, detail);
  };
  std::string swap;
  for (const auto& [slot, joint] :
       std::vector<std::pair<std::string, std::string>>{{"UpperArm", "Shoulder"},
                                                        {"LowerArm", "Elbow"},
                                                        {"Hand", "Wrist"},
                                                        {"UpperLeg", "Hip"},
                                                        {"LowerLeg", "Knee"},
                                                        {"Foot", "Ankle"}}) {
    absl::StrAppend(&swap, "set { slot: 'Left", slot, "' joint: 'Right", joint, "' } ",
                    "set { slot: 'Right", slot, "' joint: 'Left", joint, "' } ");
  }
  v1::SkeletonDetail swapped;
  status = map(swap, &swapped);
  ASSERT_TRUE(status.ok()) << status.error_message();
  v1::SearchResponse after;
  status = client.Search(request, &after);
  ASSERT_TRUE(status.ok()) << status.error_message();
  ASSERT_EQ(after.results_size(), 1);
  EXPECT_EQ(after.results(0).clip_id(), ids[raise->clip]);
  EXPECT_NEAR(after.results(0).start_frame(), raise->first_frame, 2);
  EXPECT_NEAR(after.results(0).end_frame(), raise->last_frame, 2);
  // Not equal: the space's basis was fitted to the library's sides, not to their swap.
  EXPECT_NEAR(after.results(0).score(), exact.results(0).score(), 0.1 * exact.results(0).score());
  EXPECT_GT(before.results(0).score(), 2 * after.results(0).score())
      << before.results(0).score() << " then " << after.results(0).score();

  // The neck given the head's joint leaves the head without one: refused, nothing changed.
  v1::SkeletonDetail refused;
  status = map("set { slot: 'Neck' joint: 'Head' }", &refused);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::FAILED_PRECONDITION);
  EXPECT_THAT(status.error_message(), HasSubstr("space bones lists skeleton"));
  EXPECT_THAT(status.error_message(), HasSubstr("Head"));
  v1::GetSkeletonRequest show;
  show.set_skeleton_id(skeleton_id);
  v1::SkeletonDetail shown;
  ASSERT_TRUE(client.clips().GetSkeleton(client.Context().get(), show, &shown).ok());
  EXPECT_EQ(shown.SerializeAsString(), swapped.SerializeAsString());
  v1::SearchResponse again;
  ASSERT_TRUE(client.Search(request, &again).ok());
  ASSERT_EQ(again.results_size(), 1);
  EXPECT_EQ(again.results(0).SerializeAsString(), after.results(0).SerializeAsString());
}

TEST_F(ServerTest, ASkeletonWithoutArmsCannotJoinASpaceOverSeveral) {
  const std::optional<Rigs> rigs = LoadRigs();
  if (!rigs) GTEST_SKIP() << "../shared/mocap/bandai1 is absent; skipped";
  ServerProcess* server = StartServer();
  ASSERT_NE(server, nullptr);
  Client client(testing::InsecureChannel(server->address()));
  const int64_t take = client.IngestOrFail("walk.bvh", BvhText(rigs->originals[0]));
  const int64_t legs = client.IngestOrFail("legs.bvh", R"(HIERARCHY
ROOT Hips
{
  OFFSET 0 0 0
  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
  JOINT LeftUpLeg
  {
    OFFSET 1 0 0
    CHANNELS 3 Zrotation Xrotation Yrotation
    End Site
    {
      OFFSET 0 -4 0
    }
  }
  JOINT RightUpLeg
  {
    OFFSET -1 0 0
    CHANNELS 3 Zrotation Xrotation Yrotation
    End Site
    {
      OFFSET 0 -4 0
    }
  }
}
MOTION
Frames: 2
Frame Time: 0.033333
0 4 0 0 0 0 0 0 0 0 0 0
0 4 0 10 0 0 0 0 0 0 0 0
)");
  v1::GetClipRequest get;
  v1::Clip a, b;
  get.set_clip_id(take);
  ASSERT_TRUE(client.clips().GetClip(client.Context().get(), get, &a).ok());
  get.set_clip_id(legs);
  ASSERT_TRUE(client.clips().GetClip(client.Context().get(), get, &b).ok());
  v1::CreateSpaceRequest create;
  create.set_name("rigs");
  create.add_skeleton_ids(a.skeleton_id());
  create.add_skeleton_ids(b.skeleton_id());
  v1::Space space;
  const grpc::Status status = client.CreateSpace(create, &space);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::FAILED_PRECONDITION);
  EXPECT_THAT(status.error_message(), HasSubstr("LeftHand"));
  EXPECT_THAT(status.error_message(), HasSubstr(absl::StrCat("skeleton ", b.skeleton_id())));
}

}  // namespace
}  // namespace motiondb
