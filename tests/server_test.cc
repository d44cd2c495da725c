// Integration tests of motiondb-server: the real binary on a free loopback port with a temporary
// database, driven through the generated gRPC stubs as a client would.
#include <signal.h>

#include <atomic>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>
#include <random>
#include <regex>
#include <set>
#include <thread>
#include <tuple>

#include <gmock/gmock.h>
#include <google/protobuf/descriptor.pb.h>
#include <google/protobuf/text_format.h>
#include <google/protobuf/unknown_field_set.h>
#include <google/protobuf/util/json_util.h>
#include <grpcpp/generic/generic_stub.h>
#include <gtest/gtest.h>

#include "absl/strings/str_cat.h"
#include "core/bvh/bvh_reader.h"
#include "core/bvh/bvh_writer.h"
#include "core/motion/forward_kinematics.h"
#include "grpc/health/v1/health.grpc.pb.h"
#include "motiondb/v1/clip_service.grpc.pb.h"
#include "motiondb/v1/job_service.grpc.pb.h"
#include "motiondb/v1/label_service.grpc.pb.h"
#include "motiondb/v1/search_service.grpc.pb.h"
#include "motiondb/v1/server_service.grpc.pb.h"
#include "motiondb/v1/space_service.grpc.pb.h"
#include "storage/sqlite_connection.h"
#include "testing/server_process.h"
#include "testing/synthetic_corpus.h"
#include "tests/clip_builder.h"
#include "tests/server_fixture.h"
#include "tests/test_data.h"
#include "util/byte_coding.h"

// Last: it includes <resolv.h>, whose macro _res breaks Eigen's headers included after it.
#include <httplib.h>

