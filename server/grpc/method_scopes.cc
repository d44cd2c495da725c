#include "server/grpc/method_scopes.h"

#include "absl/container/flat_hash_map.h"
#include "absl/strings/match.h"

namespace motiondb::server {
namespace {

const absl::flat_hash_map<absl::string_view, TokenScope>& Table() {
  using S = TokenScope;
  static const auto* const table = new absl::flat_hash_map<absl::string_view, TokenScope>{
      {"/motiondb.v1.ClipService/IngestClip", S::kWrite},
      {"/motiondb.v1.ClipService/IngestClipStream", S::kWrite},
      {"/motiondb.v1.ClipService/ListClips", S::kRead},
      {"/motiondb.v1.ClipService/GetClip", S::kRead},
      {"/motiondb.v1.ClipService/DeleteClip", S::kAdmin},
      {"/motiondb.v1.ClipService/UpdateClip", S::kWrite},
      {"/motiondb.v1.ClipService/ExportClip", S::kRead},
      {"/motiondb.v1.ClipService/ExportClipStream", S::kRead},
      {"/motiondb.v1.ClipService/GetClipPoses", S::kRead},
      {"/motiondb.v1.ClipService/ListSkeletons", S::kRead},
      {"/motiondb.v1.ClipService/GetSkeleton", S::kRead},
      {"/motiondb.v1.ClipService/MapSkeleton", S::kWrite},
      {"/motiondb.v1.EditService/Reconstruct", S::kWrite},
      {"/motiondb.v1.EditService/Interpolate", S::kWrite},
      {"/motiondb.v1.EditService/Blend", S::kWrite},
      {"/motiondb.v1.EditService/FillGap", S::kWrite},
      {"/motiondb.v1.EditService/Scale", S::kWrite},
      {"/motiondb.v1.EditService/Translate", S::kWrite},
      {"/motiondb.v1.EditService/Smooth", S::kWrite},
      {"/motiondb.v1.EditService/CreatePoseModel", S::kWrite},
      {"/motiondb.v1.EditService/ListPoseModels", S::kRead},
      {"/motiondb.v1.EditService/DeletePoseModel", S::kAdmin},
      {"/motiondb.v1.EditService/DetectPose", S::kWrite},
      {"/motiondb.v1.JobService/StartPropagation", S::kWrite},
      {"/motiondb.v1.JobService/GetJob", S::kRead},
      {"/motiondb.v1.JobService/ListJobs", S::kRead},
      {"/motiondb.v1.JobService/CancelJob", S::kWrite},
      {"/motiondb.v1.JobService/WatchJob", S::kRead},
      {"/motiondb.v1.LabelService/AddLabels", S::kWrite},
      {"/motiondb.v1.LabelService/ListLabels", S::kRead},
      {"/motiondb.v1.LabelService/DeleteLabels", S::kAdmin},
      {"/motiondb.v1.LabelService/FindLabels", S::kRead},
      {"/motiondb.v1.LabelService/GetClipLabels", S::kRead},
      {"/motiondb.v1.SearchService/Search", S::kRead},
      {"/motiondb.v1.SearchService/SearchBatch", S::kRead},
      {"/motiondb.v1.ServerService/GetServerInfo", S::kRead},
      {"/motiondb.v1.ServerService/CreateBackup", S::kAdmin},
      {"/motiondb.v1.SpaceService/CreateSpace", S::kWrite},
      {"/motiondb.v1.SpaceService/ListSpaces", S::kRead},
      {"/motiondb.v1.SpaceService/GetSpace", S::kRead},
      {"/motiondb.v1.SpaceService/DeleteSpace", S::kAdmin},
      {"/motiondb.v1.SpaceService/GetCurve", S::kRead},
      // A router, having checked its caller, presents the cluster's own token.
      {"/motiondb.shard.v1.ShardService/StoreTake", S::kCluster},
      {"/motiondb.shard.v1.ShardService/UpdateClip", S::kCluster},
  };
  return *table;
}

}  // namespace

bool IsMotionDbMethod(absl::string_view method) {
  return absl::StartsWith(method, "/motiondb.v1.") ||
         absl::StartsWith(method, "/motiondb.shard.v1.");
}

TokenScope RequiredScope(absl::string_view method) {
  const auto found = Table().find(method);
  return found == Table().end() ? TokenScope::kAdmin : found->second;
}

bool HasScopeEntry(absl::string_view method) { return Table().contains(method); }

}  // namespace motiondb::server
