#include "server/http/json_answer.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>

#include "absl/strings/escaping.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/string_view.h"

namespace motiondb::server {
namespace {

using google::protobuf::FieldDescriptor;
using google::protobuf::Message;
using google::protobuf::Reflection;

// Bytes are encoded this many at a time, so that no second copy of a large field is made.
constexpr size_t kBase64PieceBytes = 3 * (size_t{1} << 16);

// The length of the well-formed UTF-8 sequence at the start of `text`, or 0 (RFC 3629: no
// overlong forms, surrogates or code points past U+10FFFF).
size_t Utf8Length(absl::string_view text) {
  const auto byte = [&text](size_t i) { return static_cast<unsigned char>(text[i]); };
  const unsigned char lead = byte(0);
  size_t length = 0;
  unsigned char low = 0x80, high = 0xBF;  // the second byte's range
  if (lead >= 0xC2 && lead <= 0xDF) {
    length = 2;
  } else if (lead >= 0xE0 && lead <= 0xEF) {
    length = 3;
    if (lead == 0xE0) low = 0xA0;
    if (lead == 0xED) high = 0x9F;
  } else if (lead >= 0xF0 && lead <= 0xF4) {
    length = 4;
    if (lead == 0xF0) low = 0x90;
    if (lead == 0xF4) high = 0x8F;
  } else {
    return 0;
  }
  if (text.size() < length || byte(1) < low || byte(1) > high) return 0;
  for (size_t i = 2; i < length; ++i) {
    if (byte(i) < 0x80 || byte(i) > 0xBF) return 0;
  }
  return length;
}

class JsonWriter {
 public:
  explicit JsonWriter(size_t max_bytes) : max_bytes_(max_bytes) {}

  // False once the text passed the limit (it then stops short).
  bool WriteMessage(const Message& message) {
    const Reflection& reflection = *message.GetReflection();
    const google::protobuf::Descriptor& type = *message.GetDescriptor();
    out_ += '{';
    bool first = true;
    for (int i = 0; i < type.field_count(); ++i) {
      const FieldDescriptor& field = *type.field(i);
      // Lists, maps and plain scalars always; messages, oneofs and optional scalars when set.
      if (!field.is_repeated() && field.has_presence() && !reflection.HasField(message, &field)) {
        continue;
      }
      if (!first) out_ += ',';
      first = false;
      WriteString(field.name());
      out_ += ':';
      if (!WriteField(message, field)) return false;
    }
    out_ += '}';
    return !Full();
  }

  std::string& text() { return out_; }

 private:
  bool Full() const { return over_ || out_.size() > max_bytes_; }

  bool WriteField(const Message& message, const FieldDescriptor& field) {
    if (!field.is_repeated()) return WriteValue(message, field, -1);
    const int count = message.GetReflection()->FieldSize(message, &field);
    out_ += field.is_map() ? '{' : '[';
    for (int i = 0; i < count; ++i) {
      if (i > 0) out_ += ',';
      if (!(field.is_map() ? WriteMapEntry(message, field, i) : WriteValue(message, field, i))) {
        return false;
      }
    }
    out_ += field.is_map() ? '}' : ']';
    return !Full();
  }

  // A map entry as "key":value, the key as text whatever its type.
  bool WriteMapEntry(const Message& message, const FieldDescriptor& field, int index) {
    const Message& entry = message.GetReflection()->GetRepeatedMessage(message, &field, index);
    const FieldDescriptor& key = *field.message_type()->map_key();
    const Reflection& r = *entry.GetReflection();
    switch (key.cpp_type()) {
      case FieldDescriptor::CPPTYPE_INT32:
        WriteString(absl::StrCat(r.GetInt32(entry, &key)));
        break;
      case FieldDescriptor::CPPTYPE_UINT32:
        WriteString(absl::StrCat(r.GetUInt32(entry, &key)));
        break;
      case FieldDescriptor::CPPTYPE_INT64:
        WriteString(absl::StrCat(r.GetInt64(entry, &key)));
        break;
      case FieldDescriptor::CPPTYPE_UINT64:
        WriteString(absl::StrCat(r.GetUInt64(entry, &key)));
        break;
      case FieldDescriptor::CPPTYPE_BOOL:
        WriteString(r.GetBool(entry, &key) ? "true" : "false");
        break;
      default:  // a string: no other type keys a map
        WriteString(r.GetString(entry, &key));
    }
    out_ += ':';
    return WriteValue(entry, *field.message_type()->map_value(), -1);
  }