namespace motiondb {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;
using testing::ServerProcess;

// ---------------------------------------------------------------------------------------------
// Clips.

TEST_F(ServerTest, IngestListGetExportRoundTrip) {
  ServerProcess* server = StartServer();
  ASSERT_NE(server, nullptr);
  Client client(testing::InsecureChannel(server->address()));

  const Clip walk = ChainClip();
  v1::IngestClipResponse ingested;
  ASSERT_TRUE(client.Ingest("takes/Walk.BVH", BvhText(walk), &ingested, {"walk", "test"}).ok());
  EXPECT_EQ(ingested.clip().name(), "Walk");
  EXPECT_EQ(ingested.clip().source_file(), "takes/Walk.BVH");
  EXPECT_EQ(ingested.clip().frame_count(), 61);
  EXPECT_NEAR(ingested.clip().fps(), 30.0, 1e-6);
  EXPECT_NEAR(ingested.clip().duration_s(), 61.0 / 30, 1e-6);
  EXPECT_EQ(ingested.clip().joint_count(), 3);
  EXPECT_THAT(ingested.clip().tags(), ::testing::UnorderedElementsAre("walk", "test"));
  EXPECT_TRUE(ingested.projected_spaces().empty());
  const int64_t walk_id = ingested.clip().clip_id();

  // A name override, and a file whose Frames: header disagrees with its rows (a warning).
  v1::IngestClipRequest renamed;
  renamed.set_file_name("x.bvh");
  renamed.set_name("turn");
  std::string text = BvhText(ChainClip(0.05));
  text.replace(text.find("Frames: 61"), 10, "Frames: 70");
  renamed.set_bvh(text);
  v1::IngestClipResponse turn;
  ASSERT_TRUE(client.clips().IngestClip(client.Context().get(), renamed, &turn).ok());
  EXPECT_EQ(turn.clip().name(), "turn");
  EXPECT_EQ(turn.warnings_size(), 1);

  // Lists page through everything in id order, and filter by tag.
  v1::ListClipsRequest list;
  list.set_page_size(1);
  v1::ListClipsResponse page;
  ASSERT_TRUE(client.clips().ListClips(client.Context().get(), list, &page).ok());
  ASSERT_EQ(page.clips_size(), 1);
  EXPECT_EQ(page.clips(0).clip_id(), walk_id);
  EXPECT_EQ(page.clips(0).frame_count(), 61);
  EXPECT_FALSE(page.next_page_token().empty());
  list.set_page_token(page.next_page_token());
  ASSERT_TRUE(client.clips().ListClips(client.Context().get(), list, &page).ok());
  ASSERT_EQ(page.clips_size(), 1);
  EXPECT_EQ(page.clips(0).name(), "turn");
  v1::ListClipsRequest tagged;
  tagged.set_tag("walk");
  ASSERT_TRUE(client.clips().ListClips(client.Context().get(), tagged, &page).ok());
  ASSERT_EQ(page.clips_size(), 1);
  EXPECT_EQ(page.clips(0).clip_id(), walk_id);
  EXPECT_TRUE(page.next_page_token().empty());

  v1::GetClipRequest get;
  get.set_clip_id(walk_id);
  v1::Clip clip;
  ASSERT_TRUE(client.clips().GetClip(client.Context().get(), get, &clip).ok());
  EXPECT_THAT(clip.joint_names(), ::testing::ElementsAre("root", "child", "leaf"));
  EXPECT_GT(clip.skeleton_id(), 0);
  EXPECT_EQ(clip.skeleton_id(), turn.clip().skeleton_id());

  // The export reads back as the clip, whole and as a range.
  v1::ExportClipRequest export_request;
  export_request.mutable_clip()->set_clip_id(walk_id);
  v1::ExportClipResponse exported;
  ASSERT_TRUE(client.clips().ExportClip(client.Context().get(), export_request, &exported).ok());
  EXPECT_EQ(exported.file_name(), "Walk.bvh");
  absl::StatusOr<BvhReadResult> back = ReadBvh(exported.bvh());
  ASSERT_TRUE(back.ok()) << back.status();
  ASSERT_EQ(back->clip.frame_count(), 61);
  EXPECT_LT(testing::MaxRotationError(back->clip, walk), 1e-4);
  export_request.mutable_clip()->set_first_frame(10);
  export_request.mutable_clip()->set_last_frame(19);
  ASSERT_TRUE(client.clips().ExportClip(client.Context().get(), export_request, &exported).ok());
  EXPECT_EQ(exported.file_name(), "Walk_10-19.bvh");
  back = ReadBvh(exported.bvh());
  ASSERT_TRUE(back.ok()) << back.status();
  absl::StatusOr<Clip> expected = walk.Slice({10, 19});
  ASSERT_TRUE(expected.ok());
  ASSERT_EQ(back->clip.frame_count(), 10);
  EXPECT_LT(testing::MaxRotationError(back->clip, *expected), 1e-4);

  v1::DeleteClipRequest remove;
  remove.set_clip_id(walk_id);
  v1::DeleteClipResponse removed;
  ASSERT_TRUE(client.clips().DeleteClip(client.Context().get(), remove, &removed).ok());
  EXPECT_EQ(client.clips().GetClip(client.Context().get(), get, &clip).error_code(),
            grpc::StatusCode::NOT_FOUND);

  // One log line per call: method, status, latency.
  EXPECT_THAT(server->Log(), HasSubstr("/motiondb.v1.ClipService/IngestClip OK "));
  EXPECT_THAT(server->Log(), HasSubstr("/motiondb.v1.ClipService/GetClip NOT_FOUND "));
}

TEST_F(ServerTest, ClipPosesAreTheForwardKinematicsOfTheStoredClip) {
  ServerProcess* server = StartServer();
  ASSERT_NE(server, nullptr);
  Client client(testing::InsecureChannel(server->address()));
  const Clip walk = ChainClip();  // 61 frames at 30 fps
  const int64_t id = client.IngestOrFail("walk.bvh", BvhText(walk));
  const RowMatrixXd world = ForwardKinematics(walk);
  const auto poses = [&](const std::string& text, v1::ClipPoses* out) {
    v1::GetClipPosesRequest request;
    EXPECT_TRUE(google::protobuf::TextFormat::ParseFromString(text, &request)) << text;
    request.mutable_clip()->set_clip_id(request.clip().clip_id() == 0 ? id
                                                                      : request.clip().clip_id());
    return client.clips().GetClipPoses(client.Context().get(), request, out);
  };
  // Position of `joint` on pose `k` of `answer`.
  const auto at = [](const v1::ClipPoses& answer, int k, int joint) {
    float xyz[3];
    const size_t joints = answer.joint_names_size();
    ReadFloat32s(absl::string_view(answer.positions()).substr(12 * (k * joints + joint), 12), 3,
                 xyz);
    return Eigen::Vector3d(xyz[0], xyz[1], xyz[2]);
  };

  v1::ClipPoses whole;
  ASSERT_TRUE(poses("", &whole).ok());
  EXPECT_EQ(whole.clip_id(), id);
  EXPECT_THAT(whole.joint_names(), ::testing::ElementsAre("root", "child", "leaf"));
  EXPECT_THAT(whole.parents(), ::testing::ElementsAre(-1, 0, 1));
  EXPECT_NEAR(whole.sample_rate(), 30, 1e-6);  // at 30 fps already: kept
  EXPECT_EQ(whole.frames(), 61);
  EXPECT_EQ(whole.first_frame(), 0);
  EXPECT_EQ(whole.last_frame(), 60);
  ASSERT_EQ(whole.positions().size(), 61u * 3 * 3 * 4);
  for (int f = 0; f < 61; f += 10) {
    for (int j = 0; j < 3; ++j) {
      EXPECT_LT((at(whole, f, j) - world.block<1, 3>(f, 3 * j).transpose()).norm(), 1e-3)
          << f << " " << j;
    }
  }
  // A range, resampled to 10 Hz: pose k is frame 12 + 3k.
  v1::ClipPoses slow;
  ASSERT_TRUE(poses("clip { first_frame: 12 last_frame: 42 } max_rate: 10", &slow).ok());
  EXPECT_NEAR(slow.sample_rate(), 10, 1e-9);
  EXPECT_EQ(slow.frames(), 11);
  EXPECT_EQ(slow.first_frame(), 12);
  EXPECT_EQ(slow.last_frame(), 42);
  for (int k = 0; k < 11; ++k) {
    EXPECT_LT((at(slow, k, 2) - world.block<1, 3>(12 + 3 * k, 6).transpose()).norm(), 1e-3) << k;
  }
  // 0: the clip's own rate; a higher limit than the clip's too.
  v1::ClipPoses full;
  ASSERT_TRUE(poses("max_rate: 0", &full).ok());
  EXPECT_EQ(full.frames(), 61);
  ASSERT_TRUE(poses("max_rate: 1000", &full).ok());
  EXPECT_EQ(full.frames(), 61);

  EXPECT_EQ(poses("clip { clip_id: 999 }", &full).error_code(), grpc::StatusCode::NOT_FOUND);
  const grpc::Status past_end = poses("clip { last_frame: 61 }", &full);
  EXPECT_EQ(past_end.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(past_end.error_message(), HasSubstr("clip.last_frame"));
  const grpc::Status negative = poses("max_rate: -5", &full);
  EXPECT_EQ(negative.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(negative.error_message(), HasSubstr("max_rate"));
}

TEST_F(ServerTest, ListClipsFiltersBySkeletonAndDescriptorWithTheirTotal) {
  ServerProcess* server = StartServer();
  ASSERT_NE(server, nullptr);
  Client client(testing::InsecureChannel(server->address()));
  const int64_t walk = client.IngestOrFail("walk.bvh", BvhText(ChainClip()));
  const int64_t turn = client.IngestOrFail("turn.bvh", BvhText(ChainClip(0.05)));
  const Clip humanoid = Humanoid().clips[0];
  const int64_t other = client.IngestOrFail("humanoid.bvh", BvhText(humanoid));
  v1::AddLabelsRequest labels;
  v1::NewLabel* label = labels.add_labels();
  label->set_clip_id(turn);
  label->set_descriptor_name("spin");
  v1::AddLabelsResponse added;
  ASSERT_TRUE(client.labels().AddLabels(client.Context().get(), labels, &added).ok());

  const auto listed = [&](const std::string& text) {
    v1::ListClipsRequest request;
    EXPECT_TRUE(google::protobuf::TextFormat::ParseFromString(text, &request)) << text;
    v1::ListClipsResponse response;
    const grpc::Status status =
        client.clips().ListClips(client.Context().get(), request, &response);
    EXPECT_TRUE(status.ok()) << status.error_message();
    std::vector<int64_t> ids;
    for (const v1::Clip& clip : response.clips()) ids.push_back(clip.clip_id());
    return std::make_pair(ids, response.total_size());
  };
  v1::GetClipRequest get;
  get.set_clip_id(walk);
  v1::Clip walk_clip;
  ASSERT_TRUE(client.clips().GetClip(client.Context().get(), get, &walk_clip).ok());
  const std::string chain = absl::StrCat("skeleton_id: ", walk_clip.skeleton_id());
  using Ids = std::vector<int64_t>;
  EXPECT_EQ(listed(""), std::make_pair(Ids{walk, turn, other}, int64_t{3}));
  EXPECT_EQ(listed("page_size: 1"), std::make_pair(Ids{walk}, int64_t{3}));
  EXPECT_EQ(listed(chain), std::make_pair(Ids{walk, turn}, int64_t{2}));
  EXPECT_EQ(listed("descriptor_name: 'spin'"), std::make_pair(Ids{turn}, int64_t{1}));
  EXPECT_EQ(listed(chain + " descriptor_name: 'none'"), std::make_pair(Ids{}, int64_t{0}));

  v1::ListClipsRequest bad;
  bad.set_skeleton_id(-2);
  v1::ListClipsResponse response;
  const grpc::Status refused = client.clips().ListClips(client.Context().get(), bad, &response);
  EXPECT_EQ(refused.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(refused.error_message(), HasSubstr("skeleton_id"));
}

TEST_F(ServerTest, IngestsRealBvhFilesStreamedInChunks) {
  const std::optional<std::filesystem::path> dir = testing::AssimpBvhDir();
  if (!dir) GTEST_SKIP() << "assimp-testmodels is not installed; skipped";
  ServerProcess* server = StartServer();
  ASSERT_NE(server, nullptr);
  Client client(testing::InsecureChannel(server->address()));

  const std::string text = testing::ReadFileOrDie(*dir / "01_01.bvh");
  auto context = client.Context();
  v1::IngestClipResponse response;
  auto writer = client.clips().IngestClipStream(context.get(), &response);
  v1::IngestClipStreamRequest header;
  header.set_file_name("01_01.bvh");
  header.add_tags("cmu");
  ASSERT_TRUE(writer->Write(header));
  constexpr size_t kChunk = 256 * 1024;
  for (size_t at = 0; at < text.size(); at += kChunk) {
    v1::IngestClipStreamRequest chunk;
    chunk.set_chunk(text.substr(at, kChunk));
    ASSERT_TRUE(writer->Write(chunk));
  }
  ASSERT_TRUE(writer->WritesDone());
  const grpc::Status status = writer->Finish();
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_EQ(response.clip().name(), "01_01");
  EXPECT_EQ(response.clip().frame_count(), 2752);
  EXPECT_EQ(response.clip().joint_count(), 31);
  EXPECT_THAT(response.clip().tags(), ::testing::ElementsAre("cmu"));
}

// A stream is parsed as it arrives: a malformed row is refused at the chunk that carries it, so
// the client cannot send the 64 MiB after it (the server stops reading; before, it read them all
// and only then parsed), and nothing is stored.
TEST_F(ServerTest, AStreamIsRefusedAtTheChunkThatShowsItsError) {
  ServerProcess* server = StartServer();
  ASSERT_NE(server, nullptr);
  Client client(testing::InsecureChannel(server->address()));
  const std::string text = BvhText(ChainClip());
  const size_t second_row = text.find('\n', text.find("Frame Time:")) + 1;
  const std::string row = text.substr(second_row, text.find('\n', second_row) + 1 - second_row);

  auto context = client.Context();
  v1::IngestClipResponse response;
  auto writer = client.clips().IngestClipStream(context.get(), &response);
  v1::IngestClipStreamRequest message;
  message.set_file_name("chain.bvh");
  message.set_chunk(text + "1 2 x\n");
  ASSERT_TRUE(writer->Write(message));
  message.clear_file_name();
  message.clear_chunk();
  while (message.chunk().size() < (1 << 20)) *message.mutable_chunk() += row;
  int written = 0;
  while (written < 64 && writer->Write(message)) ++written;
  EXPECT_LT(written, 64) << "the server read the whole stream";
  writer->WritesDone();
  const grpc::Status status = writer->Finish();
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("chain.bvh: line "));
  EXPECT_THAT(status.error_message(), HasSubstr("'x'"));
  v1::ListClipsResponse page;
  ASSERT_TRUE(client.clips().ListClips(client.Context().get(), {}, &page).ok());
  EXPECT_EQ(page.clips_size(), 0);
}

// ---------------------------------------------------------------------------------------------
// Clip names that fit a studio's folders: names with '/', conflicts, content hashes, updates.

v1::IngestClipRequest Upload(const std::string& name, const std::string& bvh,
                             v1::OnConflict on_conflict = v1::ON_CONFLICT_UNSPECIFIED,
                             std::vector<std::string> tags = {}) {
  v1::IngestClipRequest request;
  request.set_file_name(name.substr(name.find_last_of('/') + 1) + ".bvh");
  request.set_name(name);
  request.set_bvh(bvh);
  request.set_on_conflict(on_conflict);
  for (const std::string& tag : tags) request.add_tags(tag);
  return request;
}

// The first `frames` frames of a humanoid clip, as BVH: new content on the humanoid skeleton.
std::string HumanoidTake(size_t clip, int frames) {
  absl::StatusOr<Clip> take = Humanoid().clips[clip].Slice({0, frames - 1});
  EXPECT_TRUE(take.ok()) << take.status();
  return take.ok() ? BvhText(*take) : "";
}

TEST_F(ServerTest, ClipNamesConflictsHashesAndUpdates) {
  ServerProcess* server = StartServer();
  ASSERT_NE(server, nullptr);
  Client client(testing::InsecureChannel(server->address()));
  const std::vector<int64_t> ids = IngestHumanoid(client);
  ASSERT_GE(ids.size(), 3u);
  CreateHumanoidSpace(client);
  const std::string take_a = HumanoidTake(0, 400);
  const std::string take_b = HumanoidTake(1, 400);
  const std::string take_c = HumanoidTake(2, 400);
  auto ingest = [&](const v1::IngestClipRequest& request, v1::IngestClipResponse* response) {
    response->Clear();
    return client.clips().IngestClip(client.Context().get(), request, response);
  };
  auto space_clips = [&] {
    v1::GetSpaceRequest get;
    get.set_name("body");
    v1::Space space;
    EXPECT_TRUE(client.spaces().GetSpace(client.Context().get(), get, &space).ok());
    return space.index().clips();
  };

  // The same take name in two session folders: two clips.
  v1::IngestClipResponse first;
  ASSERT_TRUE(ingest(Upload("session1/take_001", take_a), &first).ok());
  EXPECT_EQ(first.result(), v1::INGEST_RESULT_STORED);
  EXPECT_EQ(first.clip().name(), "session1/take_001");
  EXPECT_EQ(first.clip().source_file(), "take_001.bvh");
  EXPECT_THAT(first.clip().content_hash(), ::testing::MatchesRegex("[0-9a-f]{64}"));
  EXPECT_THAT(first.projected_spaces(), ::testing::ElementsAre("body"));
  EXPECT_TRUE(first.duplicate_of().empty());
  v1::IngestClipResponse second;
  ASSERT_TRUE(
      ingest(Upload("session2/take_001", take_b, v1::ON_CONFLICT_UNSPECIFIED, {"s2"}), &second)
          .ok());
  EXPECT_EQ(second.result(), v1::INGEST_RESULT_STORED);
  EXPECT_NE(second.clip().clip_id(), first.clip().clip_id());
  EXPECT_NE(second.clip().content_hash(), first.clip().content_hash());
  const int64_t indexed = static_cast<int64_t>(ids.size()) + 2;
  EXPECT_EQ(space_clips(), indexed);

  // Re-ingesting the same file is skipped by default: a batch ingest run again is idempotent.
  v1::IngestClipResponse again;
  ASSERT_TRUE(ingest(Upload("session1/take_001", take_a), &again).ok());
  EXPECT_EQ(again.result(), v1::INGEST_RESULT_SKIPPED);
  EXPECT_EQ(again.clip().clip_id(), first.clip().clip_id());
  EXPECT_TRUE(again.projected_spaces().empty());
  // Other content under a taken name is refused by default, saying how to choose.
  grpc::Status status = ingest(Upload("session1/take_001", take_c), &again);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::ALREADY_EXISTS);
  EXPECT_THAT(status.error_message(), HasSubstr("session1/take_001"));
  EXPECT_THAT(status.error_message(), HasSubstr("on_conflict skip"));
  EXPECT_THAT(status.error_message(), HasSubstr("replace"));
  // ERROR refuses even the identical file.
  EXPECT_EQ(ingest(Upload("session1/take_001", take_a, v1::ON_CONFLICT_ERROR), &again).error_code(),
            grpc::StatusCode::ALREADY_EXISTS);
  // SKIP keeps the existing clip, whatever the upload holds; so does a stream's first message.
  ASSERT_TRUE(ingest(Upload("session1/take_001", take_c, v1::ON_CONFLICT_SKIP), &again).ok());
  EXPECT_EQ(again.result(), v1::INGEST_RESULT_SKIPPED);
  EXPECT_EQ(again.clip().clip_id(), first.clip().clip_id());
  EXPECT_EQ(again.clip().content_hash(), first.clip().content_hash());
  {
    auto context = client.Context();
    v1::IngestClipResponse streamed;
    auto writer = client.clips().IngestClipStream(context.get(), &streamed);
    v1::IngestClipStreamRequest header;
    header.set_file_name("take_001.bvh");
    header.set_name("session1/take_001");
    header.set_on_conflict(v1::ON_CONFLICT_SKIP);
    header.set_chunk(take_c);
    ASSERT_TRUE(writer->Write(header));
    ASSERT_TRUE(writer->WritesDone());
    status = writer->Finish();
    ASSERT_TRUE(status.ok()) << status.error_message();
    EXPECT_EQ(streamed.result(), v1::INGEST_RESULT_SKIPPED);
    EXPECT_EQ(streamed.clip().clip_id(), first.clip().clip_id());
  }
  EXPECT_EQ(space_clips(), indexed);

  // REPLACE stores the new content under a new id; the old clip is gone from storage and index.
  v1::IngestClipResponse replaced;
  ASSERT_TRUE(
      ingest(Upload("session1/take_001", take_c, v1::ON_CONFLICT_REPLACE, {"s1"}), &replaced).ok());
  EXPECT_EQ(replaced.result(), v1::INGEST_RESULT_REPLACED);
  EXPECT_EQ(replaced.replaced_clip_id(), first.clip().clip_id());
  const int64_t replacement = replaced.clip().clip_id();
  EXPECT_GT(replacement, second.clip().clip_id());
  EXPECT_EQ(replaced.clip().name(), "session1/take_001");
  EXPECT_NE(replaced.clip().content_hash(), first.clip().content_hash());
  EXPECT_THAT(replaced.projected_spaces(), ::testing::ElementsAre("body"));
  v1::GetClipRequest get;
  get.set_clip_id(first.clip().clip_id());
  v1::Clip clip;
  EXPECT_EQ(client.clips().GetClip(client.Context().get(), get, &clip).error_code(),
            grpc::StatusCode::NOT_FOUND);
  EXPECT_EQ(space_clips(), indexed);
  // A search over the clips tagged s1 finds the new clip, and only it.
  v1::SearchRequest query = ClipQuery("body", replacement, 0, 150);
  query.add_tags("s1");
  v1::SearchResponse found;
  status = client.Search(query, &found);
  ASSERT_TRUE(status.ok()) << status.error_message();
  ASSERT_GE(found.results_size(), 1);
  for (const v1::SearchResult& result : found.results()) {
    EXPECT_EQ(result.clip_id(), replacement);
    EXPECT_EQ(result.clip_name(), "session1/take_001");
  }
  EXPECT_EQ(client.Search(ClipQuery("body", first.clip().clip_id(), 0, 150), &found).error_code(),
            grpc::StatusCode::NOT_FOUND);

  // Identical content under another name is stored, and reported.
  v1::IngestClipResponse duplicate;
  ASSERT_TRUE(ingest(Upload("session3/take_007", take_c), &duplicate).ok());
  EXPECT_EQ(duplicate.result(), v1::INGEST_RESULT_STORED);
  EXPECT_EQ(duplicate.clip().content_hash(), replaced.clip().content_hash());
  ASSERT_EQ(duplicate.duplicate_of_size(), 1);
  EXPECT_EQ(duplicate.duplicate_of(0).clip_id(), replacement);
  EXPECT_EQ(duplicate.duplicate_of(0).name(), "session1/take_001");
  EXPECT_THAT(duplicate.warnings(),
              ::testing::Contains("identical content to clip " + std::to_string(replacement) +
                                  " 'session1/take_001'"));

  // UpdateClip renames and re-tags, and the index sees it at once.
  v1::UpdateClipRequest update;
  update.set_clip_id(second.clip().clip_id());
  update.set_name("session2/take_001_best");
  update.add_add_tags("best");
  update.add_remove_tags("s2");
  v1::Clip updated;
  status = client.clips().UpdateClip(client.Context().get(), update, &updated);
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_EQ(updated.clip_id(), second.clip().clip_id());
  EXPECT_EQ(updated.name(), "session2/take_001_best");
  EXPECT_THAT(updated.tags(), ::testing::ElementsAre("best"));
  EXPECT_EQ(updated.content_hash(), second.clip().content_hash());
  query = ClipQuery("body", second.clip().clip_id(), 0, 150);
  query.add_tags("best");
  status = client.Search(query, &found);
  ASSERT_TRUE(status.ok()) << status.error_message();
  ASSERT_GE(found.results_size(), 1);
  for (const v1::SearchResult& result : found.results()) {
    EXPECT_EQ(result.clip_id(), second.clip().clip_id());
    EXPECT_EQ(result.clip_name(), "session2/take_001_best");
  }
  query.clear_tags();
  query.add_tags("s2");
  ASSERT_TRUE(client.Search(query, &found).ok());
  EXPECT_EQ(found.results_size(), 0);
  // The old name is free.
  ASSERT_TRUE(ingest(Upload("session2/take_001", take_b), &again).ok());
  EXPECT_EQ(again.result(), v1::INGEST_RESULT_STORED);

  // Refused updates name the field and change nothing.
  struct BadUpdate {
    std::function<void(v1::UpdateClipRequest*)> change;
    grpc::StatusCode code;
    std::string words;
  };
  const std::vector<BadUpdate> bad_updates = {
      {[](v1::UpdateClipRequest* r) { r->set_name("session1/take_001"); },
       grpc::StatusCode::ALREADY_EXISTS, "session1/take_001"},
      {[](v1::UpdateClipRequest* r) { r->set_name("session1//take"); },
       grpc::StatusCode::INVALID_ARGUMENT, "name"},
      {[](v1::UpdateClipRequest* r) { r->add_add_tags("two\nlines"); },
       grpc::StatusCode::INVALID_ARGUMENT, "add_tags[0]"},
      {[](v1::UpdateClipRequest* r) { r->set_clip_id(999999); }, grpc::StatusCode::NOT_FOUND,
       "999999"},
  };
  for (const BadUpdate& bad : bad_updates) {
    v1::UpdateClipRequest request;
    request.set_clip_id(second.clip().clip_id());
    bad.change(&request);
    status = client.clips().UpdateClip(client.Context().get(), request, &updated);
    EXPECT_EQ(status.error_code(), bad.code) << bad.words << ": " << status.error_message();
    EXPECT_THAT(status.error_message(), HasSubstr(bad.words));
  }
  get.set_clip_id(second.clip().clip_id());
  ASSERT_TRUE(client.clips().GetClip(client.Context().get(), get, &clip).ok());
  EXPECT_EQ(clip.name(), "session2/take_001_best");
  EXPECT_THAT(clip.tags(), ::testing::ElementsAre("best"));

  // Names that are no relative path, and unknown conflict modes.
  for (const std::string name : {"/session1/take", "session1/", "session1/../take", "./take"}) {
    status = ingest(Upload(name, take_a), &again);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << name;
    EXPECT_THAT(status.error_message(), HasSubstr("clip name")) << name;
  }
  status = ingest(Upload("fresh", take_a, static_cast<v1::OnConflict>(9)), &again);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("on_conflict"));

  // A replacement of another skeleton leaves the old skeleton's space as well.
  ASSERT_TRUE(ingest(Upload("session4/take_001", HumanoidTake(0, 300)), &again).ok());
  const int64_t with_take = space_clips();
  ASSERT_TRUE(
      ingest(Upload("session4/take_001", BvhText(ChainClip()), v1::ON_CONFLICT_REPLACE), &replaced)
          .ok());
  EXPECT_EQ(replaced.result(), v1::INGEST_RESULT_REPLACED);
  EXPECT_EQ(replaced.replaced_clip_id(), again.clip().clip_id());
  EXPECT_TRUE(replaced.projected_spaces().empty());
  EXPECT_EQ(space_clips(), with_take - 1);

  // The export's suggested file name stays one file name.
  v1::ExportClipRequest export_request;
  export_request.mutable_clip()->set_clip_id(replacement);
  v1::ExportClipResponse exported;
  ASSERT_TRUE(client.clips().ExportClip(client.Context().get(), export_request, &exported).ok());
  EXPECT_EQ(exported.file_name(), "session1_take_001.bvh");
  export_request.mutable_clip()->set_first_frame(10);
  export_request.mutable_clip()->set_last_frame(19);
  ASSERT_TRUE(client.clips().ExportClip(client.Context().get(), export_request, &exported).ok());
  EXPECT_EQ(exported.file_name(), "session1_take_001_10-19.bvh");
}

// ---------------------------------------------------------------------------------------------
// Spaces and search.

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

// ---------------------------------------------------------------------------------------------
// Labels.

// A manual label on frames `first`..`last` of a clip (both unset: the whole clip).
v1::NewLabel FrameLabel(int64_t clip_id, std::optional<int> first, std::optional<int> last,
                        const std::string& descriptor, std::optional<double> value = 1.0) {
  v1::NewLabel label;
  label.set_clip_id(clip_id);
  if (first) label.set_first_frame(*first);
  if (last) label.set_last_frame(*last);
  label.set_descriptor_name(descriptor);
  if (value) label.set_value(*value);
  return label;
}

std::vector<int64_t> LabelIds(const google::protobuf::RepeatedPtrField<v1::Label>& labels) {
  std::vector<int64_t> ids;
  for (const v1::Label& label : labels) ids.push_back(label.label_id());
  return ids;
}

TEST_F(ServerTest, LabelsAddListFindTimelineAndDelete) {
  ServerProcess* server = StartServer();
  ASSERT_NE(server, nullptr);
  Client client(testing::InsecureChannel(server->address()));
  const int64_t walk = client.IngestOrFail("walk.bvh", BvhText(ChainClip()), {"walk"});
  const int64_t turn = client.IngestOrFail("turn.bvh", BvhText(ChainClip(0.05)), {"turn"});

  // Frames, seconds (the clip by name, the value unset: 1) and the whole clip, in one batch.
  v1::AddLabelsRequest add;
  *add.add_labels() = FrameLabel(walk, 10, 20, "step", 0.9);
  v1::NewLabel* by_name = add.add_labels();
  by_name->set_clip_name("turn");
  by_name->set_start_s(0.5);
  by_name->set_end_s(1.0);
  by_name->set_descriptor_name("step");
  *add.add_labels() = FrameLabel(walk, std::nullopt, std::nullopt, "walk", 0.6);
  v1::AddLabelsResponse added;
  grpc::Status status = client.labels().AddLabels(client.Context().get(), add, &added);
  ASSERT_TRUE(status.ok()) << status.error_message();
  ASSERT_EQ(added.labels_size(), 3);
  const std::vector<int64_t> ids = LabelIds(added.labels());
  const v1::Label& seconds = added.labels(1);
  EXPECT_EQ(seconds.clip_id(), turn);
  EXPECT_EQ(seconds.clip_name(), "turn");
  EXPECT_EQ(seconds.first_frame(), 15);  // 0.5 s at 30 fps
  EXPECT_EQ(seconds.last_frame(), 30);
  EXPECT_NEAR(seconds.start_s(), 0.5, 1e-9);
  EXPECT_NEAR(seconds.end_s(), 1.0, 1e-9);
  EXPECT_EQ(seconds.value(), 1.0);
  EXPECT_EQ(seconds.origin(), v1::LABEL_ORIGIN_MANUAL);
  EXPECT_GT(seconds.created_unix_ms(), 0);
  EXPECT_EQ(added.labels(2).first_frame(), 0);
  EXPECT_EQ(added.labels(2).last_frame(), 60);

  // Listed a page at a time in id order, as returned; filtered.
  v1::ListLabelsRequest list;
  list.set_page_size(2);
  std::vector<int64_t> listed;
  v1::ListLabelsResponse page;
  do {
    ASSERT_TRUE(client.labels().ListLabels(client.Context().get(), list, &page).ok());
    for (const v1::Label& label : page.labels()) listed.push_back(label.label_id());
    list.set_page_token(page.next_page_token());
  } while (!list.page_token().empty());
  EXPECT_EQ(listed, ids);
  v1::ListLabelsRequest filtered;
  filtered.set_clip_id(walk);
  filtered.set_min_value(0.7);
  ASSERT_TRUE(client.labels().ListLabels(client.Context().get(), filtered, &page).ok());
  EXPECT_EQ(LabelIds(page.labels()), std::vector<int64_t>{ids[0]});
  filtered.Clear();
  filtered.set_origin(v1::LABEL_ORIGIN_PROPAGATED);
  ASSERT_TRUE(client.labels().ListLabels(client.Context().get(), filtered, &page).ok());
  EXPECT_EQ(page.labels_size(), 0);

  // Found strongest first, and by tag.
  v1::FindLabelsRequest find;
  find.set_descriptor_name("step");
  v1::FindLabelsResponse found;
  ASSERT_TRUE(client.labels().FindLabels(client.Context().get(), find, &found).ok());
  EXPECT_EQ(LabelIds(found.labels()), (std::vector<int64_t>{ids[1], ids[0]}));
  EXPECT_EQ(found.labels(1).clip_name(), "walk");
  EXPECT_NEAR(found.labels(1).start_s(), 10.0 / 30, 1e-9);
  find.add_tags("walk");
  ASSERT_TRUE(client.labels().FindLabels(client.Context().get(), find, &found).ok());
  EXPECT_EQ(LabelIds(found.labels()), std::vector<int64_t>{ids[0]});

  // The clip's timeline, by first frame.
  v1::GetClipLabelsRequest timeline_request;
  timeline_request.set_clip_id(walk);
  v1::GetClipLabelsResponse timeline;
  ASSERT_TRUE(
      client.labels().GetClipLabels(client.Context().get(), timeline_request, &timeline).ok());
  EXPECT_EQ(timeline.clip_name(), "walk");
  EXPECT_EQ(timeline.frame_count(), 61);
  EXPECT_NEAR(timeline.fps(), 30, 1e-9);
  EXPECT_EQ(LabelIds(timeline.labels()), (std::vector<int64_t>{ids[2], ids[0]}));

  // Deleted by id, then by descriptor; deleting a clip takes its labels.
  v1::DeleteLabelsRequest remove;
  remove.add_label_ids(ids[1]);
  v1::DeleteLabelsResponse removed;
  ASSERT_TRUE(client.labels().DeleteLabels(client.Context().get(), remove, &removed).ok());
  EXPECT_EQ(removed.deleted(), 1);
  remove.Clear();
  remove.set_descriptor_name("walk");
  ASSERT_TRUE(client.labels().DeleteLabels(client.Context().get(), remove, &removed).ok());
  EXPECT_EQ(removed.deleted(), 1);
  v1::DeleteClipRequest delete_clip;
  delete_clip.set_clip_id(walk);
  v1::DeleteClipResponse clip_deleted;
  ASSERT_TRUE(client.clips().DeleteClip(client.Context().get(), delete_clip, &clip_deleted).ok());
  list.Clear();
  ASSERT_TRUE(client.labels().ListLabels(client.Context().get(), list, &page).ok());
  EXPECT_EQ(page.labels_size(), 0);
  EXPECT_THAT(server->Log(), HasSubstr("/motiondb.v1.LabelService/AddLabels OK "));
}

// Every bad label gets its code and names its item and field, and a batch holding one stores
// nothing, its good labels included.
TEST_F(ServerTest, BadLabelsGetTheirStatusCodesAndStoreNothing) {
  ServerProcess* server = StartServer();
  ASSERT_NE(server, nullptr);
  Client client(testing::InsecureChannel(server->address()));
  const int64_t walk = client.IngestOrFail("walk.bvh", BvhText(ChainClip()));  // 61 frames, 30 fps
  const int64_t turn = client.IngestOrFail("turn.bvh", BvhText(ChainClip(0.05)));
  const auto seconds = [&](double start, double end) {
    v1::NewLabel label = FrameLabel(walk, std::nullopt, std::nullopt, "x");
    label.set_start_s(start);
    label.set_end_s(end);
    return label;
  };
  v1::NewLabel both = seconds(0, 1);
  both.set_first_frame(0);
  v1::NewLabel named = FrameLabel(0, 0, 1, "x");
  named.set_clip_name("nowhere");
  v1::NewLabel two_clips = FrameLabel(walk, 0, 1, "x");
  two_clips.set_clip_name("turn");
  v1::NewLabel id_and_unknown_name = FrameLabel(walk, 0, 1, "x");
  id_and_unknown_name.set_clip_name("nowhere");
  const struct {
    v1::NewLabel bad;
    grpc::StatusCode code;
    std::string message;
  } cases[] = {
      {FrameLabel(999999, 0, 1, "x"), grpc::StatusCode::NOT_FOUND,
       "labels[1].clip_id: clip 999999 not found"},
      {named, grpc::StatusCode::NOT_FOUND, "labels[1].clip_name: no clip is named 'nowhere'"},
      {FrameLabel(0, 0, 1, "x"), grpc::StatusCode::INVALID_ARGUMENT,
       "labels[1]: give clip_id or clip_name"},
      {two_clips, grpc::StatusCode::INVALID_ARGUMENT,
       absl::StrCat("labels[1]: clip_id ", walk, " and clip_name 'turn' (clip ", turn,
                    ") name different clips")},
      {id_and_unknown_name, grpc::StatusCode::NOT_FOUND,
       "labels[1].clip_name: no clip is named 'nowhere'"},
      {FrameLabel(walk, 70, std::nullopt, "x"), grpc::StatusCode::INVALID_ARGUMENT,
       "labels[1].first_frame: 70 is outside the clip's frames 0..60"},
      {FrameLabel(walk, 20, 10, "x"), grpc::StatusCode::INVALID_ARGUMENT,
       "labels[1].last_frame: 10 is before first_frame 20"},
      {FrameLabel(walk, 50, 61, "x"), grpc::StatusCode::INVALID_ARGUMENT,
       "labels[1].last_frame: 61 is outside the clip's frames 0..60"},
      {FrameLabel(walk, -1, 5, "x"), grpc::StatusCode::INVALID_ARGUMENT,
       "labels[1].first_frame: -1 is negative"},
      {seconds(1, 2.5), grpc::StatusCode::INVALID_ARGUMENT,
       "labels[1].end_s: 2.5 s is past the clip's last frame 60"},
      {seconds(1, 62.0 / 30), grpc::StatusCode::INVALID_ARGUMENT,
       "labels[1].end_s: 2.06667 s is past the clip's last frame 60"},
      {seconds(61.0 / 30, 61.0 / 30), grpc::StatusCode::INVALID_ARGUMENT,
       "labels[1].start_s: 2.03333 s is past the clip's last frame 60"},
      {seconds(-0.5, 1), grpc::StatusCode::INVALID_ARGUMENT, "labels[1].start_s: -0.5"},
      {seconds(NAN, 1), grpc::StatusCode::INVALID_ARGUMENT, "labels[1].start_s: nan"},
      {seconds(1.5, 1), grpc::StatusCode::INVALID_ARGUMENT,
       "labels[1].end_s: 1 is before start_s 1.5"},
      {both, grpc::StatusCode::INVALID_ARGUMENT, "labels[1]: give the range in frames"},
      {FrameLabel(walk, 0, 1, "x", 1.5), grpc::StatusCode::INVALID_ARGUMENT,
       "labels[1].value: 1.5 is outside [0, 1]"},
      {FrameLabel(walk, 0, 1, "x", -0.5), grpc::StatusCode::INVALID_ARGUMENT,
       "labels[1].value: -0.5 is outside [0, 1]"},
      {FrameLabel(walk, 0, 1, "x", NAN), grpc::StatusCode::INVALID_ARGUMENT,
       "labels[1].value: nan is outside [0, 1]"},
      {FrameLabel(walk, 0, 1, ""), grpc::StatusCode::INVALID_ARGUMENT,
       "labels[1].descriptor must not be empty"},
      {FrameLabel(walk, 0, 1, std::string(257, 'd')), grpc::StatusCode::INVALID_ARGUMENT,
       "labels[1].descriptor is 257 bytes long"},
      {FrameLabel(walk, 0, 1, "step\x1b[2J"), grpc::StatusCode::INVALID_ARGUMENT,
       "labels[1].descriptor 'step\\x1b[2J' holds a control character at byte 4"},
  };
  v1::AddLabelsResponse added;
  for (const auto& c : cases) {
    v1::AddLabelsRequest request;
    *request.add_labels() = FrameLabel(walk, 0, 10, "good");
    *request.add_labels() = c.bad;
    const grpc::Status status = client.labels().AddLabels(client.Context().get(), request, &added);
    EXPECT_EQ(status.error_code(), c.code) << c.message;
    EXPECT_THAT(status.error_message(), HasSubstr(c.message));
  }
  EXPECT_EQ(client.labels()
                .AddLabels(client.Context().get(), v1::AddLabelsRequest(), &added)
                .error_code(),
            grpc::StatusCode::INVALID_ARGUMENT);
  v1::ListLabelsRequest list;
  v1::ListLabelsResponse listed;
  ASSERT_TRUE(client.labels().ListLabels(client.Context().get(), list, &listed).ok());
  EXPECT_EQ(listed.labels_size(), 0) << "a failed batch stored a label";

  // The other calls' bad inputs.
  list.set_origin(static_cast<v1::LabelOrigin>(7));
  EXPECT_EQ(client.labels().ListLabels(client.Context().get(), list, &listed).error_code(),
            grpc::StatusCode::INVALID_ARGUMENT);
  list.Clear();
  list.set_page_size(-1);
  EXPECT_EQ(client.labels().ListLabels(client.Context().get(), list, &listed).error_code(),
            grpc::StatusCode::INVALID_ARGUMENT);
  list.Clear();
  list.set_page_token("bogus");
  EXPECT_EQ(client.labels().ListLabels(client.Context().get(), list, &listed).error_code(),
            grpc::StatusCode::INVALID_ARGUMENT);
  v1::FindLabelsRequest find;
  v1::FindLabelsResponse found;
  EXPECT_EQ(client.labels().FindLabels(client.Context().get(), find, &found).error_code(),
            grpc::StatusCode::INVALID_ARGUMENT);
  find.set_descriptor_name("step");
  find.set_min_value(2);
  EXPECT_EQ(client.labels().FindLabels(client.Context().get(), find, &found).error_code(),
            grpc::StatusCode::INVALID_ARGUMENT);
  v1::DeleteLabelsRequest remove;
  v1::DeleteLabelsResponse removed;
  EXPECT_EQ(client.labels().DeleteLabels(client.Context().get(), remove, &removed).error_code(),
            grpc::StatusCode::INVALID_ARGUMENT);
  remove.add_label_ids(999999);
  const grpc::Status unknown =
      client.labels().DeleteLabels(client.Context().get(), remove, &removed);
  EXPECT_EQ(unknown.error_code(), grpc::StatusCode::NOT_FOUND);
  EXPECT_THAT(unknown.error_message(), HasSubstr("label_ids[0]"));
  v1::GetClipLabelsRequest timeline_request;
  timeline_request.set_clip_id(999999);
  v1::GetClipLabelsResponse timeline;
  const grpc::Status no_timeline =
      client.labels().GetClipLabels(client.Context().get(), timeline_request, &timeline);
  EXPECT_EQ(no_timeline.error_code(), grpc::StatusCode::NOT_FOUND);
  EXPECT_EQ(no_timeline.error_message(), "clip_id: clip 999999 not found");
  list.Clear();
  list.set_clip_id(999999);
  const grpc::Status no_list = client.labels().ListLabels(client.Context().get(), list, &listed);
  EXPECT_EQ(no_list.error_code(), grpc::StatusCode::NOT_FOUND);
  EXPECT_EQ(no_list.error_message(), "clip_id: clip 999999 not found");
  remove.Clear();
  remove.set_clip_id(999999);
  const grpc::Status no_delete =
      client.labels().DeleteLabels(client.Context().get(), remove, &removed);
  EXPECT_EQ(no_delete.error_code(), grpc::StatusCode::NOT_FOUND);
  EXPECT_EQ(no_delete.error_message(), "clip_id: clip 999999 not found");
  find.Clear();
  find.set_descriptor_name("step");
  for (int i = 0; i < 65; ++i) find.add_tags(absl::StrCat("tag", i));
  const grpc::Status many_tags = client.labels().FindLabels(client.Context().get(), find, &found);
  EXPECT_EQ(many_tags.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(many_tags.error_message(), HasSubstr("tags: at most 64"));
}

// Seconds ranges as tools write them, half-open, end at the clip's duration: the last frame.
// A clip named by both id and name is taken when they agree.
TEST_F(ServerTest, LabelRangesMayEndAtTheClipsDurationAndNameTheClipTwice) {
  ServerProcess* server = StartServer();
  ASSERT_NE(server, nullptr);
  Client client(testing::InsecureChannel(server->address()));
  const int64_t walk = client.IngestOrFail("walk.bvh", BvhText(ChainClip()));  // 61 frames, 30 fps
  v1::AddLabelsRequest add;
  for (const double end : {61.0 / 30, 61.4 / 30, 60.6 / 30}) {
    v1::NewLabel* label = add.add_labels();
    label->set_clip_name("walk");
    label->set_start_s(1);
    label->set_end_s(end);
    label->set_descriptor_name("step");
  }
  v1::NewLabel* twice = add.add_labels();
  *twice = FrameLabel(walk, 3, 4, "both");
  twice->set_clip_name("walk");
  v1::AddLabelsResponse added;
  const grpc::Status status = client.labels().AddLabels(client.Context().get(), add, &added);
  ASSERT_TRUE(status.ok()) << status.error_message();
  ASSERT_EQ(added.labels_size(), 4);
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(added.labels(i).first_frame(), 30) << i;
    EXPECT_EQ(added.labels(i).last_frame(), 60) << i;
  }
  EXPECT_EQ(added.labels(3).clip_id(), walk);
  EXPECT_EQ(added.labels(3).first_frame(), 3);
}

// The descriptor is "descriptor" in JSON (descriptor_name only in the .proto), both ways.
TEST(LabelJson, DescriptorIsCalledDescriptorInJson) {
  v1::Label label;
  label.set_label_id(7);
  label.set_clip_name("walk");
  label.set_descriptor_name("raise-right-hand");
  label.set_value(0.5);
  std::string json;
  ASSERT_TRUE(google::protobuf::util::MessageToJsonString(label, &json).ok());
  EXPECT_THAT(json, HasSubstr("\"descriptor\":\"raise-right-hand\""));
  EXPECT_THAT(json, Not(HasSubstr("descriptor_name")));
  EXPECT_THAT(json, Not(HasSubstr("descriptorName")));
  v1::Label back;
  ASSERT_TRUE(google::protobuf::util::JsonStringToMessage(json, &back).ok());
  EXPECT_EQ(back.SerializeAsString(), label.SerializeAsString());
  v1::NewLabel added;
  ASSERT_TRUE(google::protobuf::util::JsonStringToMessage(
                  R"({"clipName": "walk", "descriptor": "kick", "endS": 2})", &added)
                  .ok());
  EXPECT_EQ(added.descriptor_name(), "kick");
  EXPECT_EQ(added.end_s(), 2);
}

// ---------------------------------------------------------------------------------------------
// Errors.

TEST_F(ServerTest, BadInputsGetTheirStatusCodes) {
  ServerProcess* server = StartServer();
  ASSERT_NE(server, nullptr);
  Client client(testing::InsecureChannel(server->address()));
  const std::vector<int64_t> ids = IngestHumanoid(client);
  CreateHumanoidSpace(client);
  v1::IngestClipResponse ingested;
  v1::SearchResponse found;
  v1::Space space;

  // Malformed BVH: INVALID_ARGUMENT naming the file and line.
  std::string truncated = BvhText(ChainClip());
  truncated.resize(truncated.size() - 40);
  grpc::Status status = client.Ingest("broken.bvh", truncated, &ingested);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), ::testing::MatchesRegex("broken\\.bvh: line [0-9]+: .*"));
  status = client.Ingest("garbage.bvh", "HIERARCHY\nROOT\n", &ingested);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("line 2"));
  EXPECT_EQ(client.Ingest("", BvhText(ChainClip()), &ingested).error_code(),
            grpc::StatusCode::INVALID_ARGUMENT);
  // A stream without a file name, and an empty stream.
  for (const bool empty : {false, true}) {
    auto context = client.Context();
    auto writer = client.clips().IngestClipStream(context.get(), &ingested);
    if (!empty) {
      v1::IngestClipStreamRequest chunk;
      chunk.set_chunk(BvhText(ChainClip()));
      writer->Write(chunk);
    }
    writer->WritesDone();
    status = writer->Finish();
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
    EXPECT_THAT(status.error_message(), HasSubstr("file_name"));
  }
  // A name taken by other content: ALREADY_EXISTS (the same content is skipped; see
  // ClipNamesConflictsHashesAndUpdates).
  status = client.Ingest("humanoid_0.bvh", BvhText(Humanoid().clips[1]), &ingested);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::ALREADY_EXISTS);
  EXPECT_THAT(status.error_message(), HasSubstr("on_conflict"));

  // Unknown ids and names: NOT_FOUND.
  v1::GetClipRequest get;
  get.set_clip_id(999999);
  v1::Clip clip;
  EXPECT_EQ(client.clips().GetClip(client.Context().get(), get, &clip).error_code(),
            grpc::StatusCode::NOT_FOUND);
  v1::DeleteClipRequest remove;
  remove.set_clip_id(999999);
  v1::DeleteClipResponse removed;
  EXPECT_EQ(client.clips().DeleteClip(client.Context().get(), remove, &removed).error_code(),
            grpc::StatusCode::NOT_FOUND);
  v1::ExportClipRequest export_request;
  export_request.mutable_clip()->set_clip_id(999999);
  v1::ExportClipResponse exported;
  EXPECT_EQ(
      client.clips().ExportClip(client.Context().get(), export_request, &exported).error_code(),
      grpc::StatusCode::NOT_FOUND);
  v1::GetSpaceRequest get_space;
  get_space.set_name("nowhere");
  EXPECT_EQ(client.spaces().GetSpace(client.Context().get(), get_space, &space).error_code(),
            grpc::StatusCode::NOT_FOUND);
  v1::DeleteSpaceRequest drop;
  drop.set_name("nowhere");
  v1::DeleteSpaceResponse dropped;
  EXPECT_EQ(client.spaces().DeleteSpace(client.Context().get(), drop, &dropped).error_code(),
            grpc::StatusCode::NOT_FOUND);
  EXPECT_EQ(client.Search(ClipQuery("nowhere", ids[0], 0, 10), &found).error_code(),
            grpc::StatusCode::NOT_FOUND);
  EXPECT_EQ(client.Search(ClipQuery("body", 999999, 0, 10), &found).error_code(),
            grpc::StatusCode::NOT_FOUND);
  v1::CreateSpaceRequest unknown_training;
  unknown_training.set_name("t");
  unknown_training.add_training()->set_clip_id(999999);
  status = client.CreateSpace(unknown_training, &space);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::NOT_FOUND);
  EXPECT_THAT(status.error_message(), HasSubstr("training[0]"));
  v1::CreateSpaceRequest unknown_skeleton;
  unknown_skeleton.set_name("t");
  unknown_skeleton.set_skeleton_id(999999);
  EXPECT_EQ(client.CreateSpace(unknown_skeleton, &space).error_code(), grpc::StatusCode::NOT_FOUND);

  // Bad parameters: INVALID_ARGUMENT naming the field.
  struct BadSearch {
    std::function<void(v1::SearchRequest*)> change;
    std::string field;
  };
  const std::vector<BadSearch> bad_searches = {
      {[](v1::SearchRequest* r) { r->set_ann_dims(0); }, "ann_dims"},
      {[](v1::SearchRequest* r) { r->set_dtw_dims(1000); }, "dtw_dims"},
      {[](v1::SearchRequest* r) { r->set_neighbours(-5); }, "neighbours"},
      {[](v1::SearchRequest* r) { r->set_slope_limit(0); }, "slope_limit"},
      {[](v1::SearchRequest* r) { r->set_max_results(0); }, "max_results"},
      {[](v1::SearchRequest* r) { r->set_max_overlap(2); }, "max_overlap"},
      {[](v1::SearchRequest* r) { r->set_characteristic_frame(5000); }, "characteristic_frame"},
      {[](v1::SearchRequest* r) {
         r->add_characteristic_frames(30);
         r->add_characteristic_frames(20);
       },
       "characteristic_frames[1]: 20 does not follow the frame before it, 30"},
      {[](v1::SearchRequest* r) { r->add_characteristic_frames(5000); },
       "characteristic_frames[0]: 5000 is outside the query's frames 10..60"},
      {[](v1::SearchRequest* r) { r->set_characteristic_points(17); }, "characteristic_points"},
      {[](v1::SearchRequest* r) { r->set_max_point_gap_s(-1); }, "max_point_gap_s"},
      {[](v1::SearchRequest* r) { r->set_second_anchor_scatter(1.5); },
       "second_anchor_scatter = 1.5 is out of range; expected 0..1"},
      {[](v1::SearchRequest* r) { r->mutable_clip()->set_last_frame(100000); }, "last_frame"},
      {[](v1::SearchRequest* r) { r->mutable_clip()->set_first_frame(-1); }, "first_frame"},
      {[](v1::SearchRequest* r) { r->set_neutral(static_cast<v1::NeutralPose>(9)); }, "neutral"},
      {[](v1::SearchRequest* r) { r->clear_clip(); }, "query"},
      {[](v1::SearchRequest* r) { r->set_space(""); }, "space"},
  };
  for (const BadSearch& bad : bad_searches) {
    v1::SearchRequest request = ClipQuery("body", ids[0], 10, 60);
    bad.change(&request);
    status = client.Search(request, &found);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << bad.field;
    EXPECT_THAT(status.error_message(), HasSubstr(bad.field));
  }
  v1::SearchRequest bad_upload;
  bad_upload.set_space("body");
  bad_upload.mutable_bvh()->set_bvh("HIERARCHY\n");
  status = client.Search(bad_upload, &found);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("line"));

  struct BadSpace {
    std::function<void(v1::CreateSpaceRequest*)> change;
    grpc::StatusCode code;
    std::string words;
  };
  const std::vector<BadSpace> bad_spaces = {
      {[](v1::CreateSpaceRequest* r) { r->set_name(""); }, grpc::StatusCode::INVALID_ARGUMENT,
       "name"},
      {[](v1::CreateSpaceRequest* r) { r->set_name("a b"); }, grpc::StatusCode::INVALID_ARGUMENT,
       "name"},
      {[](v1::CreateSpaceRequest* r) { r->set_name("body"); }, grpc::StatusCode::ALREADY_EXISTS,
       "body"},
      {[](v1::CreateSpaceRequest* r) { r->set_sample_rate(-1); },
       grpc::StatusCode::INVALID_ARGUMENT, "rate"},
      // Found by the space request fuzzer: the training frames were counted at this rate
      // before it was checked (an overflow).
      {[](v1::CreateSpaceRequest* r) { r->set_sample_rate(3.9e295); },
       grpc::StatusCode::INVALID_ARGUMENT, "rate"},
      // Found by it too: at 7400-8300 Hz a space over three short clips took 10-14 s to build,
      // beyond the reach of the call's deadline.
      {[](v1::CreateSpaceRequest* r) { r->set_sample_rate(8000); },
       grpc::StatusCode::INVALID_ARGUMENT, "(0, 1000]"},
      {[](v1::CreateSpaceRequest* r) { r->set_weights_json("[1, 2]"); },
       grpc::StatusCode::INVALID_ARGUMENT, "weights_json"},
      {[](v1::CreateSpaceRequest* r) { (*r->mutable_weight_overrides())["NoSuchJoint"] = 1; },
       grpc::StatusCode::INVALID_ARGUMENT, "NoSuchJoint"},
      {[](v1::CreateSpaceRequest* r) {
         (*r->mutable_weight_overrides())["Hips"] = 1;
         r->set_weights_json("{\"Hips\": 2}");
       },
       grpc::StatusCode::INVALID_ARGUMENT, "weights_json"},
      {[](v1::CreateSpaceRequest* r) { r->set_metric(static_cast<v1::SpaceMetric>(7)); },
       grpc::StatusCode::INVALID_ARGUMENT, "metric"},
      {[&](v1::CreateSpaceRequest* r) {
         v1::ClipRange* range = r->add_training();
         range->set_clip_id(ids[0]);
         range->set_last_frame(1000000);
       },
       grpc::StatusCode::INVALID_ARGUMENT, "training[0].last_frame"},
  };
  for (const BadSpace& bad : bad_spaces) {
    v1::CreateSpaceRequest request;
    request.set_name("fresh");
    bad.change(&request);
    status = client.CreateSpace(request, &space);
    EXPECT_EQ(status.error_code(), bad.code) << bad.words << ": " << status.error_message();
    EXPECT_THAT(status.error_message(), HasSubstr(bad.words));
  }
  v1::GetCurveRequest curve;
  curve.set_space("body");
  curve.mutable_clip()->set_clip_id(ids[0]);
  curve.set_dims(0);
  v1::GetCurveResponse curve_response;
  status = client.spaces().GetCurve(client.Context().get(), curve, &curve_response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("dims"));
  v1::ListClipsRequest list;
  list.set_page_token("not a token");
  v1::ListClipsResponse page;
  EXPECT_EQ(client.clips().ListClips(client.Context().get(), list, &page).error_code(),
            grpc::StatusCode::INVALID_ARGUMENT);
  v1::ListClipsRequest sorted;
  sorted.set_sort("size");
  status = client.clips().ListClips(client.Context().get(), sorted, &page);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("sort: 'size' is not id, name or created"));
  v1::ListSpacesRequest list_spaces;
  list_spaces.set_page_token("x");
  v1::ListSpacesResponse spaces;
  EXPECT_EQ(client.spaces().ListSpaces(client.Context().get(), list_spaces, &spaces).error_code(),
            grpc::StatusCode::INVALID_ARGUMENT);
  // The search of a clip of another skeleton (the chain) in the humanoid space.
  const int64_t chain = client.IngestOrFail("chain.bvh", BvhText(ChainClip()));
  EXPECT_EQ(client.Search(ClipQuery("body", chain, 0, 10), &found).error_code(),
            grpc::StatusCode::FAILED_PRECONDITION);
}

