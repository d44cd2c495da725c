// The HTTP face's bounded JSON writer (server/http/json_answer.h) against protobuf's own printer:
// for every message of the API, filled at random (defaults, optional and nested fields left
// unset or set, lists, maps, every scalar type, text that needs escaping, NaN and infinities),
// the same JSON (the same objects, keys and value types at every level, both texts reading back
// to one message), and refused exactly when the text would pass the limit.
#include <cmath>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <google/protobuf/descriptor.h>
#include <google/protobuf/dynamic_message.h>
#include <google/protobuf/util/field_comparator.h>
#include <google/protobuf/util/json_util.h>
#include <google/protobuf/util/message_differencer.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "absl/strings/str_cat.h"
#include "motiondb/v1/clip_service.pb.h"
#include "motiondb/v1/edit_service.pb.h"
#include "motiondb/v1/job_service.pb.h"
#include "motiondb/v1/label_service.pb.h"
#include "motiondb/v1/search_service.pb.h"
#include "motiondb/v1/server_service.pb.h"
#include "motiondb/v1/space_service.pb.h"
#include "server/http/json_answer.h"

namespace motiondb::server {
namespace {

using google::protobuf::Descriptor;
using google::protobuf::FieldDescriptor;
using google::protobuf::Message;

// Text that needs escaping, in UTF-8 of every length.
const std::vector<std::string> kTexts = {"",
                                         "walk",
                                         "a \"quoted\" back\\slash",
                                         "tab\there\nnew line\r\x01\x1f\x7f",
                                         "<script>&amp;</script>",
                                         "caf\xC3\xA9 \xE2\x80\xA8 \xE2\x80\xA9 \xE2\x82\xAC",
                                         "\xF0\x9F\x8E\xAC take",
                                         "session1/take_001"};
const std::vector<double> kDoubles = {0.0,
                                      -0.0,
                                      0.1,
                                      1.0 / 3,
                                      -1.5e-7,
                                      1e300,
                                      -123456789.125,
                                      std::numeric_limits<double>::denorm_min(),
                                      std::numeric_limits<double>::quiet_NaN(),
                                      std::numeric_limits<double>::infinity(),
                                      -std::numeric_limits<double>::infinity()};

class Filler {
 public:
  explicit Filler(unsigned seed) : random_(seed) {}

  void Fill(Message* message, int depth) {
    const Descriptor& type = *message->GetDescriptor();
    for (int i = 0; i < type.field_count(); ++i) {
      const FieldDescriptor& field = *type.field(i);
      if (Pick(3) == 0) continue;  // left at its default, or unset
      if (field.cpp_type() == FieldDescriptor::CPPTYPE_MESSAGE && depth >= 3) continue;
      if (!field.is_repeated()) {
        Set(message, field, depth);
        continue;
      }
      // A map's keys may repeat at random; one entry keeps it a map.
      const int count = field.is_map() ? Pick(2) : Pick(4);
      for (int k = 0; k < count; ++k) Set(message, field, depth);
    }
  }

 private:
  int Pick(int n) { return std::uniform_int_distribution<int>(0, n - 1)(random_); }
  template <typename T>
  T Any() {
    return std::uniform_int_distribution<T>(std::numeric_limits<T>::min(),
                                            std::numeric_limits<T>::max())(random_);
  }

