// What the server refuses and bounds, through the real binary and the generated stubs
// (server_fixture.h): bad inputs and their status codes, oversize requests, idle streams and
// the uploads in progress.
#include <functional>
#include <thread>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "testing/server_process.h"
#include "tests/server_fixture.h"

// Last: it includes <resolv.h>, whose macro _res breaks Eigen's headers included after it.
#include <httplib.h>

namespace motiondb {
namespace {

using ::testing::HasSubstr;
using testing::ServerProcess;

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

}  // namespace
}  // namespace motiondb
