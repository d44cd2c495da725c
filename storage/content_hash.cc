#include "storage/content_hash.h"

#include <openssl/evp.h>

#include <memory>

#include "absl/status/status.h"
#include "absl/strings/escaping.h"
#include "storage/blob_codec.h"
#include "util/byte_coding.h"

namespace motiondb::storage {

absl::StatusOr<std::string> ContentHash(const Clip& clip) {
  return ContentHashOfBlobs(clip.frame_time(), SkeletonLayoutBlob(clip.skeleton()),
                            Float32Blob(clip.rotations()), Float32Blob(clip.positions()));
}

absl::StatusOr<std::string> ContentHashOfBlobs(double frame_time, absl::string_view layout,
                                               absl::string_view rotations,
                                               absl::string_view positions) {
  // The sizes go first, so that no two splits of the same bytes into blobs hash alike. The frame
  // time is rounded to float32, the precision of the frames, so that "0.0083333333" and
  // "0.00833333333" are one rate.
  ByteWriter header;
  header.F32(static_cast<float>(frame_time));
  header.U64(layout.size());
  header.U64(rotations.size());
  header.U64(positions.size());
  const std::unique_ptr<EVP_MD_CTX, decltype(&EVP_MD_CTX_free)> context(EVP_MD_CTX_new(),
                                                                        &EVP_MD_CTX_free);
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned int digest_size = 0;
  const bool hashed =
      context != nullptr && EVP_DigestInit_ex(context.get(), EVP_sha256(), nullptr) == 1 &&
      EVP_DigestUpdate(context.get(), header.bytes().data(), header.bytes().size()) == 1 &&
      EVP_DigestUpdate(context.get(), layout.data(), layout.size()) == 1 &&
      EVP_DigestUpdate(context.get(), rotations.data(), rotations.size()) == 1 &&
      EVP_DigestUpdate(context.get(), positions.data(), positions.size()) == 1 &&
      EVP_DigestFinal_ex(context.get(), digest, &digest_size) == 1;
  if (!hashed) return absl::InternalError("OpenSSL could not compute a SHA-256 content hash");
  // BytesToHexString writes lower case.
  return absl::BytesToHexString(
      absl::string_view(reinterpret_cast<const char*>(digest), digest_size));
}

}  // namespace motiondb::storage
