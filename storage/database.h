// motiondb's embedded storage: one SQLite file (WAL, foreign keys, schema migrations by
// PRAGMA user_version) holding skeletons (and their humanoid slot overrides), clips (frames as
// float32 blobs), Motion Curve spaces (serialised), each clip's cached projection per space, and
// labels.
//
// Every multi-row write is one transaction: a crash at any point loses no acknowledged write
// and leaves no half-written clip or space. Every write takes WriteOptions, whose should_stop
// rolls it back when asked just before the commit. Open() runs an integrity check.
//
// Thread-safe: methods may be called from any thread; writes are serialised, reads run
// concurrently on their own connections. One writer connection behind a mutex runs every write
// transaction (BEGIN IMMEDIATE; synchronous=FULL, so a returned write is on disk); each read
// leases a read-only connection from a small pool (storage/read_pool.h) and, the file being in
// WAL mode, sees the last commit without waiting for the writer or other readers. Another
// process holding the write lock past busy_timeout_ms makes writes fail with UNAVAILABLE.
//
// Invariant: every clip has a projection in every space of its skeleton, so that a space's
// projections load complete. InsertClip and InsertSpace refuse (FAILED_PRECONDITION) writes that
// would break it. Ids are never reused after a delete.
#ifndef MOTIONDB_STORAGE_DATABASE_H_
#define MOTIONDB_STORAGE_DATABASE_H_

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "core/motion/clip.h"
#include "core/motion/humanoid_map.h"
#include "core/motion/matrix.h"
#include "core/space/motion_space.h"
#include "storage/job_record.h"
#include "storage/label_record.h"
#include "storage/pose_model_record.h"

