// EditService (issue 16) through the real motiondb-server on a loopback port: every operator's
// result as BVH with the source's hierarchy, stored as a clip with its provenance when asked,
// searchable and exportable; the closed forms that survive the trip (identities, endpoints,
// weights); and bad input of every kind refused naming the field, with nothing stored.

#include <cmath>
#include <filesystem>
#include <memory>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/bvh/bvh_reader.h"
#include "core/bvh/bvh_writer.h"
#include "motiondb/v1/clip_service.grpc.pb.h"
#include "motiondb/v1/edit_service.grpc.pb.h"
#include "motiondb/v1/search_service.grpc.pb.h"
#include "motiondb/v1/space_service.grpc.pb.h"
#include "testing/server_process.h"
#include "tests/synthetic_motion.h"
#include "tests/test_data.h"

namespace motiondb {
namespace {

namespace v1 = ::motiondb::v1;
using ::testing::HasSubstr;

constexpr double kFps = 30.0;  // the clips' rate and the space's: no resampling on the way

// The server and its library, shared by the suite: four synthetic humanoid clips and a space.
struct Library {
  std::filesystem::path dir;
  testing::ServerProcess server;
  std::shared_ptr<grpc::Channel> channel;
  std::vector<Clip> clips;   // as ingested
  std::vector<int64_t> ids;  // their clip ids
};

Library* library = nullptr;

std::unique_ptr<grpc::ClientContext> Context() {
  auto context = std::make_unique<grpc::ClientContext>();
  context->set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(60));
  return context;
}

v1::ClipRange Range(int index, int first, int last) {
  v1::ClipRange range;
  range.set_clip_id(library->ids[index]);
  range.set_first_frame(first);
  range.set_last_frame(last);
  return range;
}

Clip ParseBvh(const std::string& text) {
  absl::StatusOr<BvhReadResult> read = ReadBvh(text);
  EXPECT_TRUE(read.ok()) << read.status();
  // The failure is recorded; a stand-in keeps the test running to its other checks.
  return read.ok() ? read->clip : library->clips.front();
}

int64_t ClipCount() {
  v1::ListClipsRequest request;
  request.set_page_size(1000);
  v1::ListClipsResponse response;
  EXPECT_TRUE(v1::ClipService::NewStub(library->channel)
                  ->ListClips(Context().get(), request, &response)
                  .ok());
  return response.clips_size();
}

// The largest angle between joints of the same name at the same frame (the BVH writer lists
// joints depth first, the synthetic skeleton side by side).
double MaxAngleByName(const Clip& a, const Clip& b) {
  double worst = 0.0;
  for (int j = 0; j < a.skeleton().joint_count(); ++j) {
    const int k = b.skeleton().FindJoint(a.skeleton().joint(j).name);
    EXPECT_GE(k, 0);
    for (int f = 0; f < std::min(a.frame_count(), b.frame_count()); ++f) {
      worst = std::max(worst, AngleBetween(a.rotation(f, j), b.rotation(f, k)));
    }
  }
  return worst;
}

class EditServiceTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    library = new Library;
    library->dir = testing::MakeTempDir("edit_service_test");
    std::string error;
    ASSERT_TRUE(library->server.Start({"--db", (library->dir / "db.sqlite").string()}, &error))
        << error;
    library->channel = testing::InsecureChannel(library->server.address());
    ASSERT_TRUE(testing::WaitUntilServing(library->channel, ""));
    const auto skeleton = testing::HumanoidSkeleton(/*still_root=*/true);
    auto clips = v1::ClipService::NewStub(library->channel);
    for (int seed = 1; seed <= 4; ++seed) {
      library->clips.push_back(testing::SyntheticClip(
          skeleton, {.frames = 150, .fps = kFps, .turn_rate = 0.3 * seed, .seed = seed}));
      v1::IngestClipRequest request;
      request.set_file_name("take" + std::to_string(seed) + ".bvh");
      request.set_bvh(*WriteBvh(library->clips.back()));
      v1::IngestClipResponse response;
      ASSERT_TRUE(clips->IngestClip(Context().get(), request, &response).ok());
      library->ids.push_back(response.clip().clip_id());
      // The stored clip, as the server reads it back (the writer's joint order).
      library->clips.back() = ParseBvh(request.bvh());
    }
    v1::CreateSpaceRequest space;
    space.set_name("body");
    space.set_sample_rate(kFps);
    v1::Space created;
    const grpc::Status status =
        v1::SpaceService::NewStub(library->channel)->CreateSpace(Context().get(), space, &created);
    ASSERT_TRUE(status.ok()) << status.error_message();
  }
  static void TearDownTestSuite() {
    if (library == nullptr) return;
    library->server.Stop(SIGTERM);
    std::filesystem::remove_all(library->dir);
    delete library;
    library = nullptr;
  }
  void TearDown() override {
    if (HasFailure()) std::cerr << "---- server log ----\n" << library->server.Log() << "\n";
  }

  std::unique_ptr<v1::EditService::Stub> edits_ = v1::EditService::NewStub(library->channel);
};