  // Sets a singular field, or adds an element to a repeated one (a map's entry too).
  void Set(Message* message, const FieldDescriptor& field, int depth) {
    const google::protobuf::Reflection& r = *message->GetReflection();
    const bool add = field.is_repeated();
    switch (field.cpp_type()) {
      case FieldDescriptor::CPPTYPE_INT32:
        add ? r.AddInt32(message, &field, Any<int32_t>())
            : r.SetInt32(message, &field, Any<int32_t>());
        break;
      case FieldDescriptor::CPPTYPE_INT64:
        add ? r.AddInt64(message, &field, Any<int64_t>())
            : r.SetInt64(message, &field, Any<int64_t>());
        break;
      case FieldDescriptor::CPPTYPE_UINT32:
        add ? r.AddUInt32(message, &field, Any<uint32_t>())
            : r.SetUInt32(message, &field, Any<uint32_t>());
        break;
      case FieldDescriptor::CPPTYPE_UINT64:
        add ? r.AddUInt64(message, &field, Any<uint64_t>())
            : r.SetUInt64(message, &field, Any<uint64_t>());
        break;
      case FieldDescriptor::CPPTYPE_DOUBLE: {
        const double value = kDoubles[Pick(static_cast<int>(kDoubles.size()))];
        add ? r.AddDouble(message, &field, value) : r.SetDouble(message, &field, value);
        break;
      }
      case FieldDescriptor::CPPTYPE_FLOAT: {
        const float value = static_cast<float>(kDoubles[Pick(static_cast<int>(kDoubles.size()))]);
        add ? r.AddFloat(message, &field, value) : r.SetFloat(message, &field, value);
        break;
      }
      case FieldDescriptor::CPPTYPE_BOOL:
        add ? r.AddBool(message, &field, Pick(2) == 1) : r.SetBool(message, &field, Pick(2) == 1);
        break;
      case FieldDescriptor::CPPTYPE_ENUM: {
        const auto* value = field.enum_type()->value(Pick(field.enum_type()->value_count()));
        add ? r.AddEnum(message, &field, value) : r.SetEnum(message, &field, value);
        break;
      }
      case FieldDescriptor::CPPTYPE_STRING: {
        std::string value;
        if (field.type() == FieldDescriptor::TYPE_BYTES) {
          for (int n = Pick(300); n > 0; --n) value += static_cast<char>(Pick(256));
        } else {
          value = kTexts[Pick(static_cast<int>(kTexts.size()))];
        }
        add ? r.AddString(message, &field, value) : r.SetString(message, &field, value);
        break;
      }
      case FieldDescriptor::CPPTYPE_MESSAGE:
        Fill(add ? r.AddMessage(message, &field) : r.MutableMessage(message, &field), depth + 1);
        break;
    }
  }