TEST_F(ServerTest, OversizeRequestsAreResourceExhausted) {
  ServerProcess* server = StartServer({"--max-message-mb", "1", "--max-bvh-mb", "2"});
  ASSERT_NE(server, nullptr);
  Client client(testing::InsecureChannel(server->address()));
  // Over the message limit: refused by gRPC before the handler.
  v1::IngestClipResponse ingested;
  grpc::Status status = client.Ingest("big.bvh", std::string(1500 * 1024, ' '), &ingested);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED) << status.error_message();
  // Streamed in messages under the limit, but over the BVH limit in total.
  auto context = client.Context();
  auto writer = client.clips().IngestClipStream(context.get(), &ingested);
  v1::IngestClipStreamRequest chunk;
  chunk.set_file_name("big.bvh");
  chunk.set_chunk(std::string(900 * 1024, ' '));
  for (int i = 0; i < 4 && writer->Write(chunk); ++i) chunk.clear_file_name();
  writer->WritesDone();
  status = writer->Finish();
  EXPECT_EQ(status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_THAT(status.error_message(), HasSubstr("--max-bvh-mb"));
  // Small requests still work.
  EXPECT_TRUE(client.Ingest("small.bvh", BvhText(ChainClip()), &ingested).ok());
}

// True once the server's /metrics holds `line` (a sample, e.g. "motiondb_uploads_in_progress 1"),
// waiting up to 30 s: what a test sends is not yet what the server runs.
bool WaitForMetric(const ServerProcess& server, const std::string& line) {
  httplib::Client http("127.0.0.1", server.http_port());
  const auto holds = [&] {
    const httplib::Result metrics = http.Get("/metrics");
    return metrics && metrics->body.find("\n" + line + "\n") != std::string::npos;
  };
  for (int i = 0; i < 3000 && !holds(); ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return holds();
}

// Idle ingest streams hold a thread each but no call slot (issue 37: two of them once locked a
// --threads 2 server out); with the watchdog on they are ended after a second.
TEST_F(ServerTest, IdleStreamsHoldNoSlotAndAreEnded) {
  for (const bool watched : {false, true}) {
    SCOPED_TRACE(watched ? "watched" : "unwatched");
    ServerProcess* server =
        StartServer({"--threads", "2", "--stream-idle-timeout-s", watched ? "1" : "0"});
    ASSERT_NE(server, nullptr);
    Client client(testing::InsecureChannel(server->address()));
    std::vector<std::unique_ptr<grpc::ClientContext>> contexts;
    std::vector<v1::IngestClipResponse> responses(2);
    std::vector<std::unique_ptr<grpc::ClientWriter<v1::IngestClipStreamRequest>>> idle;
    v1::IngestClipStreamRequest header;
    header.set_file_name("idle.bvh");
    for (int i = 0; i < 2; ++i) {
      contexts.push_back(client.Context());
      idle.push_back(client.clips().IngestClipStream(contexts.back().get(), &responses[i]));
      ASSERT_TRUE(idle.back()->Write(header));
    }
    // Unwatched, both streams are in the server, waiting for bytes, before the call is sent.
    if (!watched) {
      ASSERT_TRUE(WaitForMetric(*server, "motiondb_uploads_in_progress 2")) << server->Log();
    }
    v1::ServerInfo info;
    const grpc::Status status =
        client.server().GetServerInfo(client.Context().get(), v1::GetServerInfoRequest(), &info);
    EXPECT_TRUE(status.ok()) << status.error_message();
    if (watched) {
      for (auto& writer : idle) {
        const grpc::Status ended = writer->Finish();
        EXPECT_EQ(ended.error_code(), grpc::StatusCode::DEADLINE_EXCEEDED);
        EXPECT_THAT(ended.error_message(), HasSubstr("--stream-idle-timeout-s"));
      }
      EXPECT_THAT(server->Log(), HasSubstr("ended a stream from ipv4:127.0.0.1:"));
    } else {
      for (auto& context : contexts) context->TryCancel();
      for (auto& writer : idle) writer->Finish();
    }
  }
}

// --max-uploads bounds the ingests in progress, --max-upload-buffer-mb the bytes they hold.
TEST_F(ServerTest, UploadsInProgressAreBounded) {
  ServerProcess* server =
      StartServer({"--max-uploads", "1", "--max-upload-buffer-mb", "1", "--max-bvh-mb", "8"});
  ASSERT_NE(server, nullptr);
  Client client(testing::InsecureChannel(server->address()));
  const std::string bvh = BvhText(ChainClip());
  // An upload in progress: its first chunk sent, its last not yet.
  auto context = client.Context();
  v1::IngestClipResponse streamed;
  auto writer = client.clips().IngestClipStream(context.get(), &streamed);
  v1::IngestClipStreamRequest first;
  first.set_file_name("streamed.bvh");
  first.set_chunk(bvh.substr(0, 100));
  ASSERT_TRUE(writer->Write(first));
  // A second upload is refused once the server has taken the first in (seen on /metrics: the
  // stream's call may reach the server after a unary one sent later).
  ASSERT_TRUE(WaitForMetric(*server, "motiondb_uploads_in_progress 1")) << server->Log();
  v1::IngestClipResponse response;
  const grpc::Status refused = client.Ingest("unary.bvh", bvh, &response);
  EXPECT_EQ(refused.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_THAT(refused.error_message(), HasSubstr("(--max-uploads)"));
  v1::IngestClipStreamRequest rest;
  rest.set_chunk(bvh.substr(100));
  ASSERT_TRUE(writer->Write(rest));
  writer->WritesDone();
  const grpc::Status done = writer->Finish();
  EXPECT_TRUE(done.ok()) << done.error_message();
  v1::IngestClipResponse again;
  EXPECT_TRUE(client.Ingest("unary2.bvh", bvh, &again).ok());

  // 2 MB in chunks: under --max-bvh-mb, over what uploads may hold together.
  auto big_context = client.Context();
  v1::IngestClipResponse big;
  auto big_writer = client.clips().IngestClipStream(big_context.get(), &big);
  v1::IngestClipStreamRequest chunk;
  chunk.set_file_name("big.bvh");
  chunk.set_chunk(std::string(256 * 1024, ' '));
  for (int i = 0; i < 8 && big_writer->Write(chunk); ++i) chunk.clear_file_name();
  big_writer->WritesDone();
  const grpc::Status over = big_writer->Finish();
  EXPECT_EQ(over.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_THAT(over.error_message(), HasSubstr("(--max-upload-buffer-mb)"));

  // 42 KB of text whose clip would take 1.3 MB (1000 joints, 40 frames, 32 bytes a joint a
  // frame whether it has channels or not): over the budget too, though its text is not.
  std::string wide =
      "HIERARCHY\nROOT r\n{\nOFFSET 0 0 0\nCHANNELS 3 Zrotation Xrotation Yrotation\n";
  for (int j = 1; j < 1000; ++j) {
    wide += "JOINT j" + std::to_string(j) + "\n{\nOFFSET 0 1 0\nCHANNELS 0\n}\n";
  }
  wide += "}\nMOTION\nFrames: 40\nFrame Time: 0.01\n";
  for (int frame = 0; frame < 40; ++frame) wide += "0 0 0\n";
  v1::IngestClipResponse wide_response;
  const grpc::Status too_wide = client.Ingest("wide.bvh", wide, &wide_response);
  EXPECT_EQ(too_wide.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED)
      << too_wide.error_message();
  EXPECT_THAT(too_wide.error_message(), HasSubstr("bytes of memory"));
}

// ---------------------------------------------------------------------------------------------
// Authentication, TLS, reflection.

// Calls /grpc.reflection.v1alpha.ServerReflection/ServerReflectionInfo with one request (raw
// protobuf bytes) and returns the response's bytes. The reflection messages are not compiled
// into the test (libgrpc++_reflection holds their generated code, without headers), so they are
// read as unknown fields.
grpc::Status Reflect(const std::shared_ptr<grpc::Channel>& channel, const std::string& token,
                     const std::string& request, std::string* response) {
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(10));
  if (!token.empty()) context.AddMetadata("authorization", "Bearer " + token);
  const grpc::internal::RpcMethod method(
      "/grpc.reflection.v1alpha.ServerReflection/ServerReflectionInfo",
      grpc::internal::RpcMethod::BIDI_STREAMING, channel);
  std::unique_ptr<grpc::ClientReaderWriter<grpc::ByteBuffer, grpc::ByteBuffer>> stream(
      grpc::internal::ClientReaderWriterFactory<grpc::ByteBuffer, grpc::ByteBuffer>::Create(
          channel.get(), method, &context));
  grpc::Slice slice(request);
  stream->Write(grpc::ByteBuffer(&slice, 1));
  stream->WritesDone();
  grpc::ByteBuffer reply;
  if (stream->Read(&reply)) {
    std::vector<grpc::Slice> slices;
    (void)reply.Dump(&slices);
    for (const grpc::Slice& s : slices) {
      response->append(reinterpret_cast<const char*>(s.begin()), s.size());
    }
  }
  return stream->Finish();
}

// Length-delimited fields `number` of a message's bytes.
std::vector<std::string> Fields(const std::string& bytes, int number) {
  google::protobuf::UnknownFieldSet fields;
  std::vector<std::string> out;
  if (!fields.ParseFromString(bytes)) return out;
  for (int i = 0; i < fields.field_count(); ++i) {
    if (fields.field(i).number() == number &&
        fields.field(i).type() == google::protobuf::UnknownField::TYPE_LENGTH_DELIMITED) {
      out.push_back(fields.field(i).length_delimited());
    }
  }
  return out;
}

std::string StringField(int number, const std::string& value) {
  std::string out(1, static_cast<char>(number << 3 | 2));
  out.push_back(static_cast<char>(value.size()));  // short values only
  return out + value;
}

TEST_F(ServerTest, ReflectionListsAndDescribesTheServices) {
  ServerProcess* server = StartServer();
  ASSERT_NE(server, nullptr);
  const auto channel = testing::InsecureChannel(server->address());
  // list_services (field 7) -> list_services_response (6) -> service (1) -> name (1).
  std::string response;
  grpc::Status status = Reflect(channel, "", StringField(7, "*"), &response);
  ASSERT_TRUE(status.ok()) << status.error_message();
  std::vector<std::string> names;
  for (const std::string& list : Fields(response, 6)) {
    for (const std::string& service : Fields(list, 1)) {
      for (const std::string& name : Fields(service, 1)) names.push_back(name);
    }
  }
  EXPECT_THAT(names,
              ::testing::IsSupersetOf({"motiondb.v1.ClipService", "motiondb.v1.SpaceService",
                                       "motiondb.v1.SearchService", "motiondb.v1.ServerService",
                                       "motiondb.v1.LabelService", "motiondb.v1.JobService",
                                       "grpc.health.v1.Health"}));
  // file_containing_symbol (4) -> file_descriptor_response (4) -> file_descriptor_proto (1).
  for (const auto& [symbol, file] : std::vector<std::pair<std::string, std::string>>{
           {"grpc.health.v1.Health", "grpc/health/v1/health.proto"},
           {"motiondb.v1.SearchService", "motiondb/v1/search_service.proto"}}) {
    response.clear();
    status = Reflect(channel, "", StringField(4, symbol), &response);
    ASSERT_TRUE(status.ok()) << status.error_message();
    std::vector<std::string> files;
    for (const std::string& descriptors : Fields(response, 4)) {
      for (const std::string& bytes : Fields(descriptors, 1)) {
        google::protobuf::FileDescriptorProto descriptor;
        ASSERT_TRUE(descriptor.ParseFromString(bytes));
        files.push_back(descriptor.name());
      }
    }
    EXPECT_THAT(files, ::testing::Contains(file)) << symbol;
  }
}

TEST_F(ServerTest, BearerTokenIsRequiredOnEveryCall) {
  const std::string token_file = WriteFile("token", "s3cret-token\n");
  ServerProcess* server = StartServer({"--auth-token-file", token_file}, "s3cret-token");
  ASSERT_NE(server, nullptr);
  const auto channel = testing::InsecureChannel(server->address());
  const v1::GetServerInfoRequest request;
  v1::ServerInfo info;
  for (const std::string& token : {std::string(""), std::string("wrong"),
                                   std::string("s3cret-tokenX"), std::string("s3cret-toke")}) {
    Client client(channel, token);
    const grpc::Status status =
        client.server().GetServerInfo(client.Context().get(), request, &info);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::UNAUTHENTICATED) << "'" << token << "'";
  }
  Client good(channel, "s3cret-token");
  ASSERT_TRUE(good.server().GetServerInfo(good.Context().get(), request, &info).ok());
  EXPECT_TRUE(info.auth_required());
  // Reflection too; the health service answers probes without the token.
  auto health = grpc::health::v1::Health::NewStub(channel);
  grpc::ClientContext context;
  grpc::health::v1::HealthCheckResponse serving;
  ASSERT_TRUE(health->Check(&context, grpc::health::v1::HealthCheckRequest(), &serving).ok());
  EXPECT_EQ(serving.status(), grpc::health::v1::HealthCheckResponse::SERVING);
  std::string response;
  EXPECT_EQ(Reflect(channel, "", StringField(7, "*"), &response).error_code(),
            grpc::StatusCode::UNAUTHENTICATED);
  EXPECT_TRUE(Reflect(channel, "s3cret-token", StringField(7, "*"), &response).ok());
  EXPECT_THAT(server->Log(), HasSubstr("/motiondb.v1.ServerService/GetServerInfo UNAUTHENTICATED"));

  // --health-needs-token: probes need it too.
  ServerProcess* strict =
      StartServer({"--auth-token-file", token_file, "--health-needs-token"}, "s3cret-token");
  ASSERT_NE(strict, nullptr);
  auto strict_health =
      grpc::health::v1::Health::NewStub(testing::InsecureChannel(strict->address()));
  grpc::ClientContext strict_context;
  EXPECT_EQ(strict_health->Check(&strict_context, grpc::health::v1::HealthCheckRequest(), &serving)
                .error_code(),
            grpc::StatusCode::UNAUTHENTICATED);
}

TEST_F(ServerTest, ServesTls) {
  const absl::StatusOr<testing::TlsFiles> tls = testing::MakeTlsCertificate(dir_);
  if (absl::IsNotFound(tls.status())) GTEST_SKIP() << tls.status().message();
  ASSERT_TRUE(tls.ok()) << tls.status();
  const std::string& cert = tls->cert;
  const std::string& key = tls->key;
  const std::string token_file = WriteFile("token", "tls-token");
  ServerProcess* server =
      StartServer({"--tls-cert", cert, "--tls-key", key, "--auth-token-file", token_file},
                  "tls-token", /*tls=*/true);
  ASSERT_NE(server, nullptr);

  grpc::SslCredentialsOptions ssl;
  ssl.pem_root_certs = testing::ReadFileOrDie(cert);
  grpc::ChannelArguments arguments;
  arguments.SetSslTargetNameOverride("localhost");
  Client client(grpc::CreateCustomChannel(server->address(), grpc::SslCredentials(ssl), arguments),
                "tls-token");
  v1::ServerInfo info;
  const grpc::Status status =
      client.server().GetServerInfo(client.Context().get(), v1::GetServerInfoRequest(), &info);
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_TRUE(info.tls());
  // A plain-text client cannot talk to it.
  Client plain(testing::InsecureChannel(server->address()), "tls-token");
  EXPECT_FALSE(plain.server()
                   .GetServerInfo(plain.Context(std::chrono::milliseconds(2000)).get(),
                                  v1::GetServerInfoRequest(), &info)
                   .ok());
  // One of the pair alone is a usage error.
  ServerProcess half;
  std::string error;
  EXPECT_FALSE(half.Start({"--db", db_, "--tls-cert", cert}, &error));
  EXPECT_THAT(error, HasSubstr("--tls-key"));
}

// ---------------------------------------------------------------------------------------------
// Lifecycle and concurrency.

// A database file damaged on disk, truncated or with zeroed pages, is refused at start with a
// message that says so and exit code 1, never a crash; the file is left as it was.
TEST_F(ServerTest, DamagedDatabaseIsRefusedAtStart) {
  {
    ServerProcess* server = StartServer();
    ASSERT_NE(server, nullptr);
    Client client(testing::InsecureChannel(server->address()));
    IngestHumanoid(client);
    CreateHumanoidSpace(client);
    ASSERT_EQ(server->Stop(SIGTERM), 0);
  }
  const std::string whole = testing::ReadFileOrDie(db_);
  ASSERT_GT(whole.size(), 64u * 1024);
  std::string zeroed = whole;
  std::fill(zeroed.begin() + 40 * 1024, zeroed.begin() + 60 * 1024, '\0');
  const std::vector<std::pair<std::string, std::string>> damaged = {
      {"truncated", whole.substr(0, whole.size() / 2)}, {"zeroed", zeroed}};
  for (const auto& [kind, bytes] : damaged) {
    SCOPED_TRACE(kind);
    const std::string path = WriteFile(kind + ".sqlite", bytes);
    ServerProcess server;
    std::string error;
    EXPECT_FALSE(server.Start({"--db", path}, &error));
    EXPECT_THAT(error, HasSubstr("exited with code 1"));
    EXPECT_THAT(error, ::testing::ContainsRegex("damaged|integrity check"));
    EXPECT_EQ(testing::ReadFileOrDie(path), bytes);
  }
}

// The same results, place and score, in the same order.
void ExpectSameResults(const v1::SearchResponse& after, const v1::SearchResponse& before) {
  ASSERT_EQ(after.results_size(), before.results_size());
  for (int i = 0; i < before.results_size(); ++i) {
    EXPECT_EQ(after.results(i).clip_id(), before.results(i).clip_id()) << i;
    EXPECT_EQ(after.results(i).start_frame(), before.results(i).start_frame()) << i;
    EXPECT_EQ(after.results(i).end_frame(), before.results(i).end_frame()) << i;
    EXPECT_EQ(after.results(i).score(), before.results(i).score()) << i;
  }
}

TEST_F(ServerTest, RestartKeepsEverything) {
  ServerProcess* server = StartServer();
  ASSERT_NE(server, nullptr);
  v1::SearchRequest query;
  v1::SearchResponse before;
  v1::Space space_before;
  v1::ListClipsResponse clips_before;
  {
    Client client(testing::InsecureChannel(server->address()));
    const std::vector<int64_t> ids = IngestHumanoid(client);
    space_before = CreateHumanoidSpace(client);
    const SyntheticSegment& raise = FirstRaise();
    query = ClipQuery("body", ids[raise.clip], raise.first_frame, raise.last_frame);
    ASSERT_TRUE(client.Search(query, &before).ok());
    ASSERT_TRUE(client.clips()
                    .ListClips(client.Context().get(), v1::ListClipsRequest(), &clips_before)
                    .ok());
  }
  EXPECT_EQ(server->Stop(SIGTERM), 0);
  EXPECT_THAT(server->Log(), HasSubstr("received SIGTERM"));

  server = StartServer();
  ASSERT_NE(server, nullptr);
  EXPECT_THAT(server->Log(), HasSubstr("loaded 1 space indices"));
  {
    Client client(testing::InsecureChannel(server->address()));
    v1::ListClipsResponse clips_after;
    ASSERT_TRUE(client.clips()
                    .ListClips(client.Context().get(), v1::ListClipsRequest(), &clips_after)
                    .ok());
    EXPECT_EQ(clips_after.SerializeAsString(), clips_before.SerializeAsString());
    v1::GetSpaceRequest get;
    get.set_name("body");
    v1::Space space_after;
    ASSERT_TRUE(client.spaces().GetSpace(client.Context().get(), get, &space_after).ok());
    EXPECT_EQ(space_after.SerializeAsString(), space_before.SerializeAsString());
    v1::SearchResponse after;
    ASSERT_TRUE(client.Search(query, &after).ok());
    ExpectSameResults(after, before);
  }
  // Stopped with no client connected: an idle connection makes a graceful stop wait (up to
  // 5 s in gRPC 1.51) for the client to acknowledge the GOAWAY.
  EXPECT_EQ(server->Stop(SIGINT), 0);
}

TEST_F(ServerTest, ConcurrentSearchesDuringIngestAllSucceed) {
  ServerProcess* server = StartServer({"--threads", "8"});
  ASSERT_NE(server, nullptr);
  Client client(testing::InsecureChannel(server->address()));
  const std::vector<int64_t> ids = IngestHumanoid(client);
  CreateHumanoidSpace(client);
  const SyntheticSegment& raise = FirstRaise();
  const v1::SearchRequest query =
      ClipQuery("body", ids[raise.clip], raise.first_frame, raise.last_frame);
  v1::SearchResponse baseline;
  ASSERT_TRUE(client.Search(query, &baseline).ok());

  std::atomic<bool> ingesting{true};
  std::atomic<int> searches{0};
  std::vector<std::string> failures[4];
  std::vector<std::thread> searchers;
  for (int t = 0; t < 4; ++t) {
    searchers.emplace_back([&, t] {
      Client own(testing::InsecureChannel(server->address()));
      int64_t library_frames = 0;
      // At least a few searches each, and on until the ingests are done.
      for (int i = 0; i < 5 || ingesting; ++i) {
        v1::SearchResponse found;
        const grpc::Status status = own.Search(query, &found);
        ++searches;
        if (!status.ok()) {
          failures[t].push_back(status.error_message());
          continue;
        }
        // Every answer comes from one whole snapshot: the query finds itself first, and the
        // library only grows.
        if (found.results_size() == 0 || found.results(0).clip_id() != ids[raise.clip] ||
            found.results(0).score() > 1e-3) {
          failures[t].push_back("the query did not find itself first");
        }
        if (found.counts().library_frames() < library_frames) {
          failures[t].push_back("the library shrank");
        }
        library_frames = found.counts().library_frames();
      }
    });
  }
  for (int i = 0; i < 6; ++i) {
    client.IngestOrFail("extra_" + std::to_string(i) + ".bvh",
                        BvhText(Humanoid().clips[i % Humanoid().clips.size()]));
  }
  ingesting = false;
  for (std::thread& thread : searchers) thread.join();
  for (const auto& failed : failures) EXPECT_THAT(failed, ::testing::IsEmpty());
  EXPECT_GE(searches.load(), 20);

  v1::SearchResponse final_answer;
  ASSERT_TRUE(client.Search(query, &final_answer).ok());
  v1::GetSpaceRequest get;
  get.set_name("body");
  v1::Space space;
  ASSERT_TRUE(client.spaces().GetSpace(client.Context().get(), get, &space).ok());
  EXPECT_EQ(space.index().clips(), static_cast<int64_t>(ids.size()) + 6);
  EXPECT_EQ(final_answer.counts().library_frames(), space.index().frames());
  EXPECT_GT(final_answer.counts().library_frames(), baseline.counts().library_frames());
}

TEST_F(ServerTest, DeadlineStopsALongExactSearch) {
  ServerProcess* server = StartServer();
  ASSERT_NE(server, nullptr);
  Client client(testing::InsecureChannel(server->address()));
  // A longer library: the whole thesis script, about five minutes at 50 fps.
  SyntheticCorpusOptions options;
  options.seed = 3;
  options.threads = 2;
  options.max_clip_duration_s = 60;
  absl::StatusOr<SyntheticCorpus> library = GenerateSyntheticCorpus(options);
  ASSERT_TRUE(library.ok()) << library.status();
  std::vector<int64_t> ids;
  for (size_t i = 0; i < library->clips.size(); ++i) {
    ids.push_back(
        client.IngestOrFail("long_" + std::to_string(i) + ".bvh", BvhText(library->clips[i])));
  }
  CreateHumanoidSpace(client);
  // A long query with every dimension in the warp makes the exhaustive search slow.
  v1::SearchRequest query = ClipQuery("body", ids[0], 0, library->clips[0].frame_count() / 2);
  query.set_exact(true);
  query.set_dtw_dims(64);
  query.set_slope_limit(4);
  const auto start = std::chrono::steady_clock::now();
  v1::SearchResponse found;
  grpc::Status status = client.Search(query, &found);
  const double full_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  ASSERT_TRUE(status.ok()) << status.error_message();
  std::cerr << "exact search without a deadline: " << full_ms << " ms\n";

  const auto deadline = std::chrono::milliseconds(static_cast<int>(std::max(20.0, full_ms / 5)));
  const auto start_late = std::chrono::steady_clock::now();
  status = client.Search(query, &found, deadline);
  const double late_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start_late)
          .count();
  EXPECT_EQ(status.error_code(), grpc::StatusCode::DEADLINE_EXCEEDED);
  // The server stops working too: its log line for the call says DEADLINE_EXCEEDED, which the
  // handler answers only when the engine stopped on the deadline (a search that ran to its end
  // would be logged OK). The times are printed, not compared: under load they say nothing.
  std::smatch line;
  const std::regex logged("/motiondb.v1.SearchService/Search DEADLINE_EXCEEDED ([0-9.]+)ms");
  std::string log;
  for (int i = 0; i < 1500 && !std::regex_search(log, line, logged); ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    log = server->Log();
  }
  ASSERT_TRUE(std::regex_search(log, line, logged)) << log;
  const double server_ms = std::stod(line[1]);
  std::cerr << "with a " << deadline.count() << " ms deadline: the client waited " << late_ms
            << " ms, the server worked " << server_ms << " ms\n";

  // A client that cancels: the server stops too, and logs CANCELLED.
  auto context = client.Context();
  std::thread canceller([&] {
    std::this_thread::sleep_for(deadline);
    context->TryCancel();
  });
  status = client.search().Search(context.get(), query, &found);
  canceller.join();
  EXPECT_EQ(status.error_code(), grpc::StatusCode::CANCELLED);
  const std::regex cancelled("/motiondb.v1.SearchService/Search CANCELLED ([0-9.]+)ms");
  for (int i = 0; i < 1500 && !std::regex_search(log, line, cancelled); ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    log = server->Log();
  }
  ASSERT_TRUE(std::regex_search(log, line, cancelled)) << log;
  std::cerr << "cancelled after " << deadline.count() << " ms: the server worked " << line[1]
            << " ms\n";
}