TEST_F(EditServiceTest, ScaleByOneGivesTheSourceBackAndAStoredResultCarriesItsProvenance) {
  v1::ScaleRequest request;
  request.set_space("body");
  *request.mutable_clip() = Range(0, 10, 109);
  request.set_factor(1.0);
  v1::EditResponse response;
  grpc::Status status = edits_->Scale(Context().get(), request, &response);
  ASSERT_TRUE(status.ok()) << status.error_message();
  const Clip same = ParseBvh(response.result().bvh());
  ASSERT_EQ(same.frame_count(), 100);
  EXPECT_EQ(response.result().frames(), 100);
  EXPECT_DOUBLE_EQ(response.result().fps(), kFps);
  EXPECT_FALSE(response.result().has_stored());
  EXPECT_LT(MaxAngleByName(same, *library->clips[0].Slice({10, 109})), 1e-4);

  // Exaggerated under a gate, and kept.
  request.set_factor(2.0);
  v1::Gate* gate = request.mutable_scope()->mutable_gate();
  gate->set_start_s(1.5);
  gate->set_end_s(2.5);
  gate->set_lead_in_s(0.5);
  gate->set_lead_out_s(0.5);
  request.mutable_output()->set_store_name("take1-exaggerated");
  request.mutable_output()->add_store_tags("edited");
  status = edits_->Scale(Context().get(), request, &response);
  ASSERT_TRUE(status.ok()) << status.error_message();
  ASSERT_TRUE(response.result().has_stored());
  const v1::Clip& stored = response.result().stored();
  EXPECT_EQ(stored.name(), "take1-exaggerated");
  EXPECT_EQ(stored.frame_count(), 100);
  const Clip edited = ParseBvh(response.result().bvh());
  // Outside the gate (before 1 s from frame 0, i.e. range frames 0-19) nothing changed.
  EXPECT_LT(MaxAngleByName(*edited.Slice({0, 19}), *library->clips[0].Slice({10, 29})), 1e-4);
  EXPECT_GT(MaxAngleByName(*edited.Slice({50, 60}), *library->clips[0].Slice({60, 70})), 0.05);

  v1::GetClipRequest get;
  get.set_clip_id(stored.clip_id());
  v1::Clip shown;
  ASSERT_TRUE(
      v1::ClipService::NewStub(library->channel)->GetClip(Context().get(), get, &shown).ok());
  ASSERT_TRUE(shown.has_provenance());
  EXPECT_EQ(shown.provenance().operator_(), "scale");
  EXPECT_EQ(shown.provenance().space(), "body");
  ASSERT_EQ(shown.provenance().sources_size(), 1);
  EXPECT_EQ(shown.provenance().sources(0).clip_id(), library->ids[0]);
  EXPECT_EQ(shown.provenance().sources(0).first_frame(), 10);
  EXPECT_EQ(shown.provenance().sources(0).last_frame(), 109);
  EXPECT_THAT(shown.provenance().parameters_json(), HasSubstr("\"factor\":2"));
  EXPECT_THAT(shown.provenance().parameters_json(), ::testing::Not(HasSubstr("store_name")));

  // Searchable like any other clip: a range of the source finds the edited copy.
  v1::SearchRequest search;
  search.set_space("body");
  *search.mutable_clip() = Range(0, 10, 40);
  search.set_max_results(10);
  v1::SearchResponse hits;
  ASSERT_TRUE(
      v1::SearchService::NewStub(library->channel)->Search(Context().get(), search, &hits).ok());
  bool found = false;
  for (const v1::SearchResult& hit : hits.results()) found |= hit.clip_id() == stored.clip_id();
  EXPECT_TRUE(found);
  // And a taken name is refused, storing nothing.
  const int64_t before = ClipCount();
  status = edits_->Scale(Context().get(), request, &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::ALREADY_EXISTS);
  EXPECT_THAT(status.error_message(), HasSubstr("store"));
  EXPECT_EQ(ClipCount(), before);
}

