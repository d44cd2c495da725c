// Names' text checked where it enters (util/name_text.h; issue 37 defect 8 and the "Also" item on
// bidi and line separators), on the real server: a BVH file's joint names, clip names, tags,
// label descriptors, space names, propagation descriptors and pose model names that are not
// UTF-8 or hold a bidirectional control or a line separator are refused, naming the field (and a
// joint's line); and joint names an older version stored unchecked no longer fail every
// listing that holds them: they are answered with U+FFFD.
#include <sqlite3.h>

#include <csignal>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "absl/strings/escaping.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_replace.h"
#include "motiondb/v1/edit_service.grpc.pb.h"
#include "tests/server_fixture.h"

// Last: httplib.h includes <resolv.h>, whose _res macro breaks the Eigen headers above.
#include <httplib.h>

namespace motiondb {
namespace {

using ::testing::HasSubstr;

constexpr char kReplacement[] = "\xEF\xBF\xBD";  // U+FFFD

// A two-joint BVH file whose root is named `root` (line 2) and its child `child` (line 6).
std::string TwoJointBvh(const std::string& root, const std::string& child) {
  std::string text = absl::StrCat(
      "HIERARCHY\nROOT ", root,
      "\n{\n  OFFSET 0 0 0\n  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation "
      "Yrotation\n  JOINT ",
      child,
      "\n  {\n    OFFSET 0 10 0\n    CHANNELS 3 Zrotation Xrotation Yrotation\n    End Site\n"
      "    {\n      OFFSET 0 10 0\n    }\n  }\n}\nMOTION\nFrames: 4\nFrame Time: 0.0333333\n");
  for (int f = 0; f < 4; ++f) absl::StrAppend(&text, "0 90 0 ", f, " 0 0 0 ", 2 * f, " 0\n");
  return text;
}

class TextEntryTest : public ServerTest {};

// The probe stored a joint name with a byte that is not UTF-8; then `motiondb skeletons` and
// `clip show` failed for everyone, and HTTP answered 200 with no joints. The BVH reader now
// refuses such a name, and a bidirectional control, naming the line.
TEST_F(TextEntryTest, AJointNameThatIsNotPrintableUtf8IsRefusedWithItsLine) {
  testing::ServerProcess* server = StartServer();
  ASSERT_NE(server, nullptr);
  Client client(testing::InsecureChannel(server->address()));
  for (const auto& [bvh, message] : std::vector<std::pair<std::string, std::string>>{
           {TwoJointBvh("Hips\xFF", "Spine"),
            "line 2: joint name 'Hips\\xff' holds invalid UTF-8 at byte 4"},
           {TwoJointBvh("H\xFC"
                        "fte",
                        "Spine"),
            "line 2: joint name 'H\\xfcfte' holds invalid UTF-8 at byte 1"},
           {TwoJointBvh("Hips",
                        "Spine\xE2\x80\xAE"
                        "kcab"),
            "line 6: joint name 'Spine\\u202Ekcab' holds the bidirectional control U+202E at byte "
            "5"},
           {TwoJointBvh("Hips", "Spine\xE2\x80\xA8"),
            "line 6: joint name 'Spine\\u2028' holds the line separator U+2028"}}) {
    v1::IngestClipResponse response;
    const grpc::Status status = client.Ingest("take.bvh", bvh, &response);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << message;
    EXPECT_THAT(status.error_message(), HasSubstr(message));
  }
  // Through HTTP too, and nothing was stored.
  httplib::Client http("127.0.0.1", server->http_port());
  const httplib::Result posted =
      http.Post("/v1/clips",
                absl::StrCat(R"({"file_name": "take.bvh", "bvh": ")",
                             absl::Base64Escape(TwoJointBvh("Hips\xFF", "Spine")), R"("})"),
                "application/json");
  ASSERT_TRUE(posted);
  EXPECT_EQ(posted->status, 400);
  EXPECT_THAT(posted->body, HasSubstr("line 2: joint name"));
  v1::ListSkeletonsResponse skeletons;
  ASSERT_TRUE(client.clips().ListSkeletons(client.Context().get(), {}, &skeletons).ok());
  EXPECT_EQ(skeletons.skeletons_size(), 0);
}