namespace motiondb::storage {

// INVALID_ARGUMENT naming `what` for a descriptor no label can carry: empty, over
// kMaxDescriptorBytes, or text util/name_text.h refuses (the rules AddLabels applies).
absl::Status CheckDescriptor(const std::string& what, const std::string& descriptor);

struct DatabaseOptions {
  // Create the file (and its schema) when it does not exist.
  bool create_if_missing = true;
  // Milliseconds a connection waits for another's write lock before failing.
  int busy_timeout_ms = 5000;
  // Run PRAGMA quick_check on open; a damaged file fails Open() instead of serving errors.
  bool integrity_check = true;
};

// A clip as stored: its frames, and what the catalogue shows.
// What an uploaded file said of itself, kept with each of its clips: an FBX or glTF file its
// format, unit and up axis; a BVH says nothing (empty and 0).
struct SourceFacts {
  std::string format;   // "fbx", "gltf", "glb"; empty for a BVH or an operator's clip
  double unit_m = 0;    // metres per unit of the clip's positions; 0: not said
  std::string up_axis;  // "X", "Y" or "Z" as the file had it (the clip is stored Y up)
};

struct ClipRecord {
  int64_t clip_id = 0;  // assigned by InsertClip
  // Unique. Printable text (util/name_text.h) of 1 to 512 bytes; '/' separates the segments of
  // a relative path ("session1/take_001"), none empty, "." or "..".
  std::string name;
  std::string source_file;        // as uploaded
  std::vector<std::string> tags;  // a set: stored sorted and without repeats
  int64_t skeleton_id = 0;        // clips with identical joint names and parents share one
  int64_t created_unix_ms = 0;    // 0 on insert: the time of the insert
  // Filled on read (InsertClip takes them from the clip): what a listing needs without
  // decoding the frames, and the content hash (storage/content_hash.h).
  double frame_time = 0;
  int64_t frame_count = 0;
  int joint_count = 0;
  std::string content_hash;
  // Where a clip made by an operator came from, as JSON text the application writes and reads
  // (server/edit/provenance.h); empty for an ingested clip. Stored as given.
  std::string provenance;
  SourceFacts source_facts;  // stored as given
};

// What every write may be told. A write is checked once its transaction is ready to commit, so
// that a call that ended first (its deadline passed, its client gone) changes nothing.
struct WriteOptions {
  // True rolls the write back: CANCELLED, nothing written. Empty: never.
  std::function<bool()> should_stop;
};

struct InsertClipOptions {
  // A clip that the new one replaces: it is deleted, with its projections and labels, in the
  // insert's transaction, so that a crash leaves the old clip or the new one, never neither.
  // 0: none.
  int64_t replace_clip_id = 0;
  // The new clip's id; 0: the database assigns the next. A cluster's shards take the ids their
  // router hands out (cluster/clip_id_blocks.h), so that an id names one clip cluster-wide.
  int64_t clip_id = 0;
};

// What UpdateClip changes; what is left unset or empty stays.
struct ClipUpdate {
  std::optional<std::string> name{};
  std::vector<std::string> add_tags{};
  // Tags the clip lacks are ignored. Only required to be non-empty, so that a tag stored before
  // the character rules can still be removed.
  std::vector<std::string> remove_tags{};
};

struct StoredClip {
  ClipRecord record;
  Clip clip;  // offsets and channels are the clip's own
};

// A clip without its frames: what answers about it are sized by before they are read.
struct ClipLayout {
  ClipRecord record;
  std::shared_ptr<const Skeleton> skeleton;  // the clip's own offsets and channels
};

// A clip's projection into a space: frames at the space rate x the space's dimensions,
// pre-scaled by the space's metric (core/search_coordinates.h).
struct Projection {
  int64_t clip_id = 0;
  RowMatrixXf coordinates;
};

struct SpaceRecord {
  int64_t space_id = 0;
  std::string name;
  int64_t skeleton_id = 0;        // 0 on insert: the skeleton of the space's topology
  int version = 1;                // rebuilding a space under the same name makes a new version
  int64_t created_unix_ms = 0;    // 0 on insert: the time of the insert
  std::string build_report_json;  // dims, explained variance, reconstruction errors, options
  // A space over several skeletons (a canonical-bones space): all of them, skeleton_id first;
  // their clips are the space's. Empty for a space over one skeleton.
  std::vector<int64_t> skeleton_ids;
};

// The rows of a listing's page: Page::page_size 0 means kDefaultPageSize, and more than
// kMaxPageSize is refused (the server reads a larger request as kMaxPageSize).
inline constexpr int kDefaultPageSize = 100;
inline constexpr int kMaxPageSize = 1000;

struct Page {
  int page_size = kDefaultPageSize;  // at most kMaxPageSize
  std::string page_token;            // empty for the first page
};

// The order of a clip listing; each has its own page tokens.
enum class ClipOrder { kId, kName, kCreated };

// Which clips a listing holds, and in what order.
struct ClipFilter {
  // The {} initialisers let callers name only the fields they set without -Wextra warnings.
  std::string tag{};                 // only clips carrying it; empty: any
  std::string name_contains{};       // only clips whose name holds it (bytes, case-sensitive)
  int64_t skeleton_id = 0;           // only clips of this skeleton; 0: any
  std::string descriptor{};          // only clips carrying a label of it; empty: any
  ClipOrder order = ClipOrder::kId;  // ties (created) in id order
  // A page ends before the clip that would bring its clips' text (names, hash, tags,
  // provenance) past this many bytes, and holds at least one clip; 0: no bound. An operator's
  // clip's provenance holds its request, so a clip's text has no small bound of its own.
  int64_t max_text_bytes = 0;
};

struct ClipPage {
  std::vector<ClipRecord> clips;
  std::string next_page_token;  // empty on the last page
  int64_t total_size = 0;       // clips the filter takes, on every page
};

// The token of the page after `last` in `order`: the position of `last` (its sort key and id),
// so a token is good for any database in that order (a cluster's shards take the same tokens).
std::string ClipPageToken(ClipOrder order, const ClipRecord& last);

// A skeleton as a listing shows it.
struct SkeletonSummary {
  int64_t skeleton_id = 0;
  int joint_count = 0;
  std::string root_joint;  // the first joint's name (a BVH file's ROOT)
  int64_t clip_count = 0;
  std::string first_clip_name;  // of its lowest clip id; empty when it has none
};

// A skeleton, its joints and the slots of its humanoid map (core/motion/humanoid_map.h) given
// their joints by hand.
struct SkeletonRecord {
  SkeletonSummary summary;
  // The joints with the offsets and channels of the skeleton's first clip (offsets differ
  // between actors of one skeleton); names and parents alone, offsets zero, when it has no clip.
  std::shared_ptr<const Skeleton> skeleton;
  std::vector<SlotOverride> slot_overrides;  // in slot order
};

// What UpdateSlotOverrides changes; slots neither set nor cleared keep their override.
struct SlotOverrideChange {
  std::vector<SlotOverride> set{};
  std::vector<HumanoidSlot> clear{};
};

// The projections of one skeleton's clips into a space over several skeletons, made again with
// the skeleton's map as an override change leaves it (UpdateSlotOverrides).
struct SpaceReprojection {
  int64_t space_id = 0;
  std::vector<Projection> projections;  // one for every clip of the skeleton
};

// `stored`'s overrides once `change` is applied, in slot order: what UpdateSlotOverrides would
// store. INVALID_ARGUMENT as UpdateSlotOverrides says.
absl::StatusOr<std::vector<SlotOverride>> OverridesAfterChange(const SkeletonRecord& stored,
                                                               const SlotOverrideChange& change);

struct Counts {
  int64_t skeletons = 0, clips = 0, frames = 0, spaces = 0, projections = 0, labels = 0;
};

class Database {
 public:
  // Opens (or creates) the database, upgrades its schema, checks integrity. FAILED_PRECONDITION
  // for a file of a newer schema or one that fails the integrity check.
  static absl::StatusOr<std::unique_ptr<Database>> Open(const std::string& path,
                                                        const DatabaseOptions& options = {});
  ~Database();