TEST_F(EditServiceTest, ReconstructionErrorFallsToZeroAtEveryDimension) {
  v1::ReconstructRequest request;
  request.set_space("body");
  *request.mutable_clip() = Range(1, 0, 89);
  request.set_dims(3);
  request.set_error_curve(true);
  v1::ReconstructResponse response;
  const grpc::Status status = edits_->Reconstruct(Context().get(), request, &response);
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_EQ(response.dims(), 3);
  EXPECT_EQ(response.joints_size(), library->clips[1].skeleton().joint_count());
  EXPECT_GT(response.mean_rad(), 0.0);
  ASSERT_GT(response.curve_size(), 10);
  EXPECT_NEAR(response.curve(2).mean_rad(), response.mean_rad(), 1e-12);
  EXPECT_LT(response.curve(response.curve_size() - 1).max_rad(), 1e-6);
  EXPECT_GT(response.curve(0).mean_rad(), response.curve(9).mean_rad());
  EXPECT_EQ(ParseBvh(response.result().bvh()).frame_count(), 90);
}

TEST_F(EditServiceTest, InterpolationHitsBothPosesAndComparesTheMethods) {
  v1::InterpolateRequest request;
  request.set_space("body");
  *request.mutable_from() = Range(0, 20, 20);
  *request.mutable_to() = Range(2, 70, 70);
  request.set_steps(5);
  v1::InterpolateResponse response;
  const grpc::Status status = edits_->Interpolate(Context().get(), request, &response);
  ASSERT_TRUE(status.ok()) << status.error_message();
  ASSERT_EQ(response.steps_size(), 5);
  EXPECT_LT(response.steps(0).max_rad(), 1e-9);
  EXPECT_LT(response.steps(4).max_rad(), 1e-9);
  EXPECT_GT(response.steps(2).max_rad(), 0.0);
  const Clip lerp = ParseBvh(response.result().bvh());
  const Clip slerp = ParseBvh(response.other_bvh());
  ASSERT_EQ(lerp.frame_count(), 5);
  ASSERT_EQ(slerp.frame_count(), 5);
  EXPECT_LT(MaxAngleByName(*lerp.Slice({0, 0}), *library->clips[0].Slice({20, 20})), 1e-4);
  EXPECT_LT(MaxAngleByName(*slerp.Slice({4, 4}), *library->clips[2].Slice({70, 70})), 1e-4);
}

