#include "util/byte_coding.h"

#include "absl/strings/str_cat.h"
#include "util/status_macros.h"

namespace motiondb {

void AppendFloat32s(const float* values, size_t count, std::string* out) {
  if constexpr (std::endian::native == std::endian::little) {
    out->append(reinterpret_cast<const char*>(values), count * sizeof(float));
  } else {
    ByteWriter writer;
    for (size_t i = 0; i < count; ++i) writer.F32(values[i]);
    out->append(writer.bytes());
  }
}

void ReadFloat32s(absl::string_view bytes, size_t count, float* values) {
  if constexpr (std::endian::native == std::endian::little) {
    if (count > 0) std::memcpy(values, bytes.data(), count * sizeof(float));
  } else {
    for (size_t i = 0; i < count; ++i) {
      uint32_t bits = 0;
      for (int b = 0; b < 4; ++b) {
        bits |= uint32_t{static_cast<uint8_t>(bytes[4 * i + b])} << (8 * b);
      }
      values[i] = std::bit_cast<float>(bits);
    }
  }
}

void ByteWriter::Str(absl::string_view text) {
  U32(static_cast<uint32_t>(text.size()));
  bytes_.append(text.data(), text.size());
}

absl::StatusOr<uint8_t> ByteReader::U8(absl::string_view field) {
  MOTIONDB_ASSIGN_OR_RETURN(const uint64_t value, Little(field, 1));
  return static_cast<uint8_t>(value);
}

absl::StatusOr<uint32_t> ByteReader::U32(absl::string_view field) {
  MOTIONDB_ASSIGN_OR_RETURN(const uint64_t value, Little(field, 4));
  return static_cast<uint32_t>(value);
}

absl::StatusOr<int32_t> ByteReader::I32(absl::string_view field) {
  MOTIONDB_ASSIGN_OR_RETURN(const uint32_t value, U32(field));
  return static_cast<int32_t>(value);
}

absl::StatusOr<uint64_t> ByteReader::U64(absl::string_view field) { return Little(field, 8); }

absl::StatusOr<double> ByteReader::F64(absl::string_view field) {
  MOTIONDB_ASSIGN_OR_RETURN(const uint64_t value, Little(field, 8));
  return std::bit_cast<double>(value);
}

absl::StatusOr<std::string> ByteReader::Str(absl::string_view field) {
  MOTIONDB_ASSIGN_OR_RETURN(const uint32_t size, U32(field));
  MOTIONDB_RETURN_IF_ERROR(Need(field, size));
  std::string text(bytes_.substr(position_, size));
  position_ += size;
  return text;
}

absl::Status ByteReader::F64s(absl::string_view field, double* values, size_t count) {
  MOTIONDB_RETURN_IF_ERROR(Need(field, 8 * static_cast<uint64_t>(count)));
  for (size_t i = 0; i < count; ++i) values[i] = *F64(field);
  return absl::OkStatus();
}

absl::StatusOr<uint32_t> ByteReader::Count(absl::string_view field, uint64_t min_bytes_each) {
  MOTIONDB_ASSIGN_OR_RETURN(const uint32_t count, U32(field));
  MOTIONDB_RETURN_IF_ERROR(Need(field, count * min_bytes_each));
  return count;
}

absl::Status ByteReader::Need(absl::string_view field, uint64_t size) const {
  if (size <= remaining()) return absl::OkStatus();
  return absl::DataLossError(absl::StrCat(subject_, " is truncated: ", field, " needs ", size,
                                          " bytes at offset ", position_, ", ", remaining(),
                                          " left"));
}

absl::StatusOr<uint64_t> ByteReader::Little(absl::string_view field, int size) {
  MOTIONDB_RETURN_IF_ERROR(Need(field, size));
  uint64_t value = 0;
  for (int i = 0; i < size; ++i) {
    value |= uint64_t{static_cast<uint8_t>(bytes_[position_ + i])} << (8 * i);
  }
  position_ += size;
  return value;
}

}  // namespace motiondb
