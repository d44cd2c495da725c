#include "storage/content_hash.h"

#include <openssl/evp.h>

#include <cstdint>
#include <memory>

#include "absl/status/status.h"
#include "absl/strings/escaping.h"
#include "storage/blob_codec.h"
#include "util/byte_coding.h"
#include "util/status_macros.h"

namespace motiondb::storage {
namespace {

// SHA-256 fed in pieces: the hash of the bytes of every Update, in order. A failure of OpenSSL
// is kept for HexDigest to report.
class Sha256 {
 public:
  Sha256() : context_(EVP_MD_CTX_new(), &EVP_MD_CTX_free) {
    ok_ = context_ != nullptr && EVP_DigestInit_ex(context_.get(), EVP_sha256(), nullptr) == 1;
  }
  void Update(absl::string_view bytes) {
    ok_ = ok_ && EVP_DigestUpdate(context_.get(), bytes.data(), bytes.size()) == 1;
  }
  absl::StatusOr<std::string> HexDigest() {
    unsigned char digest[EVP_MAX_MD_SIZE];
    unsigned int digest_size = 0;
    ok_ = ok_ && EVP_DigestFinal_ex(context_.get(), digest, &digest_size) == 1;
    if (!ok_) return absl::InternalError("OpenSSL could not compute a SHA-256 content hash");
    // BytesToHexString writes lower case.
    return absl::BytesToHexString(
        absl::string_view(reinterpret_cast<const char*>(digest), digest_size));
  }

 private:
  std::unique_ptr<EVP_MD_CTX, decltype(&EVP_MD_CTX_free)> context_;
  bool ok_ = false;
};

// The sizes go first, so that no two splits of the same bytes into blobs hash alike. The frame
// time is rounded to float32, the precision of the frames, so that "0.0083333333" and
// "0.00833333333" are one rate.
void HashHeader(double frame_time, uint64_t layout_bytes, uint64_t rotation_bytes,
                uint64_t position_bytes, Sha256& sha) {
  ByteWriter header;
  header.F32(static_cast<float>(frame_time));
  header.U64(layout_bytes);
  header.U64(rotation_bytes);
  header.U64(position_bytes);
  sha.Update(header.bytes());
}

}  // namespace

absl::StatusOr<std::string> ContentHash(const Clip& clip) {
  // The rotation blob, the largest, is hashed in pieces rather than encoded whole.
  const std::string layout = SkeletonLayoutBlob(clip.skeleton());
  Sha256 sha;
  HashHeader(clip.frame_time(), layout.size(), clip.rotations().size() * sizeof(float),
             clip.positions().size() * sizeof(float), sha);
  sha.Update(layout);
  auto update = [&sha](absl::string_view piece) {
    sha.Update(piece);
    return absl::OkStatus();
  };
  MOTIONDB_RETURN_IF_ERROR(ForEachFloat32Piece(clip.rotations(), update));
  MOTIONDB_RETURN_IF_ERROR(ForEachFloat32Piece(clip.positions(), update));
  return sha.HexDigest();
}

absl::StatusOr<std::string> ContentHashOfBlobs(double frame_time, absl::string_view layout,
                                               absl::string_view rotations,
                                               absl::string_view positions) {
  Sha256 sha;
  HashHeader(frame_time, layout.size(), rotations.size(), positions.size(), sha);
  for (const absl::string_view bytes : {layout, rotations, positions}) sha.Update(bytes);
  return sha.HexDigest();
}

}  // namespace motiondb::storage