// The server's log once it holds `count` lines of `method` (waiting up to 30 s for a call that
// outlives its client's deadline).
std::string LogWithCalls(const ServerProcess& server, const std::string& method, int count) {
  std::string log;
  for (int i = 0; i < 1500; ++i) {
    log = server.Log();
    int found = 0;
    for (size_t at = log.find(method + " "); at != std::string::npos;
         at = log.find(method + " ", at + 1)) {
      ++found;
    }
    if (found >= count) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return log;
}

int64_t ClipCount(Client& client) {
  v1::ListClipsResponse page;
  const grpc::Status status =
      client.clips().ListClips(client.Context().get(), v1::ListClipsRequest(), &page);
  EXPECT_TRUE(status.ok()) << status.error_message();
  return page.clips_size();
}

// A write whose call ends before it commits is rolled back; it used to be stored, so that a
// client told DEADLINE_EXCEEDED retried into ALREADY_EXISTS.
TEST_F(ServerTest, WritesPastTheirDeadlineAreRolledBack) {
  ServerProcess* server = StartServer();
  ASSERT_NE(server, nullptr);
  Client client(testing::InsecureChannel(server->address()));
  // 20'000 frames (2.6 MB): parsing alone outlasts a 1 ms deadline.
  const std::string bvh = BvhText(testing::MakeClip(
      testing::ChainSkeleton(), 20'000, 1.0 / 30,
      [](int f, int j) {
        return Quat(Eigen::AngleAxisd(0.01 * f * (j + 1), Eigen::Vector3d::UnitY()));
      },
      [](int f, int) { return Eigen::Vector3d(0.1 * f, 90, 0); }));
  v1::IngestClipRequest request;
  request.set_file_name("long.bvh");
  request.set_bvh(bvh);
  constexpr int kAttempts = 3;
  for (int attempt = 0; attempt < kAttempts; ++attempt) {
    v1::IngestClipResponse response;
    const grpc::Status status = client.clips().IngestClip(
        client.Context(std::chrono::milliseconds(1)).get(), request, &response);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::DEADLINE_EXCEEDED) << status.error_message();
  }
  // Some of these reach their handler (which then parses for about 20 ms and rolls back), some
  // end in transfer; which ones is not known here, so there is nothing to wait for but the
  // stream below, which takes 1.5 s. A late commit could only make the test pass wrongly.

  // A stream whose client stops before its last chunk, the file whole so far: the deadline ends
  // the stream, which must not be taken for the end of the file.
  auto context = client.Context(std::chrono::milliseconds(1000));
  v1::IngestClipResponse streamed;
  auto writer = client.clips().IngestClipStream(context.get(), &streamed);
  v1::IngestClipStreamRequest whole;
  whole.set_file_name("cut.bvh");
  whole.set_chunk(bvh);
  ASSERT_TRUE(writer->Write(whole));
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));
  EXPECT_EQ(writer->Finish().error_code(), grpc::StatusCode::DEADLINE_EXCEEDED);
  // The server may see the client's cancellation (sent when the client's timer fires) before
  // its own deadline passes: CANCELLED or DEADLINE_EXCEEDED.
  const std::string log = LogWithCalls(*server, "/motiondb.v1.ClipService/IngestClipStream", 1);
  EXPECT_THAT(log, ::testing::ContainsRegex(
                       "/motiondb.v1.ClipService/IngestClipStream (CANCELLED|DEADLINE_EXCEEDED)"));

  EXPECT_EQ(ClipCount(client), 0) << log;
  // The retry a client makes stores the clip, as new.
  v1::IngestClipResponse stored;
  ASSERT_TRUE(client.clips().IngestClip(client.Context().get(), request, &stored).ok());
  EXPECT_EQ(stored.result(), v1::INGEST_RESULT_STORED);
  EXPECT_EQ(ClipCount(client), 1);
}

