// The server's labels, through the real binary and the generated stubs (server_fixture.h): added,
// listed, found, timelined and deleted; bad labels refused; seconds ranges; the JSON names.
#include <gmock/gmock.h>
#include <google/protobuf/util/json_util.h>
#include <gtest/gtest.h>

#include "absl/strings/str_cat.h"
#include "testing/server_process.h"
#include "tests/server_fixture.h"

namespace motiondb {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;
using testing::ServerProcess;

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

}  // namespace
}  // namespace motiondb
