// The server's clips, through the real binary and the generated stubs (server_fixture.h):
// ingest, listing, poses and export, streamed uploads; clip names that fit a studio's folders.
#include <filesystem>
#include <functional>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include <gmock/gmock.h>
#include <google/protobuf/text_format.h>
#include <gtest/gtest.h>

#include "absl/strings/str_cat.h"
#include "core/bvh/bvh_reader.h"
#include "core/motion/forward_kinematics.h"
#include "testing/server_process.h"
#include "tests/server_fixture.h"
#include "tests/synthetic_motion.h"
#include "tests/test_data.h"
#include "util/byte_coding.h"

namespace motiondb {
namespace {

using ::testing::HasSubstr;
using testing::ServerProcess;

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

TEST_F(ServerTest, SkeletonsShowTheirHumanoidMapAndTakeOverrides) {
  ServerProcess* server = StartServer();
  ASSERT_NE(server, nullptr);
  Client client(testing::InsecureChannel(server->address()));
  v1::IngestClipResponse humanoid, chain;
  ASSERT_TRUE(client
                  .Ingest("humanoid.bvh",
                          BvhText(testing::SyntheticClip(testing::HumanoidSkeleton(false),
                                                         {.frames = 30, .fps = 30, .seed = 1})),
                          &humanoid)
                  .ok());
  ASSERT_TRUE(client.Ingest("chain.bvh", BvhText(ChainClip()), &chain).ok());
  const auto get = [&](int64_t skeleton_id, v1::SkeletonDetail* detail) {
    v1::GetSkeletonRequest request;
    request.set_skeleton_id(skeleton_id);
    return client.clips().GetSkeleton(client.Context().get(), request, detail);
  };
  const auto slots = [](const v1::SkeletonDetail& detail) {
    std::map<std::string, std::string> named;
    for (const v1::HumanoidSlot& slot : detail.humanoid_map().slots()) {
      named[slot.slot()] = slot.joint_name() + (slot.overridden() ? " (override)" : "");
    }
    return named;
  };

  v1::SkeletonDetail shown;
  ASSERT_TRUE(get(humanoid.clip().skeleton_id(), &shown).ok());
  EXPECT_EQ(shown.joints_size(), 19);
  EXPECT_EQ(shown.joints(2).name(), "Chest");
  EXPECT_EQ(shown.joints(2).parent(), 1);
  EXPECT_TRUE(shown.humanoid_map().complete());
  EXPECT_EQ(shown.humanoid_map().slots_size(), 19);  // every joint: no toes, the rest a slot
  EXPECT_EQ(slots(shown)["LeftLowerArm"], "LowerArm_L");
  EXPECT_EQ(shown.humanoid_map().mirror_pairs_size(), 7);
  EXPECT_EQ(shown.humanoid_map().mirror_pairs(0).left_name(), "Shoulder_L");
  EXPECT_EQ(shown.humanoid_map().mirror_pairs(0).right_name(), "Shoulder_R");

  // A skeleton that is no humanoid says what it misses; that is no error.
  v1::SkeletonDetail unmapped;
  ASSERT_TRUE(get(chain.clip().skeleton_id(), &unmapped).ok());
  EXPECT_FALSE(unmapped.humanoid_map().complete());
  EXPECT_EQ(unmapped.humanoid_map().missing_slots_size(), 15);
  EXPECT_EQ(unmapped.humanoid_map().missing_slots(0), "Hips");

  const auto map = [&](const std::string& text, v1::SkeletonDetail* detail) {
    v1::MapSkeletonRequest request;
    EXPECT_TRUE(google::protobuf::TextFormat::ParseFromString(text, &request));
    request.set_skeleton_id(humanoid.clip().skeleton_id());
    return client.clips().MapSkeleton(client.Context().get(), request, detail);
  };
  v1::SkeletonDetail mapped;
  ASSERT_TRUE(map("set { slot: 'LeftHand' joint: 'Hand_R' } set { slot: 'righthand' joint: "
                  "'Hand_L' }",
                  &mapped)
                  .ok());
  EXPECT_EQ(slots(mapped)["LeftHand"], "Hand_R (override)");
  EXPECT_EQ(slots(mapped)["RightHand"], "Hand_L (override)");
  EXPECT_EQ(slots(mapped)["LeftLowerArm"], "LowerArm_R");  // the chain follows its hand

  // Bad overrides are refused naming the field, and change nothing.
  for (const auto& [text, message] : std::vector<std::pair<std::string, std::string>>{
           {"set { slot: 'LeftHand' joint: 'hand_l' }",
            absl::StrCat("set[0].joint: skeleton ", humanoid.clip().skeleton_id(),
                         " has no joint named 'hand_l'")},
           {"set { slot: 'Tail' joint: 'Hips' }", "set[0].slot: 'Tail' is not a slot (Hips, "},
           {"clear: 'Head' clear: 'Wing'", "clear[1]: 'Wing' is not a slot"},
           {"set { slot: 'Head' joint: 'Hand_L' }",
            "set[0].joint: 'Hand_L' is already the override of slot RightHand"}}) {
    v1::SkeletonDetail refused;
    const grpc::Status status = map(text, &refused);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << text;
    EXPECT_THAT(status.error_message(), HasSubstr(message));
    v1::SkeletonDetail after;
    ASSERT_TRUE(get(humanoid.clip().skeleton_id(), &after).ok());
    EXPECT_EQ(after.SerializeAsString(), mapped.SerializeAsString()) << text;
  }

  v1::SkeletonDetail cleared;
  ASSERT_TRUE(map("clear: 'LeftHand' clear: 'RightHand'", &cleared).ok());
  EXPECT_EQ(cleared.SerializeAsString(), shown.SerializeAsString());
  v1::SkeletonDetail missing;
  EXPECT_EQ(get(999, &missing).error_code(), grpc::StatusCode::NOT_FOUND);
}

}  // namespace
}  // namespace motiondb
