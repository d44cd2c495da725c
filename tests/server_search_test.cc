// The server's spaces and search, through the real binary and the generated stubs
// (server_fixture.h): spaces built and searched, curves, real clips and skeleton mismatches.
#include <cstring>
#include <filesystem>
#include <tuple>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "testing/server_process.h"
#include "testing/synthetic_corpus.h"
#include "tests/server_fixture.h"
#include "tests/test_data.h"
#include "util/parallel_for.h"

namespace motiondb {
namespace {

using ::testing::HasSubstr;
using testing::ServerProcess;
using testing::SyntheticAction;
using testing::SyntheticSegment;

TEST_F(ServerTest, CreateSpaceSearchAndCurve) {
  ServerProcess* server = StartServer();
  ASSERT_NE(server, nullptr);
  Client client(testing::InsecureChannel(server->address()));
  const std::vector<int64_t> ids = IngestHumanoid(client);
  ASSERT_GE(ids.size(), 2u);

  const v1::Space space = CreateHumanoidSpace(client);
  EXPECT_EQ(space.name(), "body");
  const v1::SpaceBuildReport& report = space.report();
  EXPECT_EQ(report.joint_count(), 21);
  EXPECT_EQ(report.dims(), 21 * 3 + 3);  // every joint, plus the yaw rate and root velocity
  EXPECT_EQ(report.root_velocity_weight(), 0.5);
  EXPECT_EQ(report.explained_variance_size(), report.dims());
  EXPECT_EQ(report.training_size(), static_cast<int>(ids.size()));
  EXPECT_EQ(report.projected_clips(), static_cast<int64_t>(ids.size()));
  EXPECT_FALSE(report.reconstruction_error().empty());
  EXPECT_EQ(report.metric(), v1::SPACE_METRIC_UNIT);
  EXPECT_EQ(report.weight_preset(), v1::WEIGHT_PRESET_MASS);
  EXPECT_EQ(space.index().clips(), static_cast<int64_t>(ids.size()));
  EXPECT_GT(space.index().coordinate_bytes(), 0);

  // GetSpace returns the stored report; ListSpaces lists it.
  v1::GetSpaceRequest get;
  get.set_name("body");
  v1::Space got;
  ASSERT_TRUE(client.spaces().GetSpace(client.Context().get(), get, &got).ok());
  EXPECT_EQ(got.report().SerializeAsString(), report.SerializeAsString());
  v1::ListSpacesResponse spaces;
  ASSERT_TRUE(
      client.spaces().ListSpaces(client.Context().get(), v1::ListSpacesRequest(), &spaces).ok());
  ASSERT_EQ(spaces.spaces_size(), 1);
  EXPECT_EQ(spaces.spaces(0).space_id(), space.space_id());

  // root_velocity_weight 0 leaves its two dimensions out; a negative one is refused.
  v1::CreateSpaceRequest still;
  still.set_name("still");
  still.set_root_velocity_weight(0);
  v1::Space still_space;
  ASSERT_TRUE(client.CreateSpace(still, &still_space).ok());
  EXPECT_EQ(still_space.report().dims(), 21 * 3 + 1);
  EXPECT_EQ(still_space.report().root_velocity_weight(), 0.0);
  still.set_name("backwards");
  still.set_root_velocity_weight(-1);
  const grpc::Status refused = client.CreateSpace(still, &still_space);
  EXPECT_EQ(refused.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(refused.error_message(), HasSubstr("root-velocity weight"));
  v1::DeleteSpaceRequest drop_still;
  drop_still.set_name("still");
  v1::DeleteSpaceResponse still_dropped;
  ASSERT_TRUE(client.spaces().DeleteSpace(client.Context().get(), drop_still, &still_dropped).ok());

  // A clip ingested now is projected into the space at once.
  v1::IngestClipResponse late;
  ASSERT_TRUE(client.Ingest("late.bvh", BvhText(Humanoid().clips[1]), &late).ok());
  EXPECT_THAT(late.projected_spaces(), ::testing::ElementsAre("body"));

  // The first right-arm raise, queried as a stored range, finds itself first with score ~0.
  const SyntheticSegment& raise = FirstRaise();
  const int64_t raise_clip = ids[raise.clip];
  v1::SearchRequest query = ClipQuery("body", raise_clip, raise.first_frame, raise.last_frame);
  query.set_return_path(true);
  v1::SearchResponse found;
  grpc::Status status = client.Search(query, &found);
  ASSERT_TRUE(status.ok()) << status.error_message();
  ASSERT_GE(found.results_size(), 3);
  const v1::SearchResult& best = found.results(0);
  EXPECT_EQ(best.clip_id(), raise_clip);
  EXPECT_NEAR(best.start_frame(), raise.first_frame, 2);
  EXPECT_NEAR(best.end_frame(), raise.last_frame, 2);
  EXPECT_LT(best.score(), 1e-3);
  EXPECT_NEAR(best.start_s(), raise.first_frame / 50.0, 0.05);
  EXPECT_GE(best.seed_frame(), best.start_frame());
  EXPECT_LE(best.seed_frame(), best.end_frame());
  EXPECT_EQ(best.path_size(), found.counts().query_frames());
  EXPECT_GE(found.characteristic_frame(), raise.first_frame);
  EXPECT_LE(found.characteristic_frame(), raise.last_frame);
  EXPECT_GT(found.counts().seeds(), 0);
  EXPECT_GT(found.counts().warps(), 0);
  EXPECT_GT(found.timings().total_ms(), 0);
  // Alone on the server the search took every core; the threads asked are taken, with the same
  // results; a bad count is refused by name.
  EXPECT_EQ(found.counts().threads(), ThreadsFor(0));
  for (const int threads : {1, 3}) {
    v1::SearchRequest asked = query;
    asked.set_threads(threads);
    v1::SearchResponse same;
    ASSERT_TRUE(client.Search(asked, &same).ok());
    EXPECT_EQ(same.counts().threads(), std::min(threads, ThreadsFor(0)));  // at most the cores
    ASSERT_EQ(same.results_size(), found.results_size());
    for (int i = 0; i < found.results_size(); ++i) {
      EXPECT_EQ(same.results(i).SerializeAsString(), found.results(i).SerializeAsString()) << i;
    }
  }
  v1::SearchRequest too_many = query;
  too_many.set_threads(5000);
  v1::SearchResponse refused_threads;
  status = client.Search(too_many, &refused_threads);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("threads"));
  for (int i = 1; i < found.results_size(); ++i) {
    EXPECT_LE(found.results(i - 1).score(), found.results(i).score());
  }
  // The other right-arm raises come next: every top result is one.
  int raises_found = 0;
  for (const SyntheticSegment& segment : Humanoid().segments) {
    if (segment.action != SyntheticAction::kRightArmRaise) continue;
    for (int i = 0; i < 4 && i < found.results_size(); ++i) {
      const v1::SearchResult& r = found.results(i);
      if (r.clip_id() == ids[segment.clip] && r.start_frame() <= segment.last_frame &&
          r.end_frame() >= segment.first_frame) {
        ++raises_found;
        break;
      }
    }
  }
  EXPECT_EQ(raises_found, 4);

  // One frame, the raise's middle, is a pose query: one-frame places, the frame itself first.
  const int peak = (raise.first_frame + raise.last_frame) / 2;
  v1::SearchResponse poses;
  status = client.Search(ClipQuery("body", raise_clip, peak, peak), &poses);
  ASSERT_TRUE(status.ok()) << status.error_message();
  ASSERT_GE(poses.results_size(), 4);
  EXPECT_EQ(poses.results(0).clip_id(), raise_clip);
  EXPECT_NEAR(poses.results(0).start_frame(), peak, 2);  // the nearest 30 Hz sample
  EXPECT_LT(poses.results(0).score(), 1e-3);
  for (const v1::SearchResult& r : poses.results()) EXPECT_EQ(r.start_frame(), r.end_frame());
  EXPECT_EQ(poses.counts().warps(), 0);
  v1::SearchRequest explained_pose = ClipQuery("body", raise_clip, peak, peak);
  explained_pose.set_explain(true);
  status = client.Search(explained_pose, &poses);
  ASSERT_TRUE(status.ok()) << status.error_message();
  ASSERT_GE(poses.results_size(), 4);
  for (const v1::SearchResult& r : poses.results()) {
    EXPECT_TRUE(r.has_explanation());
    EXPECT_EQ(r.path_size(), 0);
  }

  // explain: each result says which joints its distance lies in and how fast it plays; the
  // path it needs is returned only when asked for.
  v1::SearchRequest explained_query = query;
  explained_query.set_return_path(false);
  explained_query.set_explain(true);
  v1::SearchResponse explained;
  status = client.Search(explained_query, &explained);
  ASSERT_TRUE(status.ok()) << status.error_message();
  ASSERT_EQ(explained.results_size(), found.results_size());
  for (const v1::SearchResult& r : explained.results()) {
    EXPECT_EQ(r.path_size(), 0);
    ASSERT_TRUE(r.has_explanation());
    const v1::SearchExplanation& why = r.explanation();
    EXPECT_EQ(why.joints_size(), 21 + 2);  // every joint, the yaw rate, the root velocity
    double shares = 0, parts = 0;
    for (const v1::JointShare& joint : why.joints()) {
      shares += joint.share();
      parts += joint.score();
    }
    // The query's own range differs in nothing: nothing to share out.
    EXPECT_NEAR(shares, why.full_score() > 0 ? 1.0 : 0.0, 1e-9);
    EXPECT_NEAR(parts, why.full_score(), 1e-9);
    EXPECT_GE(why.full_score(), r.score() * (1 - 1e-4));  // the score counts 5 dimensions
    EXPECT_GT(why.mean_speed(), 0);
    EXPECT_GE(why.max_speed(), why.mean_speed() * (1 - 1e-9));
  }
  EXPECT_NEAR(explained.results(0).explanation().mean_speed(), 1.0, 0.05);  // itself
  // The exact search explains its results too, and returns their paths (it answered INTERNAL
  // and no path: found by the search_request fuzzer).
  explained_query.set_exact(true);
  explained_query.set_return_path(true);
  status = client.Search(explained_query, &explained);
  ASSERT_TRUE(status.ok()) << status.error_message();
  ASSERT_GT(explained.results_size(), 0);
  for (const v1::SearchResult& r : explained.results()) {
    EXPECT_TRUE(r.has_explanation());
    ASSERT_GT(r.path_size(), 0);
    EXPECT_EQ(r.path(0), r.start_frame());
    EXPECT_EQ(r.path(r.path_size() - 1), r.end_frame());
  }

  // The same range uploaded as BVH gives the same results.
  v1::SearchRequest uploaded = query;
  uploaded.mutable_bvh()->set_bvh(BvhText(Humanoid().clips[raise.clip]));
  uploaded.mutable_bvh()->set_first_frame(raise.first_frame);
  uploaded.mutable_bvh()->set_last_frame(raise.last_frame);
  v1::SearchResponse found_uploaded;
  status = client.Search(uploaded, &found_uploaded);
  ASSERT_TRUE(status.ok()) << status.error_message();
  ASSERT_EQ(found_uploaded.results_size(), found.results_size());
  // The BVH text round trip moves coordinates by ~1e-6, which may swap results whose scores
  // are as close: match them by place, not rank.
  for (const v1::SearchResult& r : found.results()) {
    const auto same =
        std::find_if(found_uploaded.results().begin(), found_uploaded.results().end(),
                     [&](const v1::SearchResult& u) {
                       return u.clip_id() == r.clip_id() && u.start_frame() == r.start_frame();
                     });
    ASSERT_NE(same, found_uploaded.results().end()) << r.clip_name() << " " << r.start_frame();
    EXPECT_NEAR(same->score(), r.score(), 1e-4);
  }

  // By default a stored query's own range is left out, and max_results still filled.
  for (const bool exact : {false, true}) {
    v1::SearchRequest unset = query;
    unset.clear_exclude_query();
    unset.set_exact(exact);
    unset.set_max_results(found.results_size());
    v1::SearchResponse others;
    ASSERT_TRUE(client.Search(unset, &others).ok());
    EXPECT_EQ(others.results_size(), found.results_size()) << exact;
    for (const v1::SearchResult& r : others.results()) {
      EXPECT_FALSE(r.clip_id() == raise_clip && r.start_frame() <= raise.last_frame &&
                   r.end_frame() >= raise.first_frame)
          << "exact " << exact << ": " << r.start_frame() << "-" << r.end_frame();
    }
    // The other raises stay on top.
    ASSERT_GE(others.results_size(), 1);
    EXPECT_LT(others.results(0).score(), found.results(3).score() + 1e-9) << exact;
  }
  // An upload is no stored range: exclude_query does not apply.
  v1::SearchRequest uploaded_excluding = uploaded;
  uploaded_excluding.set_exclude_query(true);
  v1::SearchResponse found_uploaded_excluding;
  ASSERT_TRUE(client.Search(uploaded_excluding, &found_uploaded_excluding).ok());
  EXPECT_EQ(found_uploaded_excluding.results_size(), found_uploaded.results_size());

  // Filters, a given characteristic frame, and exact mode.
  v1::SearchRequest filtered = query;
  filtered.add_tags("clip" + std::to_string(raise.clip));
  filtered.set_characteristic_frame((raise.peak_first_frame + raise.peak_last_frame) / 2);
  ASSERT_TRUE(client.Search(filtered, &found).ok());
  ASSERT_GE(found.results_size(), 1);
  for (const v1::SearchResult& r : found.results()) EXPECT_EQ(r.clip_id(), raise_clip);
  EXPECT_NEAR(found.characteristic_frame(), filtered.characteristic_frame(), 1);
  EXPECT_EQ(found.second_anchor_frame(), -1);
  // A second anchor (asked for at any scatter) comes back in the query's own frames, a quarter
  // of the query or more from the characteristic frame.
  v1::SearchRequest second = query;
  second.set_second_anchor_scatter(1e-6);
  ASSERT_TRUE(client.Search(second, &found).ok());
  ASSERT_GE(found.results_size(), 1);
  EXPECT_GE(found.second_anchor_frame(), raise.first_frame);
  EXPECT_LE(found.second_anchor_frame(), raise.last_frame);
  EXPECT_GE(std::abs(found.second_anchor_frame() - found.characteristic_frame()),
            (raise.last_frame - raise.first_frame) / 4 - 1);
  // Several characteristic points, given in the query's own frames, come back in them.
  v1::SearchRequest several = query;
  several.add_characteristic_frames(raise.first_frame + 5);
  several.add_characteristic_frames((raise.peak_first_frame + raise.peak_last_frame) / 2);
  ASSERT_TRUE(client.Search(several, &found).ok());
  ASSERT_GE(found.results_size(), 1);
  ASSERT_EQ(found.characteristic_frames_size(), 2);
  EXPECT_NEAR(found.characteristic_frames(0), several.characteristic_frames(0), 1);
  EXPECT_NEAR(found.characteristic_frames(1), several.characteristic_frames(1), 1);
  EXPECT_EQ(found.characteristic_frame(), found.characteristic_frames(0));
  v1::SearchRequest found_points = query;
  found_points.set_characteristic_points(3);
  ASSERT_TRUE(client.Search(found_points, &found).ok());
  EXPECT_EQ(found.characteristic_frames_size(), 3);
  v1::SearchRequest exact = query;
  exact.set_exact(true);
  exact.set_max_results(3);
  ASSERT_TRUE(client.Search(exact, &found).ok());
  ASSERT_EQ(found.results_size(), 3);
  EXPECT_EQ(found.results(0).clip_id(), raise_clip);
  EXPECT_LT(found.results(0).score(), 1e-3);
  EXPECT_EQ(found.results(0).seed_frame(), -1);

  // A batch: per-item status.
  v1::SearchBatchRequest batch;
  *batch.add_requests() = query;
  *batch.add_requests() = ClipQuery("no-such-space", raise_clip, 0, 10);
  v1::SearchBatchResponse batch_response;
  ASSERT_TRUE(client.search().SearchBatch(client.Context().get(), batch, &batch_response).ok());
  ASSERT_EQ(batch_response.items_size(), 2);
  EXPECT_EQ(batch_response.items(0).code(), 0);
  EXPECT_EQ(batch_response.items(0).response().results(0).clip_id(), raise_clip);
  EXPECT_EQ(batch_response.items(1).code(), grpc::StatusCode::NOT_FOUND);
  EXPECT_THAT(batch_response.items(1).message(), HasSubstr("requests[1]"));

  // The motion curve: frames x dims float32 at 30 Hz.
  v1::GetCurveRequest curve_request;
  curve_request.set_space("body");
  curve_request.mutable_clip()->set_clip_id(raise_clip);
  v1::GetCurveResponse curve;
  ASSERT_TRUE(client.spaces().GetCurve(client.Context().get(), curve_request, &curve).ok());
  EXPECT_EQ(curve.dims(), 3);
  const Clip& source = Humanoid().clips[raise.clip];
  EXPECT_NEAR(curve.frames(), (source.frame_count() - 1) * 30.0 / 50 + 1, 1.0);
  ASSERT_EQ(curve.coordinates().size(), static_cast<size_t>(curve.frames()) * 3 * 4);
  std::vector<float> values(curve.frames() * 3);
  std::memcpy(values.data(), curve.coordinates().data(), curve.coordinates().size());
  const auto [lowest, highest] = std::minmax_element(values.begin(), values.end());
  EXPECT_GT(*highest - *lowest, 0.1f);  // the arm raises move the curve
  // A range is the matching rows of the whole curve.
  curve_request.mutable_clip()->set_first_frame(raise.first_frame);
  curve_request.mutable_clip()->set_last_frame(raise.last_frame);
  curve_request.set_dims(5);
  v1::GetCurveResponse part;
  ASSERT_TRUE(client.spaces().GetCurve(client.Context().get(), curve_request, &part).ok());
  EXPECT_EQ(part.dims(), 5);
  EXPECT_EQ(part.first_frame(), raise.first_frame);
  const int first_row = static_cast<int>(std::lround(raise.first_frame * 30.0 / 50));
  float first_value;
  std::memcpy(&first_value, part.coordinates().data(), 4);
  EXPECT_FLOAT_EQ(first_value, values[first_row * 3]);

  // Server info.
  v1::ServerInfo info;
  ASSERT_TRUE(client.server()
                  .GetServerInfo(client.Context().get(), v1::GetServerInfoRequest(), &info)
                  .ok());
  EXPECT_EQ(info.version(), "0.1.0");
  EXPECT_EQ(info.counts().clips(), static_cast<int64_t>(ids.size()) + 1);
  EXPECT_EQ(info.counts().spaces(), 1);
  ASSERT_EQ(info.indices_size(), 1);
  EXPECT_EQ(info.indices(0).space(), "body");
  EXPECT_EQ(info.index_bytes(),
            info.indices(0).index().coordinate_bytes() + info.indices(0).index().tree_bytes());
  EXPECT_FALSE(info.auth_required());

  // Deleting a clip drops it from the index; deleting the space removes it.
  v1::DeleteClipRequest remove;
  remove.set_clip_id(late.clip().clip_id());
  v1::DeleteClipResponse removed;
  ASSERT_TRUE(client.clips().DeleteClip(client.Context().get(), remove, &removed).ok());
  ASSERT_TRUE(client.spaces().GetSpace(client.Context().get(), get, &got).ok());
  EXPECT_EQ(got.index().clips(), static_cast<int64_t>(ids.size()));
  v1::DeleteSpaceRequest drop;
  drop.set_name("body");
  v1::DeleteSpaceResponse dropped;
  ASSERT_TRUE(client.spaces().DeleteSpace(client.Context().get(), drop, &dropped).ok());
  EXPECT_EQ(client.Search(query, &found).error_code(), grpc::StatusCode::NOT_FOUND);
}

TEST_F(ServerTest, RealClipsSearchAndSkeletonMismatch) {
  const std::optional<std::filesystem::path> dir = testing::AssimpBvhDir();
  if (!dir) GTEST_SKIP() << "assimp-testmodels is not installed; skipped";
  ServerProcess* server = StartServer();
  ASSERT_NE(server, nullptr);
  Client client(testing::InsecureChannel(server->address()));
  const int64_t walk = client.IngestOrFail("01_01.bvh", testing::ReadFileOrDie(*dir / "01_01.bvh"));
  const int64_t other =
      client.IngestOrFail("01_03.bvh", testing::ReadFileOrDie(*dir / "01_03.bvh"));
  const std::string boxing_text = testing::ReadFileOrDie(*dir / "Boxing_Toes.bvh");
  const int64_t boxing = client.IngestOrFail("Boxing_Toes.bvh", boxing_text);

  // Two skeletons: a space needs to be told which.
  v1::CreateSpaceRequest create;
  create.set_name("cmu");
  v1::Space space;
  grpc::Status status = client.CreateSpace(create, &space);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("skeleton_id"));
  v1::ClipRange* training = create.add_training();
  training->set_clip_id(walk);
  training->set_first_frame(0);
  training->set_last_frame(1999);
  create.set_keep_heading(true);
  create.set_weight_preset(v1::WEIGHT_PRESET_UNIFORM);
  (*create.mutable_weight_overrides())["Hips"] = 2.0;
  status = client.CreateSpace(create, &space);
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_EQ(space.report().dims(), 31 * 3);
  EXPECT_FALSE(space.report().heading_removed());
  EXPECT_EQ(space.report().projected_clips(), 2);  // both CMU clips, not the boxer
  EXPECT_EQ(space.report().training(0).last_frame(), 1999);
  EXPECT_EQ(space.report().joint_weights(0).joint(), "Hips");
  EXPECT_DOUBLE_EQ(space.report().joint_weights(0).weight(), 2.0);