// A backup taken while a client ingests: the copy passes integrity_check, holds every clip
// acknowledged before the backup began, and a server started on it serves the same searches.
TEST_F(ServerTest, BackupWhileIngestingServesTheSameSearches) {
  ServerProcess* server = StartServer();
  ASSERT_NE(server, nullptr);
  Client client(testing::InsecureChannel(server->address()));
  const std::vector<int64_t> ids = IngestHumanoid(client);
  CreateHumanoidSpace(client);
  const SyntheticSegment& raise = FirstRaise();
  const v1::SearchRequest query =
      ClipQuery("body", ids[raise.clip], raise.first_frame, raise.last_frame);
  v1::SearchResponse live;
  ASSERT_TRUE(client.Search(query, &live).ok());

  std::atomic<int64_t> acknowledged = static_cast<int64_t>(ids.size());
  std::atomic<bool> stop = false;
  std::thread ingester([&] {
    Client own(testing::InsecureChannel(server->address()));
    for (int i = 0; !stop; ++i) {
      v1::IngestClipResponse response;
      if (own.Ingest("chain_" + std::to_string(i) + ".bvh", BvhText(ChainClip(0.01 * (i + 1))),
                     &response)
              .ok()) {
        ++acknowledged;
      }
    }
  });
  while (acknowledged < static_cast<int64_t>(ids.size()) + 5) std::this_thread::yield();
  const int64_t before = acknowledged;
  const std::string copy = (dir_ / "copy.sqlite").string();
  {
    auto context = client.Context();
    auto reader = client.server().CreateBackup(context.get(), v1::CreateBackupRequest());
    std::ofstream file(copy, std::ios::binary);
    v1::BackupChunk chunk;
    int64_t total = -1, received = 0;
    while (reader->Read(&chunk)) {
      if (total < 0) {
        total = chunk.total_bytes();
        EXPECT_GE(chunk.counts().clips(), before);
      }
      file << chunk.data();
      received += static_cast<int64_t>(chunk.data().size());
    }
    const grpc::Status status = reader->Finish();
    ASSERT_TRUE(status.ok()) << status.error_message();
    EXPECT_EQ(received, total);
  }
  stop = true;
  ingester.join();
  // Nothing is left beside the live database.
  for (const auto& entry : std::filesystem::directory_iterator(dir_)) {
    EXPECT_THAT(entry.path().filename().string(), ::testing::Not(HasSubstr("backup"))) << entry;
  }

  ServerProcess* restored = StartServer({"--db", copy});
  ASSERT_NE(restored, nullptr);
  Client copy_client(testing::InsecureChannel(restored->address()));
  v1::ListClipsRequest all;
  all.set_page_size(1000);
  v1::ListClipsResponse page;
  ASSERT_TRUE(copy_client.clips().ListClips(copy_client.Context().get(), all, &page).ok());
  EXPECT_GE(page.clips_size(), before);
  v1::SearchResponse restored_found;
  ASSERT_TRUE(copy_client.Search(query, &restored_found).ok());
  ASSERT_EQ(restored_found.results_size(), live.results_size());
  for (int i = 0; i < live.results_size(); ++i) {
    EXPECT_EQ(restored_found.results(i).clip_id(), live.results(i).clip_id());
    EXPECT_EQ(restored_found.results(i).start_frame(), live.results(i).start_frame());
    EXPECT_EQ(restored_found.results(i).score(), live.results(i).score());
  }
  restored->Stop(SIGTERM);
  std::unique_ptr<storage::SqliteConnection> raw =
      *storage::SqliteConnection::Open(copy, storage::SqliteConnection::Mode::kReadOnly, 1000);
  EXPECT_EQ(*raw->QueryText("PRAGMA integrity_check"), "ok");
}

