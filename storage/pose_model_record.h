// A pose model as stored (thesis 3.4): a Mixture of Gaussians fitted in one space, kept by name
// so that it can score any clip of the space's skeleton. The model itself is text the storage
// does not read (core/ops/pose_model_serialization.h).
#ifndef MOTIONDB_STORAGE_POSE_MODEL_RECORD_H_
#define MOTIONDB_STORAGE_POSE_MODEL_RECORD_H_

#include <cstdint>
#include <string>

namespace motiondb::storage {

inline constexpr size_t kMaxPoseModelNameBytes = 128;

struct PoseModelRecord {
  int64_t model_id = 0;  // assigned by InsertPoseModel
  std::string name;      // unique
  int64_t space_id = 0;
  std::string space_name;       // filled on read
  std::string data;             // the serialised model
  std::string parameters_json;  // how it was fitted: examples and options, as the caller wrote
  int64_t created_unix_ms = 0;  // 0 on insert: the time of the insert
};

}  // namespace motiondb::storage

#endif  // MOTIONDB_STORAGE_POSE_MODEL_RECORD_H_