  // Ranges of one clip, apart and side by side: the training reads its clips as it goes.
  v1::CreateSpaceRequest ranges;
  ranges.set_name("cmu-ranges");
  for (const auto& [clip, first, last] :
       {std::tuple{walk, 0, 999}, std::tuple{other, 0, 99}, std::tuple{walk, 1000, 1999},
        std::tuple{walk, 100, 199}}) {
    v1::ClipRange* range = ranges.add_training();
    range->set_clip_id(clip);
    range->set_first_frame(first);
    range->set_last_frame(last);
  }
  v1::Space ranged;
  status = client.CreateSpace(ranges, &ranged);
  ASSERT_TRUE(status.ok()) << status.error_message();
  ASSERT_EQ(ranged.report().training_size(), 4);
  EXPECT_EQ(ranged.report().training(1).clip_id(), other);
  EXPECT_EQ(ranged.report().training(2).first_frame(), 1000);
  EXPECT_EQ(ranged.report().training(3).last_frame(), 199);
  EXPECT_EQ(ranged.report().training_frames(), (1000 + 100 + 1000 + 100) / 4);  // 120 -> 30 Hz

  v1::SearchResponse found;
  status = client.Search(ClipQuery("cmu", walk, 1000, 1240), &found);
  ASSERT_TRUE(status.ok()) << status.error_message();
  ASSERT_GE(found.results_size(), 1);
  EXPECT_EQ(found.results(0).clip_id(), walk);
  EXPECT_NEAR(found.results(0).start_frame(), 1000, 4);  // 120 fps, sampled at 30 Hz
  EXPECT_NEAR(found.results(0).end_frame(), 1240, 4);
  EXPECT_LT(found.results(0).score(), 1e-3);
  status = client.Search(ClipQuery("cmu", other, 0, 400), &found);
  ASSERT_TRUE(status.ok()) << status.error_message();