// ---------------------------------------------------------------------------------------------
// Propagation jobs.

// Adds `labels` (manual); returns them as stored.
std::vector<v1::Label> AddLabelsOrFail(Client& client, const std::vector<v1::NewLabel>& labels) {
  v1::AddLabelsRequest add;
  for (const v1::NewLabel& label : labels) *add.add_labels() = label;
  v1::AddLabelsResponse added;
  const grpc::Status status = client.labels().AddLabels(client.Context().get(), add, &added);
  EXPECT_TRUE(status.ok()) << status.error_message();
  return {added.labels().begin(), added.labels().end()};
}

v1::StartPropagationRequest Propagation(const std::vector<std::string>& descriptors,
                                        int max_results = 8) {
  v1::StartPropagationRequest request;
  request.set_space("body");
  for (const std::string& descriptor : descriptors) request.add_descriptor_names(descriptor);
  request.mutable_search()->set_max_results(max_results);
  return request;
}

// The job as started; an empty job after a failed expectation.
v1::Job StartOrFail(Client& client, const v1::StartPropagationRequest& request) {
  v1::Job job;
  const grpc::Status status = client.jobs().StartPropagation(client.Context().get(), request, &job);
  EXPECT_TRUE(status.ok()) << status.error_message();
  EXPECT_EQ(job.state(), v1::JOB_STATE_QUEUED);
  return job;
}

bool Ended(const v1::Job& job) {
  return job.state() != v1::JOB_STATE_QUEUED && job.state() != v1::JOB_STATE_RUNNING;
}