TEST_F(EditServiceTest, APlanarBlendHitsEachPoseAtItsPointAndItsResultIsAQuery) {
  v1::BlendRequest request;
  request.set_space("body");
  const int frames[3] = {15, 60, 100};
  const double xy[3][2] = {{0, 0}, {1, 0}, {0, 1}};
  for (int i = 0; i < 3; ++i) {
    v1::PlanarPose* pose = request.add_poses();
    *pose->mutable_pose() = Range(i, frames[i], frames[i]);
    pose->set_x(xy[i][0]);
    pose->set_y(xy[i][1]);
  }
  for (const auto& point : {std::pair{0.0, 0.0}, {1.0, 0.0}, {0.0, 1.0}, {0.0, 0.0}}) {
    v1::PlanePoint* p = request.add_path();
    p->set_x(point.first);
    p->set_y(point.second);
  }
  request.set_frames_per_segment(10);
  request.set_epsilon(0.0);
  request.mutable_output()->set_store_name("blend-path");
  v1::BlendResponse response;
  const grpc::Status status = edits_->Blend(Context().get(), request, &response);
  ASSERT_TRUE(status.ok()) << status.error_message();
  ASSERT_EQ(response.frames_size(), 31);
  for (const v1::BlendWeights& frame : response.frames()) {
    double sum = 0;
    for (const double w : frame.weights()) sum += w;
    EXPECT_NEAR(sum, 1.0, 1e-12);
  }
  EXPECT_EQ(response.frames(10).weights(1), 1.0);
  const Clip blended = ParseBvh(response.result().bvh());
  ASSERT_EQ(blended.frame_count(), 31);
  EXPECT_LT(MaxAngleByName(*blended.Slice({10, 10}), *library->clips[1].Slice({60, 60})), 1e-4);
  EXPECT_LT(MaxAngleByName(*blended.Slice({20, 20}), *library->clips[2].Slice({100, 100})), 1e-4);

  // The blend, stored, is indexed in the space and a search query like any clip: kept in the
  // results, it finds itself first, whole and at no distance; left out, it finds other clips.
  const int64_t stored = response.result().stored().clip_id();
  v1::SearchRequest search;
  search.set_space("body");
  search.mutable_clip()->set_clip_id(stored);
  search.set_max_results(3);
  search.set_exclude_query(false);
  v1::SearchResponse hits;
  const auto searcher = v1::SearchService::NewStub(library->channel);
  grpc::Status searched = searcher->Search(Context().get(), search, &hits);
  ASSERT_TRUE(searched.ok()) << searched.error_message();
  ASSERT_GT(hits.results_size(), 0);
  EXPECT_EQ(hits.results(0).clip_id(), stored);
  EXPECT_EQ(hits.results(0).start_frame(), 0);
  EXPECT_EQ(hits.results(0).end_frame(), 30);
  EXPECT_LT(hits.results(0).score(), 1e-3);
  search.set_exclude_query(true);
  searched = searcher->Search(Context().get(), search, &hits);
  ASSERT_TRUE(searched.ok()) << searched.error_message();
  ASSERT_GT(hits.results_size(), 0);
  for (const v1::SearchResult& hit : hits.results()) EXPECT_NE(hit.clip_id(), stored);
}

TEST_F(EditServiceTest, AGapIsFilledSmootherThanALineAndAnOverlapIsWarped) {
  v1::FillGapRequest request;
  request.set_space("body");
  *request.mutable_first() = Range(0, 0, 59);
  *request.mutable_second() = Range(1, 80, 149);
  request.set_gap_s(0.5);
  v1::FillGapResponse response;
  grpc::Status status = edits_->FillGap(Context().get(), request, &response);
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_EQ(response.transition_frames(), 15);
  EXPECT_EQ(ParseBvh(response.result().bvh()).frame_count(), 60 + 15 + 70);
  ASSERT_EQ(response.seams_size(), 2);
  for (const v1::SeamJump& seam : response.seams()) {
    EXPECT_LT(seam.mean_rad_s(), seam.linear_mean_rad_s());
  }
  // Linear: the line itself.
  request.set_method(v1::GAP_METHOD_LINEAR);
  status = edits_->FillGap(Context().get(), request, &response);
  ASSERT_TRUE(status.ok());
  EXPECT_DOUBLE_EQ(response.seams(0).mean_rad_s(), response.seams(0).linear_mean_rad_s());

  // An overlap, time-warped: the second range (frame 40 on) lags the first's overlap (frames
  // 45-59) by 5 frames, which the warp catches up and a frame-for-frame blend does not.
  request.clear_gap_s();
  request.set_overlap_s(0.5);
  *request.mutable_second() = Range(0, 40, 149);
  status = edits_->FillGap(Context().get(), request, &response);
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_EQ(response.transition_frames(), 15);
  const double aligned = response.warp_score();
  const int frames = ParseBvh(response.result().bvh()).frame_count();
  EXPECT_GE(frames, 60 + 110 - 30);  // the warp advances at most 2 frames a frame
  EXPECT_LE(frames, 60 + 110 - 15);
  request.set_no_align(true);
  status = edits_->FillGap(Context().get(), request, &response);
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_LT(aligned, 0.5 * response.warp_score());
  EXPECT_EQ(ParseBvh(response.result().bvh()).frame_count(), 60 + 110 - 15);
}