  // The boxer's skeleton is not the space's: as a stored clip and as an upload.
  status = client.Search(ClipQuery("cmu", boxing, 0, 100), &found);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::FAILED_PRECONDITION);
  EXPECT_THAT(status.error_message(), HasSubstr("skeleton"));
  v1::SearchRequest upload;
  upload.set_space("cmu");
  upload.mutable_bvh()->set_bvh(boxing_text);
  status = client.Search(upload, &found);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::FAILED_PRECONDITION);
  EXPECT_THAT(status.error_message(), HasSubstr("skeleton"));
  // Training on clips of two skeletons.
  v1::CreateSpaceRequest mixed;
  mixed.set_name("mixed");
  mixed.add_training()->set_clip_id(walk);
  mixed.add_training()->set_clip_id(boxing);
  EXPECT_EQ(client.CreateSpace(mixed, &space).error_code(), grpc::StatusCode::FAILED_PRECONDITION);
  v1::GetCurveRequest curve;
  curve.set_space("cmu");
  curve.mutable_clip()->set_clip_id(boxing);
  v1::GetCurveResponse curve_response;
  EXPECT_EQ(client.spaces().GetCurve(client.Context().get(), curve, &curve_response).error_code(),
            grpc::StatusCode::FAILED_PRECONDITION);
}

}  // namespace
}  // namespace motiondb