// Polls the job until `done(job)` (the job then) or 120 s (a failed expectation).
v1::Job PollJob(Client& client, const std::string& job_id,
                const std::function<bool(const v1::Job&)>& done = Ended) {
  v1::GetJobRequest get;
  get.set_job_id(job_id);
  v1::Job job;
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  while (std::chrono::steady_clock::now() < give_up) {
    const grpc::Status status = client.jobs().GetJob(client.Context().get(), get, &job);
    EXPECT_TRUE(status.ok()) << status.error_message();
    if (!status.ok() || done(job)) return job;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ADD_FAILURE() << job_id << " never got there: " << job.ShortDebugString();
  return job;
}

// Every propagated label, in id order.
std::vector<v1::Label> Propagated(Client& client) {
  v1::ListLabelsRequest list;
  list.set_origin(v1::LABEL_ORIGIN_PROPAGATED);
  list.set_page_size(1000);
  std::vector<v1::Label> labels;
  v1::ListLabelsResponse page;
  do {
    const grpc::Status status = client.labels().ListLabels(client.Context().get(), list, &page);
    EXPECT_TRUE(status.ok()) << status.error_message();
    if (!status.ok()) break;
    labels.insert(labels.end(), page.labels().begin(), page.labels().end());
    list.set_page_token(page.next_page_token());
  } while (!list.page_token().empty());
  return labels;
}

bool Overlap(int64_t first, int64_t last, const SyntheticSegment& segment) {
  return first <= segment.last_frame && last >= segment.first_frame;
}

TEST_F(ServerTest, PropagationLabelsSimilarRangesAndReRunsReplaceItsOutput) {
  ServerProcess* server = StartServer();
  ASSERT_NE(server, nullptr);
  Client client(testing::InsecureChannel(server->address()));
  const std::vector<int64_t> ids = IngestHumanoid(client);
  CreateHumanoidSpace(client);
  // Two right-arm raises labelled by hand, and a shrug.
  std::vector<const SyntheticSegment*> raises, shrugs;
  for (const SyntheticSegment& segment : Humanoid().segments) {
    (segment.action == SyntheticAction::kRightArmRaise ? raises : shrugs).push_back(&segment);
  }
  ASSERT_GE(raises.size(), 4u);
  std::vector<v1::NewLabel> given;
  for (const SyntheticSegment* raise : {raises[0], raises[1]}) {
    given.push_back(
        FrameLabel(ids[raise->clip], raise->first_frame, raise->last_frame, "raise-right", 1.0));
  }
  given.push_back(FrameLabel(ids[Humanoid().segments.back().clip],
                             Humanoid().segments.back().first_frame,
                             Humanoid().segments.back().last_frame, "other", 0.5));
  const std::vector<v1::Label> manual = AddLabelsOrFail(client, given);
  ASSERT_EQ(manual.size(), 3u);

  // Watched to its end: the first message is the job as it was, the last its end.
  const v1::Job started = StartOrFail(client, Propagation({"raise-right"}));
  EXPECT_THAT(started.job_id(), ::testing::StartsWith("job-"));
  EXPECT_EQ(started.space(), "body");
  EXPECT_THAT(started.descriptor_names(), ::testing::ElementsAre("raise-right"));
  v1::WatchJobRequest watch;
  watch.set_job_id(started.job_id());
  auto context = client.Context();
  auto reader = client.jobs().WatchJob(context.get(), watch);
  std::vector<v1::Job> seen;
  for (v1::Job job; reader->Read(&job);) seen.push_back(job);
  ASSERT_TRUE(reader->Finish().ok());
  // One message at least (a fast job may have ended before the watch began); the last final.
  ASSERT_FALSE(seen.empty());
  const v1::Job& ended = seen.back();
  ASSERT_EQ(ended.state(), v1::JOB_STATE_SUCCEEDED) << ended.error();
  for (size_t i = 0; i + 1 < seen.size(); ++i) EXPECT_FALSE(Ended(seen[i]));
  EXPECT_EQ(ended.total(), 2);
  EXPECT_EQ(ended.done(), 2);
  EXPECT_EQ(ended.queries(), 2);
  EXPECT_GT(ended.labels_written(), 0);
  EXPECT_GT(ended.finished_unix_ms(), 0);

  // Found: propagated ranges with their source, job, space and score, values in (0, 1], no two
  // overlapping by more than half, on other raises too, and none of the "other" descriptor.
  v1::FindLabelsRequest find;
  find.set_descriptor_name("raise-right");
  find.set_page_size(1000);
  v1::FindLabelsResponse found;
  ASSERT_TRUE(client.labels().FindLabels(client.Context().get(), find, &found).ok());
  std::vector<v1::Label> propagated;
  for (const v1::Label& label : found.labels()) {
    if (label.origin() == v1::LABEL_ORIGIN_PROPAGATED) propagated.push_back(label);
  }
  EXPECT_EQ(static_cast<int64_t>(propagated.size()), ended.labels_written());
  EXPECT_EQ(Propagated(client).size(), propagated.size());
  int on_other_raises = 0;
  for (const v1::Label& label : propagated) {
    EXPECT_GT(label.value(), 0);
    EXPECT_LE(label.value(), 1);
    EXPECT_EQ(label.job_id(), started.job_id());
    EXPECT_EQ(label.space(), "body");
    EXPECT_THAT(label.source_label_id(),
                ::testing::AnyOf(manual[0].label_id(), manual[1].label_id()));
    EXPECT_GE(label.score(), 0);
    for (size_t r = 2; r < raises.size(); ++r) {
      if (ids[raises[r]->clip] == label.clip_id() &&
          Overlap(label.first_frame(), label.last_frame(), *raises[r])) {
        ++on_other_raises;
        break;
      }
    }
    for (const v1::Label& other : propagated) {
      if (other.label_id() == label.label_id() || other.clip_id() != label.clip_id()) continue;
      const int64_t shared = std::min(label.last_frame(), other.last_frame()) -
                             std::max(label.first_frame(), other.first_frame()) + 1;
      // Of the shorter one: a long range around a short stronger one is not kept beside it.
      EXPECT_LE(2 * shared, std::min(label.last_frame() - label.first_frame() + 1,
                                     other.last_frame() - other.first_frame() + 1));
    }
  }
  EXPECT_GE(on_other_raises, 2);
  // Strongest first: the best propagated label is the closest (the factor falls with score).
  EXPECT_LE(propagated.front().score(), propagated.back().score());

  // A re-run replaces the output: the same labels, of the new job; the manual ones unchanged.
  const v1::Job again = PollJob(client, StartOrFail(client, Propagation({"raise-right"})).job_id());
  ASSERT_EQ(again.state(), v1::JOB_STATE_SUCCEEDED) << again.error();
  EXPECT_EQ(again.labels_written(), ended.labels_written());
  const std::vector<v1::Label> replaced = Propagated(client);
  ASSERT_EQ(replaced.size(), propagated.size());
  for (const v1::Label& label : replaced) EXPECT_EQ(label.job_id(), again.job_id());
  v1::ListLabelsRequest list;
  list.set_origin(v1::LABEL_ORIGIN_MANUAL);
  v1::ListLabelsResponse kept;
  ASSERT_TRUE(client.labels().ListLabels(client.Context().get(), list, &kept).ok());
  ASSERT_EQ(kept.labels_size(), 3);
  for (int i = 0; i < 3; ++i)
    EXPECT_EQ(kept.labels(i).ShortDebugString(), manual[i].ShortDebugString());

  // Listed newest first; a finished job cannot be cancelled.
  v1::ListJobsRequest jobs_request;
  v1::ListJobsResponse jobs;
  ASSERT_TRUE(client.jobs().ListJobs(client.Context().get(), jobs_request, &jobs).ok());
  ASSERT_EQ(jobs.jobs_size(), 2);
  EXPECT_EQ(jobs.jobs(0).job_id(), again.job_id());
  EXPECT_EQ(jobs.jobs(1).job_id(), started.job_id());
  v1::CancelJobRequest cancel;
  cancel.set_job_id(started.job_id());
  v1::Job cancelled;
  const grpc::Status refused = client.jobs().CancelJob(client.Context().get(), cancel, &cancelled);
  EXPECT_EQ(refused.error_code(), grpc::StatusCode::FAILED_PRECONDITION);
  EXPECT_THAT(refused.error_message(), HasSubstr("succeeded"));
  EXPECT_THAT(server->Log(), HasSubstr("/motiondb.v1.JobService/StartPropagation OK "));
}

// A space whose search metric is learned from the manual labels: refused with a clear error
// while no descriptor labels two clips or its shrink is out of range; then built, its report
// saying what it was fitted on, its curves the projection as in a space without it, its
// searches finding the labelled action again with explanations that add up, and all of it as
// before after a restart (the transform stored with the space).
TEST_F(ServerTest, ASpaceSearchesInAMetricLearnedFromTheLabels) {
  ServerProcess* server = StartServer();
  ASSERT_NE(server, nullptr);
  // What the restarted server must answer alike: a stored and an uploaded query (the latter
  // projected anew in the space as read back), and a curve (turned back through its inverse).
  v1::SearchRequest query, uploaded;
  v1::SearchResponse before, uploaded_before;
  v1::GetCurveRequest curve_request;
  v1::GetCurveResponse learned_curve;
  v1::Space learned;
  {
    Client client(testing::InsecureChannel(server->address()));
    const std::vector<int64_t> ids = IngestHumanoid(client);
    CreateHumanoidSpace(client);
    v1::CreateSpaceRequest request;
    request.set_name("learned");
    request.mutable_learned_metric();
    grpc::Status status = client.CreateSpace(request, &learned);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::FAILED_PRECONDITION);
    EXPECT_EQ(status.error_message(),
              "learned_metric: needs one descriptor labelled (manual labels, value >= 0.5) on at "
              "least two clips of the space's skeleton; of its 0 such labels, no descriptor is on "
              "two clips");
    request.mutable_learned_metric()->set_shrink(1);
    status = client.CreateSpace(request, &learned);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
    EXPECT_EQ(status.error_message(), "learned_metric.shrink: 1 is outside [0, 1)");

    // Every action labelled by its kind (the script's kinds fall on several clips), and one weak
    // label that is no example.
    std::vector<v1::NewLabel> given;
    for (const SyntheticSegment& segment : Humanoid().segments) {
      given.push_back(FrameLabel(ids[segment.clip], segment.first_frame, segment.last_frame,
                                 absl::StrCat("action-", static_cast<int>(segment.action))));
    }
    given.push_back(FrameLabel(ids[0], std::nullopt, std::nullopt, "action-0", 0.2));
    AddLabelsOrFail(client, given);

    request.mutable_learned_metric()->clear_shrink();
    status = client.CreateSpace(request, &learned);
    ASSERT_TRUE(status.ok()) << status.error_message();
    ASSERT_TRUE(learned.report().has_learned_metric());
    EXPECT_EQ(learned.report().learned_metric().examples(), static_cast<int64_t>(given.size()) - 1);
    EXPECT_EQ(learned.report().learned_metric().descriptors(), 4);
    EXPECT_EQ(learned.report().learned_metric().shrink(), 0.95);

    // The curve is the projection, the same as the plain space's (one training set).
    const SyntheticSegment& raise = FirstRaise();
    curve_request.mutable_clip()->set_clip_id(ids[raise.clip]);
    curve_request.set_dims(5);
    v1::GetCurveResponse plain_curve;
    curve_request.set_space("body");
    ASSERT_TRUE(client.spaces().GetCurve(client.Context().get(), curve_request, &plain_curve).ok());
    curve_request.set_space("learned");
    ASSERT_TRUE(
        client.spaces().GetCurve(client.Context().get(), curve_request, &learned_curve).ok());
    ASSERT_EQ(learned_curve.coordinates().size(), plain_curve.coordinates().size());
    std::vector<float> plain(plain_curve.coordinates().size() / 4), in_learned(plain.size());
    std::memcpy(plain.data(), plain_curve.coordinates().data(), 4 * plain.size());
    std::memcpy(in_learned.data(), learned_curve.coordinates().data(), 4 * plain.size());
    for (size_t i = 0; i < plain.size(); ++i) ASSERT_NEAR(in_learned[i], plain[i], 1e-4) << i;

    query = ClipQuery("learned", ids[raise.clip], raise.first_frame, raise.last_frame);
    query.set_explain(true);
    status = client.Search(query, &before);
    ASSERT_TRUE(status.ok()) << status.error_message();
    ASSERT_GE(before.results_size(), 3);
    EXPECT_EQ(before.results(0).clip_id(), ids[raise.clip]);  // itself
    // Explained in the space's own metric (tests/search_explanation_test.cc checks the split).
    for (const v1::SearchResult& r : before.results()) EXPECT_TRUE(r.has_explanation());
    uploaded = query;
    uploaded.mutable_bvh()->set_bvh(BvhText(Humanoid().clips[raise.clip]));
    uploaded.mutable_bvh()->set_first_frame(raise.first_frame);
    uploaded.mutable_bvh()->set_last_frame(raise.last_frame);
    status = client.Search(uploaded, &uploaded_before);
    ASSERT_TRUE(status.ok()) << status.error_message();
    ASSERT_GE(uploaded_before.results_size(), 3);
  }
  EXPECT_EQ(server->Stop(SIGTERM), 0);

  server = StartServer();
  ASSERT_NE(server, nullptr);
  Client client(testing::InsecureChannel(server->address()));
  v1::GetSpaceRequest get;
  get.set_name("learned");
  v1::Space after_restart;
  ASSERT_TRUE(client.spaces().GetSpace(client.Context().get(), get, &after_restart).ok());
  EXPECT_EQ(after_restart.report().SerializeAsString(), learned.report().SerializeAsString());
  v1::SearchResponse after;
  ASSERT_TRUE(client.Search(query, &after).ok());
  ExpectSameResults(after, before);
  ASSERT_TRUE(client.Search(uploaded, &after).ok());
  ExpectSameResults(after, uploaded_before);
  v1::GetCurveResponse curve_after;
  ASSERT_TRUE(client.spaces().GetCurve(client.Context().get(), curve_request, &curve_after).ok());
  EXPECT_EQ(curve_after.coordinates(), learned_curve.coordinates());
}

TEST_F(ServerTest, BadPropagationsGetTheirStatusCodes) {
  ServerProcess* server = StartServer();
  ASSERT_NE(server, nullptr);
  Client client(testing::InsecureChannel(server->address()));
  const int64_t walk = client.IngestOrFail("walk.bvh", BvhText(ChainClip()));
  v1::CreateSpaceRequest create;
  create.set_name("body");
  v1::Space space;
  ASSERT_TRUE(client.CreateSpace(create, &space).ok());

  const auto start = [&](const v1::StartPropagationRequest& request) {
    v1::Job job;
    return client.jobs().StartPropagation(client.Context().get(), request, &job);
  };
  // No descriptors given and no manual label: there is nothing to propagate (refused, rather
  // than a job that does nothing).
  grpc::Status status = start(Propagation({}));
  EXPECT_EQ(status.error_code(), grpc::StatusCode::FAILED_PRECONDITION);
  EXPECT_THAT(status.error_message(), HasSubstr("no manual label"));
  v1::StartPropagationRequest request = Propagation({"step"});
  request.set_space("nowhere");
  EXPECT_EQ(start(request).error_code(), grpc::StatusCode::NOT_FOUND);
  request = Propagation({"step", ""});
  status = start(request);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("descriptors[1]"));
  // Descriptors no label could carry: too long, a control character.
  for (const std::string& bad : {std::string(257, 'd'), std::string("st\x1b[2Jep")}) {
    status = start(Propagation({"step", bad}));
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
    EXPECT_THAT(status.error_message(), HasSubstr("descriptors[1]"));
  }
  request = Propagation({"step"});
  request.mutable_search()->set_max_results(0);
  status = start(request);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("max_results"));
  request = Propagation({"step"});
  request.mutable_search()->mutable_clip()->set_clip_id(walk);
  status = start(request);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("search.query"));

  // Unknown jobs.
  for (const std::string id : {"job-42", "nonsense"}) {
    v1::GetJobRequest get;
    get.set_job_id(id);
    v1::Job job;
    EXPECT_EQ(client.jobs().GetJob(client.Context().get(), get, &job).error_code(),
              grpc::StatusCode::NOT_FOUND);
    v1::CancelJobRequest cancel;
    cancel.set_job_id(id);
    EXPECT_EQ(client.jobs().CancelJob(client.Context().get(), cancel, &job).error_code(),
              grpc::StatusCode::NOT_FOUND);
    v1::WatchJobRequest watch;
    watch.set_job_id(id);
    auto context = client.Context();
    auto reader = client.jobs().WatchJob(context.get(), watch);
    EXPECT_FALSE(reader->Read(&job));
    EXPECT_EQ(reader->Finish().error_code(), grpc::StatusCode::NOT_FOUND);
  }
  // Given descriptors without manual labels: a job that finds nothing and writes nothing.
  const v1::Job job = PollJob(client, StartOrFail(client, Propagation({"step"})).job_id());
  EXPECT_EQ(job.state(), v1::JOB_STATE_SUCCEEDED) << job.error();
  EXPECT_EQ(job.total(), 0);
  EXPECT_EQ(job.labels_written(), 0);
  v1::ListJobsRequest list;
  list.set_page_size(-1);
  v1::ListJobsResponse jobs;
  EXPECT_EQ(client.jobs().ListJobs(client.Context().get(), list, &jobs).error_code(),
            grpc::StatusCode::INVALID_ARGUMENT);
}

// Many manual labels of "long" over the humanoid library, so that a job runs for a while.
std::vector<v1::Label> LabelManyRanges(Client& client, const std::vector<int64_t>& ids, int count) {
  std::vector<v1::NewLabel> given;
  for (int i = 0; i < count; ++i) {
    const size_t clip = i % ids.size();
    const int frames = Humanoid().clips[clip].frame_count();
    const int first = (i / static_cast<int>(ids.size()) * 37) % (frames - 80);
    given.push_back(FrameLabel(ids[clip], first, first + 60, "long", 1.0));
  }
  return AddLabelsOrFail(client, given);
}

bool Running(const v1::Job& job) {
  return Ended(job) || (job.state() == v1::JOB_STATE_RUNNING && job.done() >= 1);
}

TEST_F(ServerTest, RunningJobsRefuseOverlapsAreCancelledAndWatchedOutsideTheCallGate) {
  // One call at a time: a watch that held its place would block every other call. The job
  // waits after its first label until cancelled, so it is seen running on any machine.
  ServerProcess* server = StartServer({"--threads", "1", "--test-job-pause-after", "1"});
  ASSERT_NE(server, nullptr);
  Client client(testing::InsecureChannel(server->address()));
  const std::vector<int64_t> ids = IngestHumanoid(client);
  CreateHumanoidSpace(client);
  LabelManyRanges(client, ids, 20);
  AddLabelsOrFail(client, {FrameLabel(ids[0], 0, 50, "calm", 1.0)});
  const v1::Job started = StartOrFail(client, Propagation({"long", "calm"}));

  std::vector<v1::Job> watched;
  grpc::Status watch_status;
  std::thread watcher([&] {
    v1::WatchJobRequest watch;
    watch.set_job_id(started.job_id());
    auto context = client.Context(std::chrono::milliseconds(120000));
    auto reader = client.jobs().WatchJob(context.get(), watch);
    for (v1::Job job; reader->Read(&job);) watched.push_back(job);
    watch_status = reader->Finish();
  });
  const v1::Job running = PollJob(client, started.job_id(), Running);
  ASSERT_EQ(running.state(), v1::JOB_STATE_RUNNING);

  // A second job for one of its descriptors is refused, naming it; another descriptor runs.
  v1::Job second;
  const grpc::Status refused =
      client.jobs().StartPropagation(client.Context().get(), Propagation({"calm"}), &second);
  EXPECT_EQ(refused.error_code(), grpc::StatusCode::FAILED_PRECONDITION);
  EXPECT_THAT(refused.error_message(), HasSubstr(started.job_id()));

  v1::CancelJobRequest cancel;
  cancel.set_job_id(started.job_id());
  v1::Job cancelled;
  const grpc::Status status = client.jobs().CancelJob(client.Context().get(), cancel, &cancelled);
  ASSERT_TRUE(status.ok()) << status.error_message();
  // Answered at once, the job as it is: still running (it stops at its next check) or ended.
  EXPECT_THAT(cancelled.state(), ::testing::AnyOf(v1::JOB_STATE_RUNNING, v1::JOB_STATE_CANCELLED));
  const v1::Job stopped = PollJob(client, started.job_id());
  EXPECT_EQ(stopped.state(), v1::JOB_STATE_CANCELLED);
  EXPECT_LT(stopped.done(), stopped.total());
  // A second cancel finds it ended.
  const grpc::Status again = client.jobs().CancelJob(client.Context().get(), cancel, &cancelled);
  EXPECT_EQ(again.error_code(), grpc::StatusCode::FAILED_PRECONDITION);
  EXPECT_THAT(again.error_message(), HasSubstr("cancelled"));
  watcher.join();
  EXPECT_TRUE(watch_status.ok()) << watch_status.error_message();
  ASSERT_FALSE(watched.empty());
  EXPECT_EQ(watched.back().state(), v1::JOB_STATE_CANCELLED);
  EXPECT_TRUE(Propagated(client).empty());
  // Once it ended, the descriptor is free again.
  EXPECT_EQ(PollJob(client, StartOrFail(client, Propagation({"calm"})).job_id()).state(),
            v1::JOB_STATE_SUCCEEDED);
}