// Bidirectional controls (a name that reads backwards, or hides its end) and line separators
// (a name that starts a new line in a log) are refused wherever a name enters, with the field.
TEST_F(TextEntryTest, NamesRefuseBidirectionalControlsAndLineSeparators) {
  testing::ServerProcess* server = StartServer();
  ASSERT_NE(server, nullptr);
  Client client(testing::InsecureChannel(server->address()));
  const int64_t clip = client.IngestOrFail("chain.bvh", BvhText(ChainClip()));
  ASSERT_EQ(CreateHumanoidSpace(client).name(), "body");  // on the chain: any clips will do
  const std::string rlo = "\xE2\x80\xAE";                 // U+202E
  const auto expect_refused = [](const grpc::Status& status, const std::string& message) {
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << message;
    EXPECT_THAT(status.error_message(), HasSubstr(message));
  };

  v1::IngestClipRequest ingest;
  ingest.set_file_name("other.bvh");
  ingest.set_bvh(BvhText(ChainClip(0.05)));
  ingest.set_name("take" + rlo + "4pm.exe");
  v1::IngestClipResponse ingested;
  expect_refused(client.clips().IngestClip(client.Context().get(), ingest, &ingested),
                 "clip name 'take\\u202E4pm.exe' holds the bidirectional control U+202E at byte 4");
  ingest.clear_name();
  ingest.add_tags(
      "a\xE2\x80\xA8"
      "b");
  expect_refused(client.clips().IngestClip(client.Context().get(), ingest, &ingested),
                 "tags[0] 'a\\u2028b' holds the line separator U+2028 at byte 1");

  v1::UpdateClipRequest rename;
  rename.set_clip_id(clip);
  rename.set_name("walk\xE2\x81\xA6");
  v1::Clip updated;
  expect_refused(client.clips().UpdateClip(client.Context().get(), rename, &updated),
                 "holds the bidirectional control U+2066");

  v1::AddLabelsRequest add;
  v1::NewLabel* label = add.add_labels();
  label->set_clip_id(clip);
  label->set_descriptor_name("kick\xE2\x80\x8F");
  v1::AddLabelsResponse added;
  expect_refused(client.labels().AddLabels(client.Context().get(), add, &added),
                 "labels[0].descriptor 'kick\\u200F' holds the bidirectional control U+200F");

  v1::CreateSpaceRequest create_space;
  create_space.set_name("arms\xE2\x80\xA9");
  v1::Space space;
  expect_refused(client.CreateSpace(create_space, &space),
                 "name: 'arms\\u2029' may only contain letters, digits");

  v1::StartPropagationRequest propagate;
  propagate.set_space("body");
  propagate.add_descriptor_names(rlo + "kick");
  v1::Job job;
  expect_refused(client.jobs().StartPropagation(client.Context().get(), propagate, &job),
                 "descriptors[0]");

  v1::CreatePoseModelRequest model;
  model.set_name("pose" + rlo);
  model.set_space("body");
  model.set_components(1);
  v1::ClipRange* example = model.add_examples();
  example->set_clip_id(clip);
  example->set_first_frame(0);
  example->set_last_frame(30);
  v1::PoseModel fitted;
  expect_refused(v1::EditService::NewStub(client.channel())
                     ->CreatePoseModel(client.Context().get(), model, &fitted),
                 "holds the bidirectional control U+202E");

  // Nothing of it was stored.
  v1::ListClipsResponse clips;
  ASSERT_TRUE(client.clips().ListClips(client.Context().get(), {}, &clips).ok());
  ASSERT_EQ(clips.clips_size(), 1);
  EXPECT_EQ(clips.clips(0).name(), "chain");
  v1::ListLabelsResponse labels;
  ASSERT_TRUE(client.labels().ListLabels(client.Context().get(), {}, &labels).ok());
  EXPECT_EQ(labels.labels_size(), 0);
  v1::ListSpacesResponse spaces;
  ASSERT_TRUE(client.spaces().ListSpaces(client.Context().get(), {}, &spaces).ok());
  EXPECT_EQ(spaces.spaces_size(), 1);
}

// `bytes` with every `from` replaced by `to` (of the same length, so that lengths written
// before them still hold).
std::string Replaced(std::string bytes, const std::string& from, const std::string& to) {
  EXPECT_EQ(from.size(), to.size());
  EXPECT_NE(bytes.find(from), std::string::npos);
  return absl::StrReplaceAll(bytes, {{from, to}});
}