TEST_F(EditServiceTest, TranslationAndSmoothingEditTheCurve) {
  v1::TranslateRequest translate;
  translate.set_space("body");
  *translate.mutable_clip() = Range(3, 0, 99);
  *translate.mutable_target() = Range(2, 30, 30);
  translate.set_amount(0.0);
  v1::EditResponse response;
  grpc::Status status = edits_->Translate(Context().get(), translate, &response);
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_LT(MaxAngleByName(ParseBvh(response.result().bvh()), *library->clips[3].Slice({0, 99})),
            1e-4);
  *translate.mutable_axis_from() = Range(2, 30, 30);
  status = edits_->Translate(Context().get(), translate, &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("target"));
  translate.clear_target();
  *translate.mutable_axis_to() = Range(2, 0, 99);  // a range: its projected mean
  translate.set_amount(1.0);
  status = edits_->Translate(Context().get(), translate, &response);
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_GT(MaxAngleByName(ParseBvh(response.result().bvh()), *library->clips[3].Slice({0, 99})),
            0.01);

  v1::SmoothRequest smooth;
  smooth.set_space("body");
  *smooth.mutable_clip() = Range(3, 0, 99);
  smooth.set_level(0.0);
  status = edits_->Smooth(Context().get(), smooth, &response);
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_LT(MaxAngleByName(ParseBvh(response.result().bvh()), *library->clips[3].Slice({0, 99})),
            1e-4);
  smooth.set_level(2.5);
  (*smooth.mutable_constraints()->mutable_edit_weights())["Head"] = 0.0;
  status = edits_->Smooth(Context().get(), smooth, &response);
  ASSERT_TRUE(status.ok()) << status.error_message();
  const Clip smoothed = ParseBvh(response.result().bvh());
  const Clip& source = library->clips[3];
  const int head = smoothed.skeleton().FindJoint("Head");
  const int source_head = source.skeleton().FindJoint("Head");
  for (int f = 0; f < 100; ++f) {
    EXPECT_LT(AngleBetween(smoothed.rotation(f, head), source.rotation(f, source_head)), 1e-4);
  }
}

TEST_F(EditServiceTest, PoseModelsAreFittedStoredListedRunAndDeleted) {
  v1::CreatePoseModelRequest create;
  create.set_name("take3-pose");
  create.set_space("body");
  // Frames 44-46 are held out: the model must find the pose there without having seen them.
  *create.add_examples() = Range(2, 38, 43);
  *create.add_examples() = Range(2, 47, 52);
  create.set_components(1);
  v1::PoseModel model;
  grpc::Status status = edits_->CreatePoseModel(Context().get(), create, &model);
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_EQ(model.dims(), 3);
  EXPECT_EQ(model.space(), "body");
  EXPECT_EQ(edits_->CreatePoseModel(Context().get(), create, &model).error_code(),
            grpc::StatusCode::ALREADY_EXISTS);

  v1::ListPoseModelsResponse listed;
  ASSERT_TRUE(edits_->ListPoseModels(Context().get(), {}, &listed).ok());
  ASSERT_EQ(listed.models_size(), 1);
  EXPECT_EQ(listed.models(0).name(), "take3-pose");

  v1::DetectPoseRequest detect;
  detect.set_model("take3-pose");
  *detect.mutable_clip() = Range(2, 0, 149);
  v1::DetectPoseResponse found;
  status = edits_->DetectPose(Context().get(), detect, &found);
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_EQ(found.log_likelihood().size(), 150 * sizeof(float));
  ASSERT_GE(found.intervals_size(), 1);
  bool covers = false;
  int covered = 0;
  for (const v1::DetectedInterval& interval : found.intervals()) {
    covers |= interval.first_frame() <= 44 && interval.last_frame() >= 46;
    covered += interval.last_frame() - interval.first_frame() + 1;
  }
  EXPECT_TRUE(covers);
  EXPECT_LT(covered, 150) << "a model that fires everywhere finds nothing";
  // A duration is refused in seconds, the field's own unit, with the operator's frames beside.
  for (const double seconds : {-1.0, 1e5}) {
    detect.set_min_duration_s(seconds);
    status = edits_->DetectPose(Context().get(), detect, &found);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
    EXPECT_THAT(status.error_message(),
                ::testing::StartsWith(
                    "min_duration_s = " + std::string(seconds < 0 ? "-1" : "100000") +
                    " is out of range; expected 0 or more, at most 33333.3 seconds (1000000 "
                    "frames at the space's 30 fps)"));
  }
  detect.clear_min_duration_s();

  v1::DeletePoseModelRequest erase;
  erase.set_name("take3-pose");
  v1::DeletePoseModelResponse erased;
  ASSERT_TRUE(edits_->DeletePoseModel(Context().get(), erase, &erased).ok());
  EXPECT_EQ(edits_->DetectPose(Context().get(), detect, &found).error_code(),
            grpc::StatusCode::NOT_FOUND);
  EXPECT_EQ(edits_->DeletePoseModel(Context().get(), erase, &erased).error_code(),
            grpc::StatusCode::NOT_FOUND);
}

