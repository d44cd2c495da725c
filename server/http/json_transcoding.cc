#include "server/http/json_transcoding.h"

#include <google/protobuf/stubs/common.h>
#include <google/protobuf/util/json_util.h>

#include <nlohmann/json.hpp>
#include "absl/strings/ascii.h"
#include "absl/strings/escaping.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"

namespace motiondb::server {
namespace {

using google::protobuf::FieldDescriptor;
using google::protobuf::Message;

const FieldDescriptor* FindField(const google::protobuf::Descriptor& type, absl::string_view name) {
  if (const FieldDescriptor* field = type.FindFieldByName(std::string(name))) return field;
  if (const FieldDescriptor* field = type.FindFieldByCamelcaseName(std::string(name))) {
    return field;
  }
  for (int i = 0; i < type.field_count(); ++i) {
    if (type.field(i)->json_name() == name) return type.field(i);
  }
  return nullptr;
}

bool ParseBool(absl::string_view text, bool* value) {
  if (text == "true" || text == "1") return *value = true, true;
  if (text == "false" || text == "0") return *value = false, true;
  return false;
}

// Parses `text` with `parse` and sets the field to it, or adds it to a repeated field.
template <typename T, typename Parse, typename Set, typename Add>
bool Store(absl::string_view text, Parse parse, Set set, Add add, const FieldDescriptor& field,
           Message* message) {
  T value{};
  if (!parse(text, &value)) return false;
  const google::protobuf::Reflection* reflection = message->GetReflection();
  if (field.is_repeated()) {
    (reflection->*add)(message, &field, std::move(value));
  } else {
    (reflection->*set)(message, &field, std::move(value));
  }
  return true;
}

bool ParseBytes(absl::string_view text, std::string* value) {
  return absl::Base64Unescape(text, value) || absl::WebSafeBase64Unescape(text, value);
}

bool ParseString(absl::string_view text, std::string* value) {
  *value = std::string(text);
  return true;
}

// Sets or adds one value of a scalar field; false when `text` is not of its type.
bool SetScalar(const FieldDescriptor& field, absl::string_view text, Message* message) {
  using R = google::protobuf::Reflection;
  switch (field.cpp_type()) {
    case FieldDescriptor::CPPTYPE_INT32:
      return Store<int32_t>(text, absl::SimpleAtoi<int32_t>, &R::SetInt32, &R::AddInt32, field,
                            message);
    case FieldDescriptor::CPPTYPE_INT64:
      return Store<int64_t>(text, absl::SimpleAtoi<int64_t>, &R::SetInt64, &R::AddInt64, field,
                            message);
    case FieldDescriptor::CPPTYPE_UINT32:
      return Store<uint32_t>(text, absl::SimpleAtoi<uint32_t>, &R::SetUInt32, &R::AddUInt32, field,
                             message);
    case FieldDescriptor::CPPTYPE_UINT64:
      return Store<uint64_t>(text, absl::SimpleAtoi<uint64_t>, &R::SetUInt64, &R::AddUInt64, field,
                             message);
    case FieldDescriptor::CPPTYPE_DOUBLE:
      return Store<double>(text, absl::SimpleAtod, &R::SetDouble, &R::AddDouble, field, message);
    case FieldDescriptor::CPPTYPE_FLOAT:
      return Store<float>(text, absl::SimpleAtof, &R::SetFloat, &R::AddFloat, field, message);
    case FieldDescriptor::CPPTYPE_BOOL:
      return Store<bool>(text, ParseBool, &R::SetBool, &R::AddBool, field, message);
    case FieldDescriptor::CPPTYPE_ENUM: {
      // By name, as JSON gives enums, or by number.
      const auto parse = [&field](absl::string_view name, int* number) {
        if (const auto* value = field.enum_type()->FindValueByName(std::string(name))) {
          *number = value->number();
          return true;
        }
        return absl::SimpleAtoi(name, number) &&
               field.enum_type()->FindValueByNumber(*number) != nullptr;
      };
      return Store<int>(text, parse, &R::SetEnumValue, &R::AddEnumValue, field, message);
    }
    case FieldDescriptor::CPPTYPE_STRING:
      return Store<std::string>(
          text, field.type() == FieldDescriptor::TYPE_BYTES ? ParseBytes : ParseString,
          &R::SetString, &R::AddString, field, message);
    case FieldDescriptor::CPPTYPE_MESSAGE:
      return false;
  }
  return false;
}

}  // namespace

absl::Status MergeJson(absl::string_view json, Message* message) {
  if (absl::StripAsciiWhitespace(json).empty()) return absl::OkStatus();
  google::protobuf::util::JsonParseOptions options;
  options.ignore_unknown_fields = false;  // a misspelt field is an error, not a default
  std::unique_ptr<Message> parsed(message->New());
  const auto status = google::protobuf::util::JsonStringToMessage(
      google::protobuf::StringPiece(json.data(), json.size()), parsed.get(), options);
  if (!status.ok()) {
    return absl::InvalidArgumentError(absl::StrCat("request body: ", status.message().ToString()));
  }
  message->MergeFrom(*parsed);
  return absl::OkStatus();
}

absl::Status SetField(absl::string_view path, absl::string_view text, Message* message) {
  const std::vector<absl::string_view> names = absl::StrSplit(path, '.');
  Message* owner = message;
  for (size_t i = 0; i < names.size(); ++i) {
    const FieldDescriptor* field = FindField(*owner->GetDescriptor(), names[i]);
    if (field == nullptr) {
      return absl::InvalidArgumentError(absl::StrCat("parameter '", path,
                                                     "': ", owner->GetDescriptor()->full_name(),
                                                     " has no field '", names[i], "'"));
    }
    const bool last = i + 1 == names.size();
    if (field->cpp_type() == FieldDescriptor::CPPTYPE_MESSAGE) {
      if (last || field->is_repeated()) {
        return absl::InvalidArgumentError(absl::StrCat(
            "parameter '", path, "': a query parameter names one value, and '", names[i],
            "' is a message", field->is_repeated() ? " list" : "", "; send it in a JSON body"));
      }
      owner = owner->GetReflection()->MutableMessage(owner, field);
      continue;
    }
    if (!last) {
      return absl::InvalidArgumentError(
          absl::StrCat("parameter '", path, "': '", names[i], "' has no fields"));
    }
    // A protobuf string holds UTF-8, and the services' side refuses a request with anything
    // else as a whole (INTERNAL, no message); a percent-encoded path or query can carry any byte.
    if (field->type() == FieldDescriptor::TYPE_STRING &&
        !google::protobuf::internal::IsStructurallyValidUTF8(text.data(),
                                                             static_cast<int>(text.size()))) {
      return absl::InvalidArgumentError(
          absl::StrCat("parameter '", path, "': not UTF-8 text (percent-encode UTF-8 bytes)"));
    }
    if (!SetScalar(*field, text, owner)) {
      return absl::InvalidArgumentError(absl::StrCat("parameter '", path, "': '",
                                                     text.substr(0, 64), "' is not a valid ",
                                                     field->type_name(), " value"));
    }
  }
  return absl::OkStatus();
}

std::string FieldName(absl::string_view path, const google::protobuf::Descriptor& type) {
  std::string name;
  const google::protobuf::Descriptor* owner = &type;
  for (const absl::string_view part : absl::StrSplit(path, '.')) {
    const FieldDescriptor* field = owner == nullptr ? nullptr : FindField(*owner, part);
    if (field == nullptr) return "";
    absl::StrAppend(&name, name.empty() ? "" : ".", field->name());
    owner = field->message_type();
  }
  return name;
}

std::string ErrorJson(grpc::StatusCode code, absl::string_view message) {
  const nlohmann::json error = {{"code", static_cast<int>(code)}, {"message", message}};
  // A message may quote what a client sent (a parameter's name, a value, a path), which need
  // not be UTF-8: such bytes become U+FFFD, so that the body stays JSON.
  return error.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

}  // namespace motiondb::server