  std::mt19937 random_;
};

std::string ProtobufJson(const Message& message) {
  google::protobuf::util::JsonPrintOptions options;
  options.preserve_proto_field_names = true;
  options.always_print_primitive_fields = true;
  std::string json;
  EXPECT_TRUE(google::protobuf::util::MessageToJsonString(message, &json, options).ok());
  return json;
}

// The same objects, keys, list lengths and value types at every level; int64s (strings) and
// texts equal. Numbers may be spelt differently (both read back as the message's).
void ExpectSameShape(const nlohmann::json& ours, const nlohmann::json& theirs,
                     const std::string& path) {
  ASSERT_EQ(ours.type(), theirs.type()) << path;
  if (ours.is_object()) {
    ASSERT_EQ(ours.size(), theirs.size()) << path << ": " << ours.dump() << " vs " << theirs.dump();
    for (const auto& [key, value] : theirs.items()) {
      ASSERT_TRUE(ours.contains(key)) << path << "." << key;
      ExpectSameShape(ours.at(key), value, path + "." + key);
    }
  } else if (ours.is_array()) {
    ASSERT_EQ(ours.size(), theirs.size()) << path;
    for (size_t i = 0; i < ours.size(); ++i) {
      ExpectSameShape(ours[i], theirs[i], path + "[" + std::to_string(i) + "]");
    }
  } else if (ours.is_string()) {
    EXPECT_EQ(ours, theirs) << path;
  }
}

std::vector<const Descriptor*> ApiMessages() {
  std::vector<const Descriptor*> types;
  const google::protobuf::FileDescriptor* files[] = {v1::ClipPoses::descriptor()->file(),
                                                     v1::Space::descriptor()->file(),
                                                     v1::SearchResponse::descriptor()->file(),
                                                     v1::Label::descriptor()->file(),
                                                     v1::Job::descriptor()->file(),
                                                     v1::ServerInfo::descriptor()->file(),
                                                     v1::BlendResponse::descriptor()->file()};
  for (const auto* file : files) {
    for (int i = 0; i < file->message_type_count(); ++i) types.push_back(file->message_type(i));
  }
  return types;
}

TEST(AnswerJson, IsProtobufsJsonForEveryMessageOfTheApi) {
  google::protobuf::DynamicMessageFactory factory;
  Filler filler(37);
  google::protobuf::util::DefaultFieldComparator comparator;
  comparator.set_treat_nan_as_equal(true);
  int compared = 0;
  for (const Descriptor* type : ApiMessages()) {
    for (int round = 0; round < 20; ++round) {
      std::unique_ptr<Message> message(factory.GetPrototype(type)->New());
      if (round > 0) filler.Fill(message.get(), 0);
      const absl::StatusOr<std::string> ours = AnswerJson(*message, 1 << 30);
      ASSERT_TRUE(ours.ok()) << ours.status();
      const std::string theirs = ProtobufJson(*message);
      ASSERT_NO_FATAL_FAILURE(ExpectSameShape(nlohmann::json::parse(*ours),
                                              nlohmann::json::parse(theirs), type->name()))
          << *ours << "\n"
          << theirs;
      // Both read back to one message (the message itself, but for -0.0, which protobuf's
      // parser reads as 0).
      std::unique_ptr<Message> read(message->New()), expected(message->New());
      ASSERT_TRUE(google::protobuf::util::JsonStringToMessage(*ours, read.get()).ok()) << *ours;
      ASSERT_TRUE(google::protobuf::util::JsonStringToMessage(theirs, expected.get()).ok());
      google::protobuf::util::MessageDifferencer differencer;
      differencer.set_field_comparator(&comparator);
      std::string differences;
      differencer.ReportDifferencesToString(&differences);
      EXPECT_TRUE(differencer.Compare(*expected, *read)) << type->name() << ": " << differences;
      ++compared;
    }
  }
  EXPECT_GT(compared, 1000);
}

TEST(AnswerJson, IsRefusedExactlyPastTheLimit) {
  google::protobuf::DynamicMessageFactory factory;
  Filler filler(11);
  for (const Descriptor* type : {v1::SearchResponse::descriptor(), v1::ClipPoses::descriptor(),
                                 v1::GetClipLabelsResponse::descriptor()}) {
    for (int round = 0; round < 10; ++round) {
      std::unique_ptr<Message> message(factory.GetPrototype(type)->New());
      filler.Fill(message.get(), 0);
      const absl::StatusOr<std::string> whole = AnswerJson(*message, 1 << 30);
      ASSERT_TRUE(whole.ok());
      EXPECT_TRUE(AnswerJson(*message, whole->size()).ok());
      const absl::StatusOr<std::string> cut = AnswerJson(*message, whole->size() - 1);
      EXPECT_EQ(cut.status().code(), absl::StatusCode::kResourceExhausted);
      EXPECT_EQ(cut.status().message(),
                absl::StrCat("the answer's JSON is longer than ", whole->size() - 1, " bytes"));
    }
  }
}

TEST(AnswerJson, WritesTextThatIsNotUtf8AsReplacementCharacters) {
  v1::Clip clip;
  clip.add_joint_names(
      std::string("ab\xFF"
                  "c\xC3",
                  5));                   // a stray byte, a cut sequence
  clip.add_joint_names("\xED\xA0\x80");  // a surrogate
  clip.add_joint_names("\xE0\x80\xAF");  // an overlong '/'
  const absl::StatusOr<std::string> json = AnswerJson(clip, 1 << 20);
  ASSERT_TRUE(json.ok());
  const nlohmann::json parsed = nlohmann::json::parse(*json);
  EXPECT_EQ(parsed["joint_names"][0],
            "ab\xEF\xBF\xBD"
            "c\xEF\xBF\xBD");
  EXPECT_EQ(parsed["joint_names"][1], "\xEF\xBF\xBD\xEF\xBF\xBD\xEF\xBF\xBD");
  EXPECT_EQ(parsed["joint_names"][2], "\xEF\xBF\xBD\xEF\xBF\xBD\xEF\xBF\xBD");
}

}  // namespace
}  // namespace motiondb::server