TEST_F(EditServiceTest, BadInputIsRefusedNamingTheFieldAndStoresNothing) {
  const int64_t before = ClipCount();
  const auto expect = [&](const grpc::Status& status, grpc::StatusCode code,
                          const std::string& field) {
    EXPECT_EQ(status.error_code(), code) << status.error_message();
    EXPECT_THAT(status.error_message(), HasSubstr(field));
  };
  v1::ScaleRequest scale;
  scale.set_space("body");
  *scale.mutable_clip() = Range(0, 0, 10);
  scale.mutable_output()->set_store_name("never-stored");
  v1::EditResponse response;
  scale.set_factor(std::nan(""));
  expect(edits_->Scale(Context().get(), scale, &response), grpc::StatusCode::INVALID_ARGUMENT,
         "factor");
  scale.set_factor(2);
  scale.mutable_scope()->add_dims(500);
  expect(edits_->Scale(Context().get(), scale, &response), grpc::StatusCode::INVALID_ARGUMENT,
         "dims[0]");
  scale.mutable_scope()->clear_dims();
  *scale.mutable_clip() = Range(0, 0, 999);
  expect(edits_->Scale(Context().get(), scale, &response), grpc::StatusCode::INVALID_ARGUMENT,
         "clip");
  scale.mutable_clip()->set_clip_id(999999);
  expect(edits_->Scale(Context().get(), scale, &response), grpc::StatusCode::NOT_FOUND, "999999");
  *scale.mutable_clip() = Range(0, 0, 10);
  scale.set_space("nowhere");
  expect(edits_->Scale(Context().get(), scale, &response), grpc::StatusCode::NOT_FOUND, "nowhere");
  scale.set_space("body");
  (*scale.mutable_constraints()->mutable_max_angles())["Tail"] = 1;
  expect(edits_->Scale(Context().get(), scale, &response), grpc::StatusCode::INVALID_ARGUMENT,
         "max_angles[Tail]");

  v1::InterpolateRequest interpolate;
  interpolate.set_space("body");
  *interpolate.mutable_from() = Range(0, 5, 5);
  *interpolate.mutable_to() = Range(1, 5, 5);
  interpolate.add_t(0.5);
  interpolate.add_t(1.5);
  interpolate.mutable_output()->set_store_name("never-stored");
  v1::InterpolateResponse interpolated;
  expect(edits_->Interpolate(Context().get(), interpolate, &interpolated),
         grpc::StatusCode::INVALID_ARGUMENT, "t[1]");

  v1::BlendRequest blend;
  blend.set_space("body");
  blend.add_path();
  v1::BlendResponse blended;
  expect(edits_->Blend(Context().get(), blend, &blended), grpc::StatusCode::INVALID_ARGUMENT,
         "poses");

  v1::ReconstructRequest reconstruct;
  reconstruct.set_space("body");
  *reconstruct.mutable_clip() = Range(0, 0, 10);
  reconstruct.set_dims(10000);
  v1::ReconstructResponse rebuilt;
  expect(edits_->Reconstruct(Context().get(), reconstruct, &rebuilt),
         grpc::StatusCode::INVALID_ARGUMENT, "dims");

  v1::FillGapRequest gap;
  gap.set_space("body");
  *gap.mutable_first() = Range(0, 0, 10);
  *gap.mutable_second() = Range(1, 0, 10);
  gap.set_damping(2);
  v1::FillGapResponse filled;
  expect(edits_->FillGap(Context().get(), gap, &filled), grpc::StatusCode::INVALID_ARGUMENT,
         "damping");
  gap.clear_damping();
  gap.set_gap_s(-1);
  expect(edits_->FillGap(Context().get(), gap, &filled), grpc::StatusCode::INVALID_ARGUMENT,
         "gap_s");

  v1::CreatePoseModelRequest model;
  model.set_name("m");
  model.set_space("body");
  v1::PoseModel created;
  expect(edits_->CreatePoseModel(Context().get(), model, &created),
         grpc::StatusCode::INVALID_ARGUMENT, "examples");
  *model.add_examples() = Range(0, 3, 3);
  expect(edits_->CreatePoseModel(Context().get(), model, &created),
         grpc::StatusCode::INVALID_ARGUMENT, "components");
  v1::DetectPoseRequest detect;
  detect.set_model("no-such-model");
  *detect.mutable_clip() = Range(0, 0, 10);
  v1::DetectPoseResponse detected;
  expect(edits_->DetectPose(Context().get(), detect, &detected), grpc::StatusCode::NOT_FOUND,
         "no-such-model");
  EXPECT_EQ(ClipCount(), before);
  v1::ListPoseModelsResponse models;
  ASSERT_TRUE(edits_->ListPoseModels(Context().get(), {}, &models).ok());
  for (const v1::PoseModel& m : models.models()) EXPECT_NE(m.name(), "m");
}

