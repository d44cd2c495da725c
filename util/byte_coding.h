// Little-endian byte coding, the one byte order of every file, blob and API byte field we write
// (space files, storage blobs, float32 arrays in responses), whatever the host's order.
//
// ByteWriter appends; ByteReader consumes front to back and fails with DATA_LOSS, naming the
// field, once the bytes run out. Neither is thread-safe; both are cheap to create.
#ifndef MOTIONDB_UTIL_BYTE_CODING_H_
#define MOTIONDB_UTIL_BYTE_CODING_H_

#include <bit>
#include <cstdint>
#include <cstring>
#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"

namespace motiondb {

// `count` float32 values appended to `out`, little-endian (one copy on little-endian hosts).
void AppendFloat32s(const float* values, size_t count, std::string* out);
// Exactly `count` float32 values from `bytes` (which must hold 4 * count bytes) into `values`.
void ReadFloat32s(absl::string_view bytes, size_t count, float* values);

class ByteWriter {
 public:
  void U8(uint8_t value) { bytes_.push_back(static_cast<char>(value)); }
  void U32(uint32_t value) { Little(value, 4); }
  void I32(int32_t value) { Little(static_cast<uint32_t>(value), 4); }
  void U64(uint64_t value) { Little(value, 8); }
  void F32(float value) { Little(std::bit_cast<uint32_t>(value), 4); }
  void F64(double value) { Little(std::bit_cast<uint64_t>(value), 8); }
  // u32 length, then the bytes.
  void Str(absl::string_view text);
  void F64s(const double* values, size_t count) {
    for (size_t i = 0; i < count; ++i) F64(values[i]);
  }

  std::string& bytes() { return bytes_; }

 private:
  void Little(uint64_t value, int size) {
    for (int i = 0; i < size; ++i) bytes_.push_back(static_cast<char>(value >> (8 * i)));
  }

  std::string bytes_;
};

class ByteReader {
 public:
  // `subject` names the whole in errors: "<subject> is truncated: <field> needs ...".
  ByteReader(absl::string_view bytes, absl::string_view subject)
      : bytes_(bytes), subject_(subject) {}

  absl::StatusOr<uint8_t> U8(absl::string_view field);
  absl::StatusOr<uint32_t> U32(absl::string_view field);
  absl::StatusOr<int32_t> I32(absl::string_view field);
  absl::StatusOr<uint64_t> U64(absl::string_view field);
  absl::StatusOr<double> F64(absl::string_view field);
  absl::StatusOr<std::string> Str(absl::string_view field);
  absl::Status F64s(absl::string_view field, double* values, size_t count);
  // An element count, refused when even `min_bytes_each` per element would overrun the input,
  // so that a damaged count cannot trigger a huge allocation.
  absl::StatusOr<uint32_t> Count(absl::string_view field, uint64_t min_bytes_each);

  size_t remaining() const { return bytes_.size() - position_; }
  size_t position() const { return position_; }

 private:
  absl::Status Need(absl::string_view field, uint64_t size) const;
  absl::StatusOr<uint64_t> Little(absl::string_view field, int size);

  absl::string_view bytes_;
  absl::string_view subject_;
  size_t position_ = 0;
};

}  // namespace motiondb

#endif  // MOTIONDB_UTIL_BYTE_CODING_H_