TEST_F(ServerTest, KillDuringAJobLeavesItInterruptedWithoutOutputAndItRunsAgain) {
  ServerProcess* server = StartServer();
  ASSERT_NE(server, nullptr);
  std::string job_id;
  int64_t earlier = 0;  // labels of the first, complete run
  {
    Client client(testing::InsecureChannel(server->address()));
    const std::vector<int64_t> ids = IngestHumanoid(client);
    CreateHumanoidSpace(client);
    LabelManyRanges(client, ids, 400);
    const v1::Job first = PollJob(client, StartOrFail(client, Propagation({"long"})).job_id());
    ASSERT_EQ(first.state(), v1::JOB_STATE_SUCCEEDED) << first.error();
    earlier = first.labels_written();
    ASSERT_GT(earlier, 0);
  }
  // Again with the job held after its first label, so that the kill finds it running on any
  // machine.
  EXPECT_EQ(server->Stop(SIGTERM), 0);
  server = StartServer({"--test-job-pause-after", "1"});
  ASSERT_NE(server, nullptr);
  {
    Client client(testing::InsecureChannel(server->address()));
    job_id = StartOrFail(client, Propagation({"long"})).job_id();
    ASSERT_EQ(PollJob(client, job_id, Running).state(), v1::JOB_STATE_RUNNING);
  }
  EXPECT_EQ(server->Stop(SIGKILL), 128 + SIGKILL);

  server = StartServer();
  ASSERT_NE(server, nullptr);
  Client client(testing::InsecureChannel(server->address()));
  v1::GetJobRequest get;
  get.set_job_id(job_id);
  v1::Job job;
  ASSERT_TRUE(client.jobs().GetJob(client.Context().get(), get, &job).ok());
  EXPECT_EQ(job.state(), v1::JOB_STATE_INTERRUPTED);
  EXPECT_THAT(job.error(), HasSubstr("stopped"));
  // The first run's output, whole; nothing of the cut-off run.
  const std::vector<v1::Label> labels = Propagated(client);
  EXPECT_EQ(static_cast<int64_t>(labels.size()), earlier);
  for (const v1::Label& label : labels) EXPECT_NE(label.job_id(), job_id);
  const v1::Job again = PollJob(client, StartOrFail(client, Propagation({"long"})).job_id());
  EXPECT_EQ(again.state(), v1::JOB_STATE_SUCCEEDED) << again.error();
  EXPECT_EQ(again.labels_written(), earlier);
}

// ---------------------------------------------------------------------------------------------
// Crash safety: SIGKILL at random points of ingest, space creation and propagation jobs.

// Rounds of the crash loop: MOTIONDB_CRASH_ROUNDS (scripts/crash-loop.sh runs 20), default 3;
// its random kill points come from MOTIONDB_CRASH_SEED (default 1).
int EnvInt(const char* name, int default_value) {
  const char* value = std::getenv(name);
  return value != nullptr ? std::atoi(value) : default_value;
}

// What the client of an ingest loop saw when the server was killed under it.
struct CutIngest {
  std::map<std::string, int> acknowledged;  // frames of each clip answered OK, by name
  std::string in_flight;                    // the clip sent when the answer failed
  int in_flight_frames = 0;
  bool failed_early = false;  // an ingest failed before the kill
};

// Ingests humanoid clips ("<prefix>_<i>", single messages and chunked streams alternately) until
// a call fails, while the server is killed after `delay` past the second acknowledged clip.
CutIngest IngestUntilKilled(ServerProcess& server, const std::string& prefix,
                            std::chrono::milliseconds delay) {
  std::vector<std::string> texts;
  for (const Clip& clip : Humanoid().clips) texts.push_back(BvhText(clip));
  CutIngest cut;
  std::atomic<int> acknowledged{0};
  std::atomic<bool> stopped{false};
  std::thread ingester([&] {
    Client own(testing::InsecureChannel(server.address()));
    for (int i = 0;; ++i) {
      const size_t source = i % texts.size();
      const std::string name = prefix + "_" + std::to_string(i);
      cut.in_flight = name;
      cut.in_flight_frames = Humanoid().clips[source].frame_count();
      v1::IngestClipResponse response;
      grpc::Status status;
      if (i % 2 == 0) {
        status = own.Ingest(name + ".bvh", texts[source], &response);
      } else {
        auto context = own.Context();
        auto writer = own.clips().IngestClipStream(context.get(), &response);
        v1::IngestClipStreamRequest header;
        header.set_file_name(name + ".bvh");
        bool written = writer->Write(header);
        for (size_t at = 0; written && at < texts[source].size(); at += 16384) {
          v1::IngestClipStreamRequest chunk;
          chunk.set_chunk(texts[source].substr(at, 16384));
          written = writer->Write(chunk);
        }
        if (written) writer->WritesDone();
        status = writer->Finish();
      }
      if (!status.ok()) {  // the server is gone (or, before the kill, a failure)
        stopped = true;
        return;
      }
      cut.acknowledged[name] = response.clip().frame_count();
      ++acknowledged;
    }
  });
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (acknowledged < 2 && !stopped && std::chrono::steady_clock::now() < give_up) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  std::this_thread::sleep_for(delay);
  cut.failed_early = stopped;
  EXPECT_EQ(server.Stop(SIGKILL), 128 + SIGKILL);
  ingester.join();
  return cut;
}

// Kills the server `delay` after a call to `operation` started on its own thread.
void KillDuring(ServerProcess& server, std::chrono::milliseconds delay,
                const std::function<void(Client&)>& operation) {
  std::thread caller([&] {
    Client own(testing::InsecureChannel(server.address()));
    operation(own);
  });
  std::this_thread::sleep_for(delay);
  EXPECT_EQ(server.Stop(SIGKILL), 128 + SIGKILL);
  caller.join();
}

// Every propagated label of `job_id`.
std::set<int64_t> LabelsOfJob(const std::vector<v1::Label>& labels, const std::string& job_id) {
  std::set<int64_t> ids;
  for (const v1::Label& label : labels) {
    if (label.job_id() == job_id) ids.insert(label.label_id());
  }
  return ids;
}

// Rounds of: a SIGKILL at a random moment of an ingest loop (single messages and chunked
// streams, each projected into a space), of a space's creation, or of a propagation job; then a
// restart on the same database. It must open (its integrity check passes) and hold every
// acknowledged clip whole, at most the one clip in flight besides (whole), every stored clip in
// the space's index; a space cut off is absent or whole (indexed and searchable); a job cut off
// is interrupted with none of its output, the earlier output kept, or succeeded with its output
// whole.
TEST_F(ServerTest, KillAtRandomPointsLosesNoAcknowledgedWriteAndLeavesNoHalfWrite) {
  const int rounds = EnvInt("MOTIONDB_CRASH_ROUNDS", 3);
  const int seed = EnvInt("MOTIONDB_CRASH_SEED", 1);
  std::mt19937 random(seed);
  ServerProcess* server = StartServer();
  ASSERT_NE(server, nullptr);
  std::map<std::string, int> expected_frames;  // every clip that must be stored, by name
  std::chrono::milliseconds creation_time, job_time;
  std::vector<v1::Label> job_output;  // the propagated labels of the last whole job
  {
    Client client(testing::InsecureChannel(server->address()));
    const std::vector<int64_t> ids = IngestHumanoid(client);
    ASSERT_EQ(ids.size(), Humanoid().clips.size());
    for (size_t i = 0; i < ids.size(); ++i) {
      expected_frames["humanoid_" + std::to_string(i)] = Humanoid().clips[i].frame_count();
    }
    auto started = std::chrono::steady_clock::now();
    CreateHumanoidSpace(client);
    creation_time = std::chrono::duration_cast<std::chrono::milliseconds>(
        std::chrono::steady_clock::now() - started);
    LabelManyRanges(client, ids, 400);
    started = std::chrono::steady_clock::now();
    const v1::Job first = PollJob(client, StartOrFail(client, Propagation({"long"})).job_id());
    ASSERT_EQ(first.state(), v1::JOB_STATE_SUCCEEDED) << first.error();
    job_time = std::chrono::duration_cast<std::chrono::milliseconds>(
        std::chrono::steady_clock::now() - started);
    job_output = Propagated(client);
    ASSERT_FALSE(job_output.empty());
  }
  std::set<std::string> known_spaces = {"body"};  // spaces that must be there
  const std::vector<std::string> kinds = {"ingest", "space creation", "propagation job"};
  for (int round = 0; round < rounds; ++round) {
    const int kind = round % 3;
    // Up to 1.5x the operation's uninterrupted time on the library as it is now (both grow with
    // it), so that some kills come after its end.
    const double growth = static_cast<double>(expected_frames.size()) / Humanoid().clips.size();
    const int window =
        kind == 0
            ? 150
            : static_cast<int>(1.5 * growth *
                               static_cast<double>((kind == 1 ? creation_time : job_time).count()));
    const std::chrono::milliseconds delay(std::uniform_int_distribution<int>(0, window)(random));
    SCOPED_TRACE(absl::StrCat("round ", round, " (seed ", seed, "): kill during ", kinds[kind],
                              " after ", delay.count(), " ms"));
    const std::string space_name = "round_" + std::to_string(round);
    std::string job_id;
    std::string outcome;  // what the round found, for the crash loop's report
    if (kind == 0) {
      CutIngest cut = IngestUntilKilled(*server, "bulk_" + std::to_string(round), delay);
      EXPECT_FALSE(cut.failed_early) << "an ingest failed before the kill";
      outcome = absl::StrCat(cut.acknowledged.size(), " clips acknowledged; the clip in flight ");
      for (const auto& [name, frames] : cut.acknowledged) expected_frames[name] = frames;
      // Only the clip in flight may have been stored besides, and then whole.
      expected_frames.emplace(cut.in_flight, -cut.in_flight_frames);
    } else if (kind == 1) {
      KillDuring(*server, delay, [&](Client& own) {
        v1::CreateSpaceRequest request;
        request.set_name(space_name);
        v1::Space space;
        own.CreateSpace(request, &space);
      });
    } else {
      Client client(testing::InsecureChannel(server->address()));
      job_id = StartOrFail(client, Propagation({"long"})).job_id();
      KillDuring(*server, delay, [](Client&) {});
    }

    server = StartServer();
    ASSERT_NE(server, nullptr);
    Client client(testing::InsecureChannel(server->address()));
    absl::StatusOr<std::unique_ptr<storage::SqliteConnection>> file =
        storage::SqliteConnection::Open(db_, storage::SqliteConnection::Mode::kReadOnly, 1000);
    ASSERT_TRUE(file.ok()) << file.status();
    EXPECT_EQ(*(*file)->QueryText("PRAGMA integrity_check"), "ok");

    v1::ListClipsRequest list;
    list.set_page_size(1000);
    v1::ListClipsResponse stored;
    ASSERT_TRUE(client.clips().ListClips(client.Context().get(), list, &stored).ok());
    std::map<std::string, int> stored_frames;
    for (const v1::Clip& clip : stored.clips()) stored_frames[clip.name()] = clip.frame_count();
    for (auto it = expected_frames.begin(); it != expected_frames.end();) {
      const auto [name, frames] = *it;
      const auto stored_clip = stored_frames.find(name);
      if (frames < 0) {  // the clip in flight: absent, or stored whole
        if (stored_clip == stored_frames.end()) {
          outcome += "absent";
          it = expected_frames.erase(it);
          continue;
        }
        outcome += "stored whole";
        EXPECT_EQ(stored_clip->second, -frames) << name;
        it->second = -frames;
      } else {
        EXPECT_NE(stored_clip, stored_frames.end()) << name << " was acknowledged but is missing";
        if (stored_clip != stored_frames.end()) {
          EXPECT_EQ(stored_clip->second, frames) << name;
        }
      }
      ++it;
    }
    EXPECT_EQ(stored_frames.size(), expected_frames.size());
    // Every stored clip reads back whole and is in the space's index.
    for (const v1::Clip& clip : stored.clips()) {
      v1::ExportClipRequest request;
      request.mutable_clip()->set_clip_id(clip.clip_id());
      v1::ExportClipResponse exported;
      ASSERT_TRUE(client.clips().ExportClip(client.Context().get(), request, &exported).ok());
      absl::StatusOr<BvhReadResult> read = ReadBvh(exported.bvh());
      ASSERT_TRUE(read.ok()) << clip.name() << ": " << read.status();
      EXPECT_EQ(read->clip.frame_count(), clip.frame_count()) << clip.name();
    }
    // Every space (a space cut off while being created is absent or whole) indexes every clip.
    v1::ListSpacesResponse spaces;
    ASSERT_TRUE(
        client.spaces().ListSpaces(client.Context().get(), v1::ListSpacesRequest(), &spaces).ok());
    std::set<std::string> space_names;
    for (const v1::Space& space : spaces.spaces()) space_names.insert(space.name());
    for (const std::string& name : known_spaces) EXPECT_EQ(space_names.count(name), 1u) << name;
    if (space_names.count(space_name) > 0) known_spaces.insert(space_name);
    if (kind == 1) outcome = space_names.count(space_name) > 0 ? "space whole" : "space absent";
    EXPECT_EQ(space_names, known_spaces);
    for (const v1::Space& space : spaces.spaces()) {
      EXPECT_EQ(space.index().clips(), stored.clips_size()) << space.name();
      v1::SearchResponse found;
      ASSERT_TRUE(
          client.Search(ClipQuery(space.name(), stored.clips(0).clip_id(), 0, 40), &found).ok());
      EXPECT_EQ(found.counts().library_frames(), space.index().frames()) << space.name();
      EXPECT_GT(found.results_size(), 0) << space.name();
    }
    if (!job_id.empty()) {
      v1::GetJobRequest get;
      get.set_job_id(job_id);
      v1::Job job;
      ASSERT_TRUE(client.jobs().GetJob(client.Context().get(), get, &job).ok());
      const std::vector<v1::Label> labels = Propagated(client);
      outcome = absl::StrCat("job ", v1::JobState_Name(job.state()), " at ", job.done(), "/",
                             job.total(), " labels, ", labels.size(), " propagated labels");
      if (job.state() == v1::JOB_STATE_SUCCEEDED) {
        EXPECT_EQ(static_cast<int64_t>(LabelsOfJob(labels, job_id).size()), job.labels_written());
        EXPECT_EQ(labels.size(), LabelsOfJob(labels, job_id).size());
        job_output = labels;
      } else {
        EXPECT_EQ(job.state(), v1::JOB_STATE_INTERRUPTED);
        EXPECT_TRUE(LabelsOfJob(labels, job_id).empty());
        ASSERT_EQ(labels.size(), job_output.size());
        for (size_t i = 0; i < labels.size(); ++i) {
          EXPECT_EQ(labels[i].SerializeAsString(), job_output[i].SerializeAsString());
        }
      }
    }
    std::cout << "round " << round << ": SIGKILL " << delay.count() << " ms into " << kinds[kind]
              << " (up to " << window << " ms): " << outcome << std::endl;
    if (HasFailure()) break;
  }
}

}  // namespace
}  // namespace motiondb