  // Stores a clip, finding or creating its skeleton and computing its content hash, together
  // with its projection into every space of that skeleton (`projections`: one per space, keyed
  // by space id), in one transaction; first deletes options.replace_clip_id, when given. Returns
  // the new clip id. ALREADY_EXISTS when another clip of that name, or options.clip_id, exists
  // (INVALID_ARGUMENT when that is negative); NOT_FOUND for an
  // unknown space or clip to replace; FAILED_PRECONDITION when `projections` misses a space of
  // the skeleton or names one of another; INVALID_ARGUMENT for a name that breaks
  // ClipRecord::name's rules, a tag of 0 or over 128 bytes or of text util/name_text.h refuses,
  // over 64 tags, values beyond float32, or a projection with non-finite values or more columns
  // than its space. Projection::clip_id is ignored here.
  absl::StatusOr<int64_t> InsertClip(const ClipRecord& record, const Clip& clip,
                                     const std::vector<std::pair<int64_t, Projection>>& projections,
                                     const InsertClipOptions& options = {},
                                     const WriteOptions& write = {});
  // The skeleton id a clip of this topology has or would get (-1 when none is stored yet).
  absl::StatusOr<int64_t> FindSkeleton(const Skeleton& skeleton);
  // The clip, or only its frames `frames`, read and decoded without the others (a 10 s range of
  // a long take costs what 10 s costs). NOT_FOUND for an unknown clip; OUT_OF_RANGE when
  // `frames` is empty or not inside it.
  absl::StatusOr<StoredClip> GetClip(int64_t clip_id,
                                     std::optional<FrameRange> frames = std::nullopt);
  absl::StatusOr<ClipRecord> GetClipRecord(int64_t clip_id);
  // The record (tags included) and skeleton, without the frames. NOT_FOUND for an unknown clip.
  absl::StatusOr<ClipLayout> GetClipLayout(int64_t clip_id);
  // The clip's frames `frames` handed to `consume` in batches of at most `batch_frames`, in
  // order, each a clip of those frames sharing one skeleton (the clip's own), read from the
  // stored blobs piece by piece in one read snapshot: memory holds a batch whatever the clip's
  // length, and the clip stays as it was until the last batch. The snapshot is held while `consume`
  // runs, so a slow consumer keeps the write-ahead log from being checkpointed past it. consume's
  // first error ends the read and is returned. NOT_FOUND for an unknown clip; OUT_OF_RANGE when
  // `frames` is empty or not inside it; INVALID_ARGUMENT for a batch_frames below 1.
  absl::Status ReadClipFrames(int64_t clip_id, FrameRange frames, int batch_frames,
                              const std::function<absl::Status(const Clip& batch)>& consume);
  absl::StatusOr<ClipRecord> GetClipRecordByName(const std::string& name);  // NOT_FOUND
  // Up to `limit` clips whose content hash is `content_hash`, in id order.
  absl::StatusOr<std::vector<ClipRecord>> FindClipsByContentHash(const std::string& content_hash,
                                                                 int limit);
  // Renames and re-tags a clip in one transaction, and returns its record as updated. NOT_FOUND
  // for an unknown clip; ALREADY_EXISTS when another clip has the name; INVALID_ARGUMENT naming
  // the field for a name or added tag that InsertClip would refuse, an empty removed tag, a tag
  // both added and removed, or more than 64 tags in the end. Nothing changes on error.
  absl::StatusOr<ClipRecord> UpdateClip(int64_t clip_id, const ClipUpdate& update,
                                        const WriteOptions& write = {});
  // Clips in id order; optionally only those carrying `tag`. page_size 0 means 100; outside
  // 0-1000, or a malformed page_token: INVALID_ARGUMENT.
  absl::StatusOr<ClipPage> ListClips(const Page& page, const std::string& tag = "");
  // The same, filtered and ordered by `filter`, in one read transaction, with the number of
  // clips the filter takes. A page token holds the last clip's sort key and id, so pages stay
  // stable while clips come and go; a token of another order is INVALID_ARGUMENT, as are a bad
  // tag or descriptor (naming the field) and a negative skeleton_id.
  absl::StatusOr<ClipPage> ListClips(const Page& page, const ClipFilter& filter);
  // Deletes the clip, its projections and labels. NOT_FOUND when absent.
  absl::Status DeleteClip(int64_t clip_id, const WriteOptions& write = {});

