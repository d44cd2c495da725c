// Mirrored search through the real binary (SearchRequest.mirror): a query's left/right mirror
// searched beside it, its results marked; the query's own range left out of both halves; a
// skeleton that cannot be mirrored refused.
#include <optional>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/motion/clip_mirror.h"
#include "testing/server_process.h"
#include "testing/synthetic_corpus.h"
#include "tests/server_fixture.h"

namespace motiondb {
namespace {

using ::testing::HasSubstr;
using testing::ServerProcess;
using testing::SyntheticAction;
using testing::SyntheticSegment;

const SyntheticSegment& FirstOf(SyntheticAction action) {
  for (const SyntheticSegment& segment : Humanoid().segments) {
    if (segment.action == action) return segment;
  }
  ADD_FAILURE() << "the humanoid library performs no such action";
  return Humanoid().segments.front();
}

// The action performed on `frame` of library clip `clip`, if any.
std::optional<SyntheticAction> ActionAt(int clip, int first, int last) {
  for (const SyntheticSegment& segment : Humanoid().segments) {
    if (segment.clip == clip && first <= segment.last_frame && last >= segment.first_frame) {
      return segment.action;
    }
  }
  return std::nullopt;
}

// In `space`, over the humanoid library `ids`: a right-arm raise (a left one mirrored) finds
// right-arm raises; with `mirror` its source first, marked, and left-arm raises among the rest;
// a stored query's own range left out of both halves.
void ExpectMirroredSearchWorks(Client& client, const std::vector<int64_t>& ids,
                               const std::string& space) {
  // A left-arm raise, mirrored here into a right-arm raise and sent as the query.
  const SyntheticSegment& left = FirstOf(SyntheticAction::kLeftArmRaise);
  const absl::StatusOr<Clip> source =
      Humanoid().clips[left.clip].Slice({left.first_frame, left.last_frame});
  ASSERT_TRUE(source.ok());
  const absl::StatusOr<HumanoidMap> map = MapHumanoid(source->skeleton());
  ASSERT_TRUE(map.ok());
  const absl::StatusOr<SkeletonMirror> mirror = MakeSkeletonMirror(source->skeleton(), *map);
  ASSERT_TRUE(mirror.ok()) << mirror.status();
  const absl::StatusOr<Clip> mirrored = MirrorClip(*source, *mirror);
  ASSERT_TRUE(mirrored.ok());

  v1::SearchRequest request;
  request.set_space(space);
  request.mutable_bvh()->set_bvh(BvhText(*mirrored));
  request.set_max_results(8);
  v1::SearchResponse plain;
  grpc::Status status = client.Search(request, &plain);
  ASSERT_TRUE(status.ok()) << status.error_message();
  for (const v1::SearchResult& result : plain.results()) EXPECT_FALSE(result.mirrored());
  // The plain query, a right-arm raise, finds right-arm raises first.
  ASSERT_GE(plain.results_size(), 1);
  const auto action_of = [&](const v1::SearchResult& result) {
    for (size_t i = 0; i < ids.size(); ++i) {
      if (ids[i] == result.clip_id()) {
        return ActionAt(static_cast<int>(i), result.start_frame(), result.end_frame());
      }
    }
    return std::optional<SyntheticAction>();
  };
  EXPECT_EQ(action_of(plain.results(0)), SyntheticAction::kRightArmRaise);

  request.set_mirror(true);
  request.set_explain(true);
  v1::SearchResponse both;
  status = client.Search(request, &both);
  ASSERT_TRUE(status.ok()) << status.error_message();
  ASSERT_GE(both.results_size(), 2);
  EXPECT_LE(both.results_size(), 8);
  // The query's mirror is the source itself: found first, marked, at its own frames.
  const v1::SearchResult& first = both.results(0);
  EXPECT_TRUE(first.mirrored());
  EXPECT_EQ(first.clip_id(), ids[left.clip]);
  EXPECT_NEAR(first.start_frame(), left.first_frame, 2);
  EXPECT_NEAR(first.end_frame(), left.last_frame, 2);
  EXPECT_LT(first.score(), plain.results(0).score());
  EXPECT_TRUE(first.has_explanation());
  // Both halves' results, ranked together: marked by the half that found them, best first.
  int mirrored_count = 0;
  for (int i = 0; i < both.results_size(); ++i) {
    const v1::SearchResult& result = both.results(i);
    if (i > 0) {
      EXPECT_GE(result.score(), both.results(i - 1).score());
    }
    mirrored_count += result.mirrored() ? 1 : 0;
    EXPECT_EQ(action_of(result),
              result.mirrored() ? SyntheticAction::kLeftArmRaise : SyntheticAction::kRightArmRaise)
        << "result " << i;
  }
  EXPECT_GT(mirrored_count, 0);
  EXPECT_LT(mirrored_count, both.results_size());

  // A stored query's own range is left out of both halves. Both arms raised: the query's mirror
  // moves as the query does, and would find its own range.
  const SyntheticSegment& both_arms = FirstOf(SyntheticAction::kBothArmsRaise);
  request = ClipQuery(space, ids[both_arms.clip], both_arms.first_frame, both_arms.last_frame);
  request.set_mirror(true);
  request.set_max_results(6);
  request.set_characteristic_frame((both_arms.peak_first_frame + both_arms.peak_last_frame) / 2);
  v1::SearchResponse kept;
  status = client.Search(request, &kept);  // exclude_query false: ClipQuery's
  ASSERT_TRUE(status.ok()) << status.error_message();
  ASSERT_GE(kept.results_size(), 2);
  const auto own = [&](const v1::SearchResult& result) {
    return result.clip_id() == ids[both_arms.clip] &&
           result.start_frame() <= both_arms.last_frame &&
           result.end_frame() >= both_arms.first_frame;
  };
  // Kept: the query finds itself first, and its mirror's match of the same range overlaps it
  // and is suppressed.
  EXPECT_TRUE(own(kept.results(0)));
  EXPECT_FALSE(kept.results(0).mirrored());
  for (int i = 1; i < kept.results_size(); ++i) EXPECT_FALSE(own(kept.results(i))) << i;

  request.set_exclude_query(true);
  v1::SearchResponse excluded;
  status = client.Search(request, &excluded);
  ASSERT_TRUE(status.ok()) << status.error_message();
  ASSERT_GE(excluded.results_size(), 1);
  for (const v1::SearchResult& result : excluded.results()) EXPECT_FALSE(own(result));
}

TEST_F(ServerTest, AMirroredQueryFindsItsSourceMarkedMirroredAndLeavesItsOwnRangeOut) {
  ServerProcess* server = StartServer();
  ASSERT_NE(server, nullptr);
  Client client(testing::InsecureChannel(server->address()));
  const std::vector<int64_t> ids = IngestHumanoid(client);
  CreateHumanoidSpace(client);
  ExpectMirroredSearchWorks(client, ids, "body");
}

// The same in a space of canonical bone directions (a space over several skeletons, here over
// the humanoid's one): the query's poses are mirrored, not its joints.
TEST_F(ServerTest, AMirroredQueryWorksInASpaceOverSeveralSkeletons) {
  ServerProcess* server = StartServer();
  ASSERT_NE(server, nullptr);
  Client client(testing::InsecureChannel(server->address()));
  const std::vector<int64_t> ids = IngestHumanoid(client);
  CreateBonesSpace(client, ids[0]);
  ExpectMirroredSearchWorks(client, ids, "bones");
}

TEST_F(ServerTest, ASkeletonItsMapCannotMirrorIsRefused) {
  ServerProcess* server = StartServer();
  ASSERT_NE(server, nullptr);
  Client client(testing::InsecureChannel(server->address()));
  const int64_t clip = client.IngestOrFail("chain.bvh", BvhText(ChainClip()));
  client.IngestOrFail("chain2.bvh", BvhText(ChainClip(0.05)));
  v1::CreateSpaceRequest create;
  create.set_name("chain");
  v1::Space space;
  ASSERT_TRUE(client.CreateSpace(create, &space).ok());

  v1::SearchRequest request = ClipQuery("chain", clip, 0, 30);
  request.set_mirror(true);
  v1::SearchResponse found;
  const grpc::Status status = client.Search(request, &found);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::FAILED_PRECONDITION);
  EXPECT_THAT(status.error_message(), HasSubstr("cannot be mirrored"));
  EXPECT_THAT(status.error_message(), HasSubstr("LeftUpperArm"));
  EXPECT_THAT(status.error_message(), HasSubstr("skeletons map"));
  // Nothing else changed: the plain search still answers.
  request.set_mirror(false);
  EXPECT_TRUE(client.Search(request, &found).ok());
}

}  // namespace
}  // namespace motiondb
