// FBX and glTF files through the real server: a clip a take, unary and streamed, searched with,
// and refused with a clear error that stores nothing; the importer's crash is its own.
#include <filesystem>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/motion/forward_kinematics.h"
#include "core/scene/scene_reader.h"
#include "testing/server_process.h"
#include "tests/scene_files.h"
#include "tests/server_fixture.h"
#include "tests/test_data.h"

namespace motiondb {
namespace {

using ::testing::HasSubstr;
using testing::ReadFileOrDie;
using testing::ServerProcess;

int64_t ClipCount(Client& client) {
  v1::ListClipsRequest list;
  v1::ListClipsResponse page;
  EXPECT_TRUE(client.clips().ListClips(client.Context().get(), list, &page).ok());
  return page.total_size();
}

// Sends `bytes` in chunks of `chunk` bytes over IngestClipStream.
grpc::Status IngestStreamed(Client& client, const std::string& file_name, const std::string& bytes,
                            size_t chunk, v1::IngestClipResponse* response) {
  auto context = client.Context();
  auto writer = client.clips().IngestClipStream(context.get(), response);
  v1::IngestClipStreamRequest header;
  header.set_file_name(file_name);
  writer->Write(header);
  for (size_t at = 0; at < bytes.size(); at += chunk) {
    v1::IngestClipStreamRequest message;
    message.set_chunk(bytes.substr(at, chunk));
    if (!writer->Write(message)) break;
  }
  writer->WritesDone();
  return writer->Finish();
}

TEST_F(ServerTest, FbxAndGlbFilesAreStoredAClipATake) {
  MOTIONDB_BLENDER_FILE(two, "two.fbx");
  MOTIONDB_BLENDER_FILE(glb, "one.glb");
  ServerProcess* server = StartServer();
  ASSERT_NE(server, nullptr);
  Client client(testing::InsecureChannel(server->address()));

  v1::IngestClipResponse response;
  grpc::Status status = client.Ingest("session/two.FBX", ReadFileOrDie(two), &response, {"fbx"});
  ASSERT_TRUE(status.ok()) << status.error_message();
  ASSERT_EQ(response.more_takes_size(), 1);
  EXPECT_EQ(response.file().format(), "fbx");
  EXPECT_EQ(response.file().up_axis(), "Y");
  EXPECT_DOUBLE_EQ(response.file().unit_m(), 0.01);
  EXPECT_THAT(response.file().generator(), HasSubstr("Blender"));
  EXPECT_THAT(response.take(), HasSubstr("normal_001"));
  EXPECT_EQ(response.clip().name(), "two/" + response.take());
  EXPECT_EQ(response.clip().frame_count(), 51);
  EXPECT_NEAR(response.clip().fps(), 30, 1e-3);
  EXPECT_EQ(response.clip().source_file(), "session/two.FBX");
  const v1::IngestClipResponse& second = response.more_takes(0);
  EXPECT_THAT(second.take(), HasSubstr("normal_002"));
  EXPECT_EQ(second.clip().name(), "two/" + second.take());
  EXPECT_EQ(second.clip().frame_count(), 57);
  EXPECT_EQ(second.clip().skeleton_id(), response.clip().skeleton_id());
  EXPECT_THAT(second.clip().tags(), ::testing::ElementsAre("fbx"));
  EXPECT_EQ(ClipCount(client), 2);
  // The file's unit and up axis are kept with each clip.
  v1::GetClipRequest get;
  get.set_clip_id(second.clip().clip_id());
  v1::Clip stored;
  ASSERT_TRUE(client.clips().GetClip(client.Context().get(), get, &stored).ok());
  EXPECT_EQ(stored.source().format(), "fbx");
  EXPECT_DOUBLE_EQ(stored.source().unit_m(), 0.01);
  EXPECT_EQ(stored.source().up_axis(), "Y");

  // A GLB streamed in small chunks: one take, named after the file.
  const std::string glb_bytes = ReadFileOrDie(glb);
  status = IngestStreamed(client, "one.glb", glb_bytes, 4096, &response);
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_EQ(response.more_takes_size(), 0);
  EXPECT_EQ(response.clip().name(), "one");
  EXPECT_EQ(response.file().format(), "glb");
  EXPECT_DOUBLE_EQ(response.file().unit_m(), 1.0);
  EXPECT_EQ(response.clip().frame_count(), 51);
  EXPECT_EQ(ClipCount(client), 3);
}

TEST_F(ServerTest, AnFbxTakeSearchesTheTakesItWasMadeFrom) {
  MOTIONDB_BLENDER_FILE(two, "two.fbx");
  MOTIONDB_BLENDER_FILE(one, "one.fbx");
  ServerProcess* server = StartServer();
  ASSERT_NE(server, nullptr);
  Client client(testing::InsecureChannel(server->address()));
  v1::IngestClipResponse response;
  ASSERT_TRUE(client.Ingest("two.fbx", ReadFileOrDie(two), &response).ok());
  const int64_t first_take = response.clip().clip_id();
  v1::CreateSpaceRequest create;
  create.set_name("fbx");
  v1::Space space;
  const grpc::Status created = client.CreateSpace(create, &space);
  ASSERT_TRUE(created.ok()) << created.error_message();

  // The first take's own FBX, uploaded as the query, finds that take first.
  v1::SearchRequest request;
  request.set_space("fbx");
  request.mutable_bvh()->set_bvh(ReadFileOrDie(one));
  request.set_max_results(2);
  v1::SearchResponse found;
  const grpc::Status searched = client.Search(request, &found);
  ASSERT_TRUE(searched.ok()) << searched.error_message();
  ASSERT_GE(found.results_size(), 1);
  EXPECT_EQ(found.results(0).clip_id(), first_take);

  // A file of several takes is no query.
  request.mutable_bvh()->set_bvh(ReadFileOrDie(two));
  const grpc::Status refused = client.Search(request, &found);
  EXPECT_EQ(refused.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(refused.error_message(), HasSubstr("holds 2 takes"));
}

TEST_F(ServerTest, BadFbxAndGltfFilesAreRefusedAndStoreNothing) {
  MOTIONDB_BLENDER_FILE(mesh, "mesh.fbx");
  MOTIONDB_BLENDER_FILE(one, "one.fbx");
  ServerProcess* server = StartServer();
  ASSERT_NE(server, nullptr);
  Client client(testing::InsecureChannel(server->address()));
  const std::string fbx = ReadFileOrDie(one);
  std::string corrupt = fbx;
  for (size_t i = 64; i < corrupt.size(); i += 5) corrupt[i] = static_cast<char>(corrupt[i] ^ 0x33);
  const std::vector<std::pair<std::string, std::string>> files = {
      {"mesh.fbx", ReadFileOrDie(mesh)},
      {"cut.fbx", fbx.substr(0, fbx.size() / 3)},
      {"corrupt.fbx", corrupt},
      {"header.glb", "glTF\x02\x00\x00\x00"},
      {"empty.gltf", R"({"asset": {"version": "2.0"}})"},
      {"external.gltf",
       R"({"asset": {"version": "2.0"}, "buffers": [{"uri": "data.bin", "byteLength": 4}]})"},
  };
  for (const auto& [name, bytes] : files) {
    v1::IngestClipResponse response;
    const grpc::Status status = client.Ingest(name, bytes, &response);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT)
        << name << ": " << status.error_message();
    EXPECT_THAT(status.error_message(), HasSubstr(name + ": ")) << name;
  }
  v1::IngestClipResponse response;
  EXPECT_THAT(client.Ingest("mesh.fbx", ReadFileOrDie(mesh), &response).error_message(),
              HasSubstr("no skeletal animation"));
  EXPECT_EQ(ClipCount(client), 0);
  // The server is whole: a good file after them is stored.
  EXPECT_TRUE(client.Ingest("one.fbx", fbx, &response).ok());
  EXPECT_EQ(ClipCount(client), 1);
}

TEST_F(ServerTest, AnImporterThatCrashesFailsItsUploadOnly) {
  // An importer that dies as assimp would on a hostile file.
  const std::string crasher = WriteFile("crashing-importer", "#!/bin/sh\nkill -SEGV $$\n");
  std::filesystem::permissions(crasher, std::filesystem::perms::owner_all);
  ServerProcess* server = StartServer({"--scene-importer", crasher});
  ASSERT_NE(server, nullptr);
  Client client(testing::InsecureChannel(server->address()));
  v1::IngestClipResponse response;
  const grpc::Status status = client.Ingest(
      "take.glb", std::string("glTF\x02\x00\x00\x00", 8) + std::string(100, 'x'), &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << status.error_message();
  EXPECT_THAT(status.error_message(), HasSubstr("take.glb: the glb reader failed on this file"));
  EXPECT_THAT(status.error_message(), HasSubstr("signal 11"));
  // The server goes on.
  EXPECT_TRUE(client.Ingest("chain.bvh", BvhText(ChainClip()), &response).ok());
  EXPECT_EQ(ClipCount(client), 1);
}

TEST_F(ServerTest, AClipAndAHitExportAsGltfThatReadsBack) {
  ServerProcess* server = StartServer();
  ASSERT_NE(server, nullptr);
  Client client(testing::InsecureChannel(server->address()));
  const Clip chain = ChainClip();
  const int64_t id = client.IngestOrFail("session/chain.bvh", BvhText(chain));

  for (const std::string format : {"glb", "gltf"}) {
    v1::ExportClipRequest request;
    request.mutable_clip()->set_clip_id(id);
    request.mutable_clip()->set_first_frame(10);
    request.mutable_clip()->set_last_frame(40);
    request.set_format(format);
    v1::ExportClipResponse whole;
    const grpc::Status status = client.clips().ExportClip(client.Context().get(), request, &whole);
    ASSERT_TRUE(status.ok()) << status.error_message();
    EXPECT_EQ(whole.file_name(), "chain_10-40." + format);
    // Streamed, the pieces join into the same file.
    auto context = client.Context();
    auto reader = client.clips().ExportClipStream(context.get(), request);
    std::string streamed;
    v1::ExportClipResponse piece;
    while (reader->Read(&piece)) streamed += piece.bvh();
    ASSERT_TRUE(reader->Finish().ok());
    EXPECT_EQ(streamed, whole.bvh());

    auto read =
        ReadScene(whole.bvh(), format == "glb" ? MotionFileFormat::kGlb : MotionFileFormat::kGltf);
    ASSERT_TRUE(read.ok()) << read.status();
    ASSERT_EQ(read->takes.size(), 1u);
    const Clip& back = read->takes[0].clip;
    ASSERT_EQ(back.frame_count(), 31);
    const RowMatrixXd expected = ForwardKinematics(chain).middleRows(10, 31);
    const RowMatrixXd actual = ForwardKinematics(back);
    ASSERT_EQ(actual.cols(), expected.cols());
    EXPECT_LE((actual - expected).cwiseAbs().maxCoeff(), 1e-4 * expected.cwiseAbs().maxCoeff());
  }
  v1::ExportClipRequest bad;
  bad.mutable_clip()->set_clip_id(id);
  bad.set_format("fbx");
  v1::ExportClipResponse response;
  const grpc::Status refused = client.clips().ExportClip(client.Context().get(), bad, &response);
  EXPECT_EQ(refused.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(refused.error_message(), HasSubstr("format"));
}

}  // namespace
}  // namespace motiondb