  // Stores a space built on `skeleton_id` with the projections of every clip of that skeleton
  // (of every skeleton of `skeleton_ids` when it lists them; the first must be the space's),
  // in one transaction. ALREADY_EXISTS when a space of that name exists; NOT_FOUND for an
  // unknown skeleton or clip; FAILED_PRECONDITION when the space's topology is not the
  // skeleton's, or `projections` misses a clip of the skeleton or names one of another.
  absl::StatusOr<int64_t> InsertSpace(const SpaceRecord& record, const MotionSpace& space,
                                      const std::vector<Projection>& projections,
                                      const WriteOptions& write = {});
  absl::StatusOr<SpaceRecord> GetSpaceRecord(const std::string& name);  // NOT_FOUND
  absl::StatusOr<MotionSpace> GetSpace(int64_t space_id);
  absl::StatusOr<std::vector<SpaceRecord>> ListSpaces();
  // And its projections. NOT_FOUND when absent.
  absl::Status DeleteSpace(const std::string& name, const WriteOptions& write = {});
  // Every cached projection of a space, in clip id order (loaded at start, not recomputed).
  absl::StatusOr<std::vector<Projection>> LoadProjections(int64_t space_id);
  // Ids of the clips of a skeleton, in id order (a space over several skeletons holds the clips
  // of each of its SpaceRecord::skeleton_ids).
  absl::StatusOr<std::vector<int64_t>> ClipsOfSkeleton(int64_t skeleton_id);

  // Labels (storage/label_record.h). AddLabels stores the batch in one transaction, all or
  // nothing, and returns it as stored. An item identical to a stored label (or to an earlier
  // item) in every column but id and creation time is not stored again: it is returned as the
  // stored label, and AddedLabels::skipped lists it, so that importing a file twice adds its
  // labels once. Errors name the item and field
  // ("labels[3].value: 1.5 is outside [0, 1]"): NOT_FOUND for an unknown clip (or source label
  // or space of a propagated label); INVALID_ARGUMENT for an empty batch, a range outside the
  // clip's frames or reversed, a value not in [0, 1] (NaN included), a descriptor that is empty,
  // over kMaxDescriptorBytes or of text util/name_text.h refuses, or a manual label carrying the
  // fields of a propagated one.
  absl::StatusOr<AddedLabels> AddLabels(const std::vector<LabelRecord>& labels,
                                        const WriteOptions& write = {});
  // Labels matching `filter`, in label id order; Page as ListClips takes it (its token is the
  // last label id). NOT_FOUND naming clip_id when the filter's clip is unknown.
  absl::StatusOr<LabelPage> ListLabels(const Page& page, const LabelFilter& filter);
  // Labels of `query.descriptor` with a value of at least `query.min_value`, strongest first,
  // then by clip and first frame. INVALID_ARGUMENT for an empty descriptor, a min_value
  // outside [0, 1], more than kMaxTags tags or a malformed page token.
  absl::StatusOr<LabelPage> FindLabels(const Page& page, const LabelQuery& query);
  // A clip's labels by first frame (then last frame, id), its timeline, a page at a time as
  // ListLabels gives them (its token is the last label's first and last frames and id).
  // NOT_FOUND naming clip_id.
  absl::StatusOr<LabelPage> ClipLabels(int64_t clip_id, const Page& page);
  // Deletes the labels of these ids, and those propagated from them, in one transaction;
  // returns how many of the ids there were. NOT_FOUND naming label_ids[i] when an id is unknown,
  // and nothing is deleted.
  absl::StatusOr<int64_t> DeleteLabels(const std::vector<int64_t>& label_ids,
                                       const WriteOptions& write = {});
  // The same for every label `filter` takes (and those propagated from them); returns how many
  // it took. INVALID_ARGUMENT for an empty filter: deleting every label is not a slip to allow;
  // NOT_FOUND naming clip_id when the filter's clip is unknown.
  absl::StatusOr<int64_t> DeleteLabels(const LabelFilter& filter, const WriteOptions& write = {});

  // The descriptors that manual labels carry, sorted.
  absl::StatusOr<std::vector<std::string>> ManualDescriptors();