// Every refusal names the field as the client sends it, by its path in the request, not the
// operator's own name for it (overlap_frames, warp.dims, b, plane, gate.start_s, ...).
TEST_F(EditServiceTest, ErrorsNameTheRequestsOwnFields) {
  const int64_t before = ClipCount();
  const auto expect = [](const grpc::Status& status, const std::string& field) {
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << status.error_message();
    EXPECT_THAT(status.error_message(), ::testing::StartsWith(field));
  };
  v1::FillGapRequest gap;
  gap.set_space("body");
  *gap.mutable_first() = Range(0, 0, 10);
  *gap.mutable_second() = Range(1, 0, 99);
  gap.mutable_output()->set_store_name("never-stored");
  v1::FillGapResponse filled;
  gap.set_gap_s(3600);  // 108000 frames at 30 fps, more than a gap may have
  grpc::Status status = edits_->FillGap(Context().get(), gap, &filled);
  expect(status, "gap_s");
  // In seconds, the field's unit, with the operator's frames beside.
  EXPECT_EQ(status.error_message(),
            "gap_s = 3600 is out of range; expected more than 0, at most 3333.33 seconds (100000 "
            "frames at the space's 30 fps)");
  gap.clear_gap_s();
  gap.set_overlap_s(1.0);  // 30 frames, longer than the 11 of the first range
  status = edits_->FillGap(Context().get(), gap, &filled);
  expect(status, "overlap_s");
  EXPECT_EQ(status.error_message(),
            "overlap_s = 1 is out of range; expected at most the first range's 0.366667 seconds "
            "(11 frames at the space's 30 fps)");
  gap.set_overlap_s(0.2);
  gap.set_slope_limit(50);
  expect(edits_->FillGap(Context().get(), gap, &filled), "slope_limit");
  gap.clear_slope_limit();
  gap.set_warp_dims(5000);
  expect(edits_->FillGap(Context().get(), gap, &filled), "warp_dims");
  gap.clear_warp_dims();
  *gap.mutable_second() = Range(1, 0, 1);  // 2 frames: too short for an overlap of 6
  expect(edits_->FillGap(Context().get(), gap, &filled), "second");
  gap.set_no_align(true);
  expect(edits_->FillGap(Context().get(), gap, &filled), "second");

  v1::BlendRequest blend;
  blend.set_space("body");
  for (int i = 0; i < 2; ++i) {
    v1::PlanarPose* pose = blend.add_poses();
    *pose->mutable_pose() = Range(i, 10, 10);
    pose->set_x(i);
  }
  blend.add_path()->set_x(0.5);
  blend.add_path()->set_y(0.5);
  blend.mutable_output()->set_store_name("never-stored");
  v1::BlendResponse blended;
  blend.mutable_poses(1)->set_y(std::nan(""));
  expect(edits_->Blend(Context().get(), blend, &blended), "poses[1].y");
  blend.mutable_poses(1)->set_y(0);
  blend.mutable_path(1)->set_x(HUGE_VAL);
  blend.set_frames_per_segment(4);
  expect(edits_->Blend(Context().get(), blend, &blended), "path[1].x");
  blend.mutable_path(1)->set_x(0);
  *blend.mutable_poses(1)->mutable_pose() = Range(1, 10, 900);
  expect(edits_->Blend(Context().get(), blend, &blended), "poses[1].pose.last_frame");

  v1::ScaleRequest scale;
  scale.set_space("body");
  *scale.mutable_clip() = Range(0, 0, 29);
  scale.mutable_output()->set_store_name("never-stored");
  v1::EditResponse response;
  scale.mutable_scope()->add_dims(0);
  scale.mutable_scope()->add_dims(500);
  expect(edits_->Scale(Context().get(), scale, &response), "scope.dims[1]");
  scale.mutable_scope()->clear_dims();
  scale.mutable_scope()->mutable_gate()->set_start_s(0.5);
  scale.mutable_scope()->mutable_gate()->set_end_s(0.2);
  expect(edits_->Scale(Context().get(), scale, &response), "scope.gate.end_s");
  scale.mutable_scope()->mutable_gate()->set_start_s(100);  // past the range: no frame selected
  scale.mutable_scope()->mutable_gate()->set_end_s(101);
  scale.set_centre(v1::SCALE_CENTRE_SELECTION_MEAN);
  expect(edits_->Scale(Context().get(), scale, &response), "scope.gate");
  scale.clear_scope();
  (*scale.mutable_constraints()->mutable_edit_weights())["Head"] = 2;
  expect(edits_->Scale(Context().get(), scale, &response), "constraints.edit_weights[Head]");
  scale.mutable_constraints()->clear_edit_weights();
  scale.mutable_constraints()->set_source_margin(-1);
  expect(edits_->Scale(Context().get(), scale, &response), "constraints.source_margin");
  scale.clear_constraints();
  scale.mutable_sigmoid()->set_width(0);
  expect(edits_->Scale(Context().get(), scale, &response), "sigmoid.width");

  v1::TranslateRequest translate;
  translate.set_space("body");
  *translate.mutable_clip() = Range(0, 0, 29);
  *translate.mutable_axis_from() = Range(1, 0, 0);
  *translate.mutable_axis_to() = Range(1, 0, 900);
  translate.mutable_output()->set_store_name("never-stored");
  expect(edits_->Translate(Context().get(), translate, &response), "axis_to.last_frame");
  translate.clear_axis_from();
  translate.clear_axis_to();
  *translate.mutable_target() = Range(1, 900, 900);
  expect(edits_->Translate(Context().get(), translate, &response), "target.first_frame");

  v1::SmoothRequest smooth;
  smooth.set_space("body");
  *smooth.mutable_clip() = Range(0, 0, 29);
  smooth.mutable_output()->set_store_name("bad//name");
  expect(edits_->Smooth(Context().get(), smooth, &response), "output.store_name");
  smooth.mutable_output()->set_store_name("never-stored");
  smooth.mutable_output()->add_store_tags("");
  expect(edits_->Smooth(Context().get(), smooth, &response), "output.store_tags[0]");
  EXPECT_EQ(ClipCount(), before);
}

}  // namespace
}  // namespace motiondb