  // The field's value, or its element `index` of a list (-1: a singular field).
  bool WriteValue(const Message& message, const FieldDescriptor& field, int index) {
    const Reflection& r = *message.GetReflection();
    const bool one = index < 0;
    switch (field.cpp_type()) {
      case FieldDescriptor::CPPTYPE_INT32:
        absl::StrAppend(
            &out_, one ? r.GetInt32(message, &field) : r.GetRepeatedInt32(message, &field, index));
        break;
      case FieldDescriptor::CPPTYPE_UINT32:
        absl::StrAppend(&out_, one ? r.GetUInt32(message, &field)
                                   : r.GetRepeatedUInt32(message, &field, index));
        break;
      case FieldDescriptor::CPPTYPE_INT64:
        absl::StrAppend(
            &out_, "\"",
            one ? r.GetInt64(message, &field) : r.GetRepeatedInt64(message, &field, index), "\"");
        break;
      case FieldDescriptor::CPPTYPE_UINT64:
        absl::StrAppend(
            &out_, "\"",
            one ? r.GetUInt64(message, &field) : r.GetRepeatedUInt64(message, &field, index), "\"");
        break;
      case FieldDescriptor::CPPTYPE_DOUBLE:
        WriteNumber(one ? r.GetDouble(message, &field)
                        : r.GetRepeatedDouble(message, &field, index));
        break;
      case FieldDescriptor::CPPTYPE_FLOAT:
        WriteNumber(one ? r.GetFloat(message, &field) : r.GetRepeatedFloat(message, &field, index));
        break;
      case FieldDescriptor::CPPTYPE_BOOL:
        out_ += (one ? r.GetBool(message, &field) : r.GetRepeatedBool(message, &field, index))
                    ? "true"
                    : "false";
        break;
      case FieldDescriptor::CPPTYPE_ENUM: {
        const int number =
            one ? r.GetEnumValue(message, &field) : r.GetRepeatedEnumValue(message, &field, index);
        const auto* value = field.enum_type()->FindValueByNumber(number);
        if (value != nullptr) {
          WriteString(value->name());
        } else {
          absl::StrAppend(&out_, number);
        }
        break;
      }
      case FieldDescriptor::CPPTYPE_STRING: {
        std::string scratch;
        const std::string& text =
            one ? r.GetStringReference(message, &field, &scratch)
                : r.GetRepeatedStringReference(message, &field, index, &scratch);
        if (field.type() == FieldDescriptor::TYPE_BYTES) return WriteBase64(text);
        WriteString(text);
        break;
      }
      case FieldDescriptor::CPPTYPE_MESSAGE:
        return WriteMessage(one ? r.GetMessage(message, &field)
                                : r.GetRepeatedMessage(message, &field, index));
    }
    return !Full();
  }

  // The shortest text that reads back as `value`; NaN and the infinities as proto3 JSON names
  // them.
  template <typename Float>
  void WriteNumber(Float value) {
    if (std::isnan(value)) {
      out_ += "\"NaN\"";
    } else if (std::isinf(value)) {
      out_ += value > 0 ? "\"Infinity\"" : "\"-Infinity\"";
    } else {
      char buffer[32];
      out_.append(buffer, std::to_chars(buffer, buffer + sizeof(buffer), value).ptr);
    }
  }

  bool WriteBase64(absl::string_view bytes) {
    // Refused before it is encoded when it cannot fit.
    if (out_.size() + (bytes.size() + 2) / 3 * 4 + 2 > max_bytes_) {
      over_ = true;
      return false;
    }
    out_ += '"';
    std::string piece;
    for (size_t at = 0; at < bytes.size(); at += kBase64PieceBytes) {
      absl::Base64Escape(bytes.substr(at, kBase64PieceBytes), &piece);
      out_ += piece;
    }
    out_ += '"';
    return true;
  }

  // A JSON string: quotes, backslashes and control characters escaped, and as protobuf does
  // '<', '>', DEL and the line and paragraph separators (for pages that inline JSON); bytes that
  // are not UTF-8 as U+FFFD.
  void WriteString(absl::string_view text) {
    out_ += '"';
    size_t i = 0;
    while (i < text.size()) {
      const unsigned char c = static_cast<unsigned char>(text[i]);
      if (c >= 0x80) {
        const size_t length = Utf8Length(text.substr(i));
        const absl::string_view sequence = text.substr(i, length);
        if (length == 0) {
          out_ += "\\ufffd";
        } else if (sequence == "\xE2\x80\xA8" || sequence == "\xE2\x80\xA9") {
          out_ += sequence.back() == '\xA8' ? "\\u2028" : "\\u2029";
        } else {
          out_.append(sequence.data(), sequence.size());
        }
        i += std::max<size_t>(length, 1);
        continue;
      }
      switch (c) {
        case '"':
          out_ += "\\\"";
          break;
        case '\\':
          out_ += "\\\\";
          break;
        case '\n':
          out_ += "\\n";
          break;
        case '\r':
          out_ += "\\r";
          break;
        case '\t':
          out_ += "\\t";
          break;
        default:
          if (c < 0x20 || c == 0x7F || c == '<' || c == '>') {
            absl::StrAppend(&out_, "\\u00", absl::Hex(c, absl::kZeroPad2));
          } else {
            out_ += static_cast<char>(c);
          }
      }
      ++i;
    }
    out_ += '"';
  }

  const size_t max_bytes_;
  std::string out_;
  bool over_ = false;  // a value was refused before it was written
};

}  // namespace

absl::StatusOr<std::string> AnswerJson(const Message& message, size_t max_bytes) {
  JsonWriter writer(max_bytes);
  if (!writer.WriteMessage(message)) {
    return absl::ResourceExhaustedError(
        absl::StrCat("the answer's JSON is longer than ", max_bytes, " bytes"));
  }
  return std::move(writer.text());
}

}  // namespace motiondb::server