  // Jobs (storage/job_record.h). Open() marks every job it finds queued or running
  // `interrupted`: a database file is served by one process at a time, so such a job has nobody
  // left to run it (its process stopped or died first).
  //
  // Stores a new job (its id and creation time assigned) and returns it as stored.
  // INVALID_ARGUMENT for a kind other than "propagation" or a final state.
  absl::StatusOr<JobRecord> CreateJob(const JobRecord& job, const WriteOptions& write = {});
  // Writes the job's state, progress, counts, error and times. NOT_FOUND for an unknown job.
  absl::Status UpdateJob(const JobRecord& job, const WriteOptions& write = {});
  absl::StatusOr<JobRecord> GetJob(const std::string& job_id);  // NOT_FOUND
  // Newest first; Page as ListClips takes it (its token is the last job's number).
  absl::StatusOr<JobPage> ListJobs(const Page& page);
  // How many job rows are in each state (states without jobs are absent).
  absl::StatusOr<std::map<JobState, int64_t>> CountJobs();
  // A propagation job's output and its final row, in one transaction: the propagated labels of
  // output.descriptors found in output.space_id are deleted, output.labels inserted (those whose
  // clip or source label was deleted meanwhile are left out), and output.job written with
  // labels_written set to the number inserted, which is returned. A crash leaves the old labels
  // and the job unfinished, or the new ones and the job done. INVALID_ARGUMENT naming
  // labels[i] for a label AddLabels would refuse or that is not propagated by this job from this
  // space with one of the descriptors; NOT_FOUND for an unknown job.
  absl::StatusOr<int64_t> FinishPropagation(const PropagationOutput& output,
                                            const WriteOptions& write = {});

  // Pose models (storage/pose_model_record.h). InsertPoseModel stores one and returns its id:
  // ALREADY_EXISTS for a taken name, NOT_FOUND for an unknown space, INVALID_ARGUMENT naming
  // `name` for a name of 0 or over 128 bytes or of text util/name_text.h refuses.
  absl::StatusOr<int64_t> InsertPoseModel(const PoseModelRecord& model,
                                          const WriteOptions& write = {});
  absl::StatusOr<PoseModelRecord> GetPoseModel(const std::string& name);  // NOT_FOUND
  // Every model, by name; only those of one space when `space_id` is not 0.
  absl::StatusOr<std::vector<PoseModelRecord>> ListPoseModels(int64_t space_id = 0);
  absl::Status DeletePoseModel(const std::string& name, const WriteOptions& write = {});

  // Every skeleton, in id order, with its clip count and first clip, in one query.
  absl::StatusOr<std::vector<SkeletonSummary>> ListSkeletons();
  // The skeleton and its stored slot overrides. NOT_FOUND for an unknown skeleton.
  absl::StatusOr<SkeletonRecord> GetSkeleton(int64_t skeleton_id);
  // Sets and clears a skeleton's slot overrides in one transaction and returns the skeleton as
  // updated. NOT_FOUND for an unknown skeleton; INVALID_ARGUMENT naming `set[i].joint` for a
  // joint the skeleton lacks or that another override (stored, or set here) gives to another
  // slot, `set[i].slot` for a slot set twice or both set and cleared. In the same transaction,
  // the skeleton's clips' projections into each space of `reprojections` are replaced by its
  // (the spaces over several skeletons that list it, whose poses follow its map):
  // FAILED_PRECONDITION when such a space does not list the skeleton or a clip of the skeleton
  // lacks its projection, INVALID_ARGUMENT for a projection of another clip or of the wrong
  // width. Nothing changes on error.
  absl::StatusOr<SkeletonRecord> UpdateSlotOverrides(
      int64_t skeleton_id, const SlotOverrideChange& change,
      const std::vector<SpaceReprojection>& reprojections = {}, const WriteOptions& write = {});

  absl::StatusOr<Counts> GetCounts();

  struct BackupOptions {
    // Flushed to disk before Backup returns, as a copy to keep must be. Off for a copy read back
    // and removed (CreateBackup's): its flush competes with the live database's commits for the
    // disk.
    bool durable = true;
  };
  // Writes a consistent copy of the database to `path` (missing or empty; ALREADY_EXISTS
  // otherwise) while writers go on: the copy is of one snapshot, taken during the call, so it
  // holds every write acknowledged before the call began. Readers and writers do not wait for
  // it (WAL); the log grows until the copy ends. The copy is a database file of its own, in WAL
  // mode, which Open() opens. RESOURCE_EXHAUSTED when its disk is full; a failed copy is removed.
  absl::Status Backup(const std::string& path, const BackupOptions& options);

 private:
  class Impl;
  explicit Database(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace motiondb::storage

#endif  // MOTIONDB_STORAGE_DATABASE_H_
