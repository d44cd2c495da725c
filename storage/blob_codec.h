// The byte forms storage keeps in blobs: matrices as row-major little-endian float32, and a
// clip's joint layout (its Skeleton). Also the canonical text of a skeleton's topology.
//
// Pure functions; thread-safe.
#ifndef MOTIONDB_STORAGE_BLOB_CODEC_H_
#define MOTIONDB_STORAGE_BLOB_CODEC_H_

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

#include "absl/functional/function_ref.h"
#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "core/motion/matrix.h"
#include "core/motion/skeleton.h"

namespace motiondb::storage {

// INVALID_ARGUMENT naming `what` when a value is not finite or does not fit a float32.
absl::Status CheckFloat32Range(const RowMatrixXd& matrix, absl::string_view what);

// Row-major little-endian float32; doubles are rounded to the nearest float.
std::string Float32Blob(const RowMatrixXd& matrix);
std::string Float32Blob(const RowMatrixXf& matrix);
// Float32Blob(matrix)'s bytes in order, in pieces of at most kFloat32PieceBytes handed to
// `consume` (its first error stops the loop and is returned): a blob written or hashed this way
// is never whole in memory.
inline constexpr size_t kFloat32PieceBytes = size_t{1} << 20;
absl::Status ForEachFloat32Piece(const RowMatrixXd& matrix,
                                 absl::FunctionRef<absl::Status(absl::string_view)> consume);
// DATA_LOSS naming `what` when the blob is not rows x cols floats.
absl::StatusOr<RowMatrixXf> ParseFloat32Blob(absl::string_view blob, int64_t rows, int64_t cols,
                                             absl::string_view what);
// Quaternions (frames x 4 * joints, w x y z) from a float32 blob, each renormalised in double
// so that they are unit to double precision again; DATA_LOSS for a zero or non-finite one.
absl::StatusOr<RowMatrixXd> ParseRotationBlob(absl::string_view blob, int64_t frames,
                                              int64_t joints);

// Every joint's name, parent, offset, channels and End Site, exactly (doubles bit for bit).
std::string SkeletonLayoutBlob(const Skeleton& skeleton);
// DATA_LOSS for damaged bytes; Skeleton::Create's errors for an inconsistent hierarchy.
absl::StatusOr<std::shared_ptr<const Skeleton>> ParseSkeletonLayout(absl::string_view blob);

// The canonical text of the joint names and parents, equal exactly when SameTopology: one line
// per joint, "<parent> <name length> <name>" (the length keeps any name unambiguous).
std::string TopologyKey(const Skeleton& skeleton);

}  // namespace motiondb::storage

#endif  // MOTIONDB_STORAGE_BLOB_CODEC_H_