// Rewrites `column` of every row of `table` (its key `key`) through Replaced, with SQLite alone,
// as an older version would have written it.
void RewriteColumn(sqlite3* db, const std::string& table, const std::string& key,
                   const std::string& column, const std::string& from, const std::string& to) {
  sqlite3_stmt* select = nullptr;
  ASSERT_EQ(sqlite3_prepare_v2(db, ("SELECT " + key + ", " + column + " FROM " + table).c_str(), -1,
                               &select, nullptr),
            SQLITE_OK);
  std::vector<std::pair<int64_t, std::string>> rows;
  while (sqlite3_step(select) == SQLITE_ROW) {
    const auto* bytes = static_cast<const char*>(sqlite3_column_blob(select, 1));
    rows.emplace_back(sqlite3_column_int64(select, 0),
                      std::string(bytes, sqlite3_column_bytes(select, 1)));
  }
  sqlite3_finalize(select);
  ASSERT_FALSE(rows.empty());
  const bool blob = column == "layout";
  for (const auto& [id, bytes] : rows) {
    const std::string rewritten = Replaced(bytes, from, to);
    sqlite3_stmt* update = nullptr;
    ASSERT_EQ(sqlite3_prepare_v2(
                  db, ("UPDATE " + table + " SET " + column + " = ? WHERE " + key + " = ?").c_str(),
                  -1, &update, nullptr),
              SQLITE_OK);
    if (blob) {
      sqlite3_bind_blob(update, 1, rewritten.data(), static_cast<int>(rewritten.size()),
                        SQLITE_TRANSIENT);
    } else {
      sqlite3_bind_text(update, 1, rewritten.data(), static_cast<int>(rewritten.size()),
                        SQLITE_TRANSIENT);
    }
    sqlite3_bind_int64(update, 2, id);
    EXPECT_EQ(sqlite3_step(update), SQLITE_DONE) << sqlite3_errmsg(db);
    sqlite3_finalize(update);
  }
}

// A database an older version filled: a clip whose root joint's name ends in a byte that is not
// UTF-8 (written here with SQLite, since the server now refuses it). Every listing answers, the
// name shown with U+FFFD; gRPC and HTTP alike.
TEST_F(TextEntryTest, JointNamesAnOlderVersionStoredAsInvalidUtf8AreAnsweredReplaced) {
  testing::ServerProcess* server = StartServer();
  ASSERT_NE(server, nullptr);
  int64_t clip = 0;
  {
    Client client(testing::InsecureChannel(server->address()));
    clip = client.IngestOrFail("take.bvh", TwoJointBvh("Hipsx", "Spine"));
  }
  ASSERT_EQ(server->Stop(SIGTERM), 0);
  servers_.clear();
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(db_.c_str(), &db), SQLITE_OK);
  RewriteColumn(db, "clips", "clip_id", "layout", "Hipsx", "Hips\xFF");
  RewriteColumn(db, "skeletons", "skeleton_id", "joint_names", "Hipsx", "Hips\xFF");
  RewriteColumn(db, "skeletons", "skeleton_id", "topology_key", "Hipsx", "Hips\xFF");
  sqlite3_close(db);

  server = StartServer();
  ASSERT_NE(server, nullptr);
  Client client(testing::InsecureChannel(server->address()));
  const std::string shown = std::string("Hips") + kReplacement;
  v1::ListSkeletonsResponse skeletons;
  grpc::Status status = client.clips().ListSkeletons(client.Context().get(), {}, &skeletons);
  ASSERT_TRUE(status.ok()) << status.error_message();
  ASSERT_EQ(skeletons.skeletons_size(), 1);
  EXPECT_EQ(skeletons.skeletons(0).root_joint(), shown);
  EXPECT_THAT(skeletons.skeletons(0).name(), HasSubstr(shown));
  v1::GetClipRequest get;
  get.set_clip_id(clip);
  v1::Clip shown_clip;
  status = client.clips().GetClip(client.Context().get(), get, &shown_clip);
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_THAT(shown_clip.joint_names(), ::testing::ElementsAre(shown, "Spine"));
  v1::GetClipPosesRequest poses;
  poses.mutable_clip()->set_clip_id(clip);
  v1::ClipPoses posed;
  status = client.clips().GetClipPoses(client.Context().get(), poses, &posed);
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_THAT(posed.joint_names(), ::testing::ElementsAre(shown, "Spine"));
  v1::ListClipsResponse clips;
  ASSERT_TRUE(client.clips().ListClips(client.Context().get(), {}, &clips).ok());
  EXPECT_EQ(clips.clips_size(), 1);

  httplib::Client http("127.0.0.1", server->http_port());
  for (const std::string& path :
       std::vector<std::string>{"/v1/skeletons", absl::StrCat("/v1/clips/", clip),
                                absl::StrCat("/v1/clips/", clip, "/poses")}) {
    const httplib::Result answer = http.Get(path.c_str());
    ASSERT_TRUE(answer) << path;
    EXPECT_EQ(answer->status, 200) << path;
    EXPECT_THAT(answer->body, HasSubstr(shown)) << path;
  }
}

}  // namespace
}  // namespace motiondb
