// Search across skeletons (issue 40 item 3), in process (server::Catalog and server::SearchRunner
// on temporary databases, as the server runs them), each figure beside the window-vector
// baseline (bench/window_vector_baseline.h) on the same space and queries:
//  1. cmu/01_01 `_3dsmax` against `_motionbuilder` (one performance, two conventions; the latter
//     has one more frame, a T-pose, first), in a space over both skeletons: 2 s ranges every 5 s
//     of each, searched among the other's clip; found when the first hit starts within 0.1 s of
//     the range's own frames there.
//  2. Bandai takes (the reporting half of bandai2-normal: the second half of each content's
//     takes) against the same takes re-rigged (testing/rerigged_copy.h), in a space over both
//     skeletons: each take whole, its own copy first (and each copy's original); content
//     precision@5 across rigs (an original's first five among the other takes' copies) against
//     within one rig (the same query among the other originals in today's joint-rotation space
//     over the originals alone, and in the canonical space).
//  3. other-skeletons/ (27 joints) against Bandai (22): 4 s ranges every 4 s of cmu1006_walking
//     and cmu1006_running, searched among the Bandai takes: the share of walks (walk,
//     walk-turn-*) and runs among the first five. cmu/ itself holds no labelled walk.
//  4. Cost: the queries of 2 searched in the space over the two skeletons and in a canonical
//     space over one skeleton holding the same frames (each original twice), median request ms.
//  5. FBX and GLB files Debian's Blender makes from BVH takes (testing/blender_scene_files.h;
//     two takes of each content of the reporting half, and cmu/14_14), read by the scene reader
//     the import process runs, among the BVH takes (the reporting half and cmu/14_14) in a space
//     over every skeleton they bring: each file's take whole finds its source take first, and its
//     2 s ranges every 2 s find the source's same frames first (within 0.1 s). Skipped, saying
//     so, without Blender.
// Nothing here chose a default: the bone weights (1 each) and every other option are as built,
// and the re-rig test used bandai1.
//
// usage: rig_search [--mocap DIR]
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "bench/window_vector_baseline.h"
#include "core/bvh/bvh_reader.h"
#include "core/scene/scene_reader.h"
#include "server/catalog.h"
#include "server/index_registry.h"
#include "server/search_runner.h"
#include "storage/database.h"
#include "testing/blender_scene_files.h"
#include "testing/corpus_paths.h"
#include "testing/rerigged_copy.h"
#include "util/file_io.h"
#include "util/status_macros.h"

namespace motiondb {
namespace {

namespace fs = std::filesystem;

double Median(std::vector<double> values) {
  if (values.empty()) return 0;
  std::sort(values.begin(), values.end());
  return values[values.size() / 2];
}

struct Share {
  int hits = 0;
  int counted = 0;
  void Add(bool right) { hits += right ? 1 : 0, ++counted; }
  double value() const { return counted > 0 ? static_cast<double>(hits) / counted : 0; }
  std::string Text() const { return absl::StrFormat("%.3f (%d/%d)", value(), hits, counted); }
};

// "walk" of "dataset-2_walk_normal_012".
std::string ContentOf(const std::string& stem) {
  const size_t first = stem.find('_');
  const size_t last = stem.find("_normal_");
  if (first == std::string::npos || last == std::string::npos || last <= first) return stem;
  return stem.substr(first + 1, last - first - 1);
}

// A database, its catalog and runner in a temporary folder.
class Library {
 public:
  static absl::StatusOr<std::unique_ptr<Library>> Open(const std::string& name) {
    auto library = std::unique_ptr<Library>(new Library);
    library->dir_ = fs::temp_directory_path() / absl::StrCat("rig_search_", name, "_", ::getpid());
    fs::create_directories(library->dir_);
    MOTIONDB_ASSIGN_OR_RETURN(library->database_,
                              storage::Database::Open((library->dir_ / "bench.sqlite").string()));
    library->catalog_ = std::make_unique<server::Catalog>(*library->database_, library->registry_);
    library->runner_ = std::make_unique<server::SearchRunner>(
        library->registry_, *library->database_, server::UploadLimits{});
    return library;
  }
  ~Library() {
    runner_.reset();
    catalog_.reset();
    database_.reset();
    fs::remove_all(dir_);
  }

  // The stored clip's record.
  absl::StatusOr<storage::ClipRecord> Add(const std::string& name, const Clip& clip,
                                          const std::string& tag,
                                          const std::string& extension = ".bvh") {
    storage::ClipRecord record;
    record.name = name;
    record.source_file = name + extension;
    record.tags = {tag};
    MOTIONDB_ASSIGN_OR_RETURN(const server::IngestedClip stored,
                              catalog_->IngestClip(record, clip));
    return stored.record;
  }
  absl::Status Space(const std::string& name, std::vector<int64_t> skeletons, bool canonical) {
    server::SpaceRequest request;
    request.name = name;
    if (canonical) {
      request.skeleton_ids = std::move(skeletons);
    } else {
      request.skeleton_id = skeletons.front();
    }
    return catalog_->CreateSpace(request, {}).status();
  }
  absl::StatusOr<server::SearchOutcome> Search(const std::string& space, int64_t clip_id,
                                               std::optional<int> first, std::optional<int> last,
                                               const std::string& tag, int max_results,
                                               bool exact = false) const {
    server::SearchRequest request;
    request.exact = exact;
    request.space = space;
    server::ClipSelection query;
    query.clip_id = clip_id;
    query.first_frame = first;
    query.last_frame = last;
    request.query = query;
    request.params.max_results = max_results;
    if (!tag.empty()) request.params.tags = {tag};
    return runner_->Run(request, {});
  }
  std::shared_ptr<const server::SpaceSnapshot> Snapshot(const std::string& space) const {
    return registry_.Find(space);
  }

 private:
  Library() = default;
  fs::path dir_;
  std::unique_ptr<storage::Database> database_;
  server::IndexRegistry registry_;
  std::unique_ptr<server::Catalog> catalog_;
  std::unique_ptr<server::SearchRunner> runner_;
};

// The window-vector baseline of a space, and its answer for a stored clip's frames (at the clip's
// rate) among the clips `allowed` says yes to.
class Baseline {
 public:
  static absl::StatusOr<Baseline> Of(std::shared_ptr<const server::SpaceSnapshot> snapshot) {
    Baseline baseline;
    MOTIONDB_ASSIGN_OR_RETURN(
        baseline.index_,
        bench::WindowVectorBaseline::Build(*snapshot->index, bench::WindowBaselineOptions{}));
    baseline.snapshot_ = std::move(snapshot);
    return baseline;
  }
  std::vector<SearchResult> Search(int64_t clip_id, int first, int last, double fps,
                                   const std::function<bool(int64_t clip_id)>& allowed,
                                   int max_results) const {
    const LibraryIndex& library = *snapshot_->index;
    const double rate = snapshot_->space->sample_rate();
    const CoordinateView rows = library.clip_coordinates(library.FindClip(clip_id));
    const int64_t from = std::min<int64_t>(rows.rows - 1, std::lround(first / fps * rate));
    const int64_t to = std::min<int64_t>(rows.rows - 1, std::lround(last / fps * rate));
    std::vector<bool> allow(library.clip_count());
    for (int c = 0; c < library.clip_count(); ++c) allow[c] = allowed(library.clip(c).clip_id);
    return index_->Search(rows.middle_rows(from, to - from + 1), max_results, allow);
  }
  double rate() const { return snapshot_->space->sample_rate(); }

 private:
  std::shared_ptr<const server::SpaceSnapshot> snapshot_;
  std::shared_ptr<const bench::WindowVectorBaseline> index_;
};

absl::StatusOr<Clip> Read(const fs::path& path) {
  MOTIONDB_ASSIGN_OR_RETURN(BvhReadResult read, ReadBvhFile(path.string()));
  return std::move(read.clip);
}

// 1. cmu/01_01 in two conventions.
absl::Status SameTakeTwoConventions(const fs::path& mocap) {
  MOTIONDB_ASSIGN_OR_RETURN(std::unique_ptr<Library> library, Library::Open("cmu"));
  const std::vector<std::string> names = {"01_01_3dsmax", "01_01_motionbuilder"};
  std::vector<storage::ClipRecord> records;
  for (const std::string& name : names) {
    MOTIONDB_ASSIGN_OR_RETURN(const Clip clip, Read(mocap / "cmu" / (name + ".bvh")));
    MOTIONDB_ASSIGN_OR_RETURN(records.emplace_back(), library->Add(name, clip, name));
  }
  MOTIONDB_RETURN_IF_ERROR(
      library->Space("both", {records[0].skeleton_id, records[1].skeleton_id}, true));
  MOTIONDB_ASSIGN_OR_RETURN(const Baseline baseline, Baseline::Of(library->Snapshot("both")));
  for (int q = 0; q < 2; ++q) {
    const storage::ClipRecord& query = records[q];
    const storage::ClipRecord& other = records[1 - q];
    const double fps = 1.0 / query.frame_time;
    const int shift = q == 0 ? 1 : -1;  // the motionbuilder file's frame f + 1 is 3dsmax's f
    const int length = static_cast<int>(std::lround(2.0 * fps));
    Share found, baseline_found;
    std::vector<double> ms, offsets;
    for (int first = 1; first + length < query.frame_count - 1; first += static_cast<int>(fps)) {
      const int last = first + length - 1;
      MOTIONDB_ASSIGN_OR_RETURN(
          const server::SearchOutcome outcome,
          library->Search("both", query.clip_id, first, last, names[1 - q], 1));
      ms.push_back(outcome.request_ms);
      const bool hit = !outcome.hits.empty() && outcome.hits[0].clip_id == other.clip_id;
      const double offset = hit ? (outcome.hits[0].start_frame - (first + shift)) / fps : 1e9;
      if (hit) offsets.push_back(std::abs(offset));
      found.Add(hit && std::abs(offset) <= 0.1);
      if (!(hit && std::abs(offset) <= 0.1)) {
        absl::PrintF("   a miss: %s frames %d-%d found %s frames %d-%d (score %.4f)\n", names[q],
                     first, last, outcome.hits.empty() ? "nothing" : outcome.hits[0].clip_name,
                     outcome.hits.empty() ? 0 : outcome.hits[0].start_frame,
                     outcome.hits.empty() ? 0 : outcome.hits[0].end_frame,
                     outcome.hits.empty() ? 0.0 : outcome.hits[0].score);
      }
      const std::vector<SearchResult> base = baseline.Search(
          query.clip_id, first, last, fps, [&](int64_t id) { return id == other.clip_id; }, 1);
      baseline_found.Add(!base.empty() && std::abs(base[0].first_frame / baseline.rate() -
                                                   (first + shift) / fps) <= 0.1);
    }
    absl::PrintF(
        "1. %s ranges (2 s every 1 s) -> %s: first hit within 0.1 s %s, median |offset| %.3f s, "
        "median request %.1f ms; baseline (window start within 0.1 s) %s\n",
        names[q], names[1 - q], found.Text(), Median(offsets), Median(ms), baseline_found.Text());
  }
  return absl::OkStatus();
}

// The reporting half of bandai2-normal: per content, the second half of its takes.
absl::StatusOr<std::vector<fs::path>> ReportingHalf(const fs::path& folder) {
  std::map<std::string, std::vector<fs::path>> by_content;
  for (const auto& entry : fs::directory_iterator(folder)) {
    if (entry.path().extension() == ".bvh") {
      by_content[ContentOf(entry.path().stem().string())].push_back(entry.path());
    }
  }
  std::vector<fs::path> half;
  for (auto& [content, files] : by_content) {
    std::sort(files.begin(), files.end());
    half.insert(half.end(), files.begin() + files.size() / 2, files.end());
  }
  if (half.empty()) return absl::NotFoundError(absl::StrCat("no BVH files in ", folder.string()));
  return half;
}

// 2 and 4.
absl::Status ReriggedTakes(const fs::path& mocap) {
  MOTIONDB_ASSIGN_OR_RETURN(const std::vector<fs::path> files,
                            ReportingHalf(mocap / "bandai2-normal"));
  MOTIONDB_ASSIGN_OR_RETURN(std::unique_ptr<Library> rigs, Library::Open("rigs"));
  MOTIONDB_ASSIGN_OR_RETURN(std::unique_ptr<Library> twice, Library::Open("twice"));
  std::vector<int64_t> originals, copies, doubled;
  std::map<int64_t, std::string> content;
  std::map<int64_t, int64_t> copy_of, original_of;
  std::map<int64_t, std::string> names;
  int misses = 0;
  int64_t original_skeleton = 0, copy_skeleton = 0, twice_skeleton = 0;
  double fps = 30;
  for (const fs::path& file : files) {
    const std::string name = file.stem().string();
    MOTIONDB_ASSIGN_OR_RETURN(const Clip clip, Read(file));
    MOTIONDB_ASSIGN_OR_RETURN(const Clip copy, testing::ReriggedCopy(clip));
    MOTIONDB_ASSIGN_OR_RETURN(const storage::ClipRecord a, rigs->Add(name, clip, "original"));
    MOTIONDB_ASSIGN_OR_RETURN(const storage::ClipRecord b,
                              rigs->Add("rerig-" + name, copy, "copy"));
    MOTIONDB_ASSIGN_OR_RETURN(const storage::ClipRecord c, twice->Add(name, clip, "original"));
    MOTIONDB_ASSIGN_OR_RETURN(const storage::ClipRecord d,
                              twice->Add("again-" + name, clip, "again"));
    originals.push_back(a.clip_id);
    copies.push_back(b.clip_id);
    doubled.push_back(c.clip_id);
    content[a.clip_id] = content[b.clip_id] = content[c.clip_id] = content[d.clip_id] =
        ContentOf(name);
    copy_of[a.clip_id] = b.clip_id;
    names[a.clip_id] = name;
    original_of[b.clip_id] = a.clip_id;
    original_skeleton = a.skeleton_id, copy_skeleton = b.skeleton_id,
    twice_skeleton = c.skeleton_id;
    fps = 1.0 / a.frame_time;
  }
  MOTIONDB_RETURN_IF_ERROR(rigs->Space("both", {original_skeleton, copy_skeleton}, true));
  // Today's space over one skeleton: its clips are the originals alone.
  MOTIONDB_RETURN_IF_ERROR(rigs->Space("rotations", {original_skeleton}, false));
  MOTIONDB_RETURN_IF_ERROR(twice->Space("one", {twice_skeleton}, true));
  MOTIONDB_ASSIGN_OR_RETURN(const Baseline both_base, Baseline::Of(rigs->Snapshot("both")));
  MOTIONDB_ASSIGN_OR_RETURN(const Baseline rotation_base,
                            Baseline::Of(rigs->Snapshot("rotations")));
  absl::PrintF("2. %d takes of bandai2-normal's reporting half and their re-rigged copies\n",
               originals.size());

  Share own_first, copy_first, base_own_first, exact_own_first;
  Share across, within_rotations, within_canonical, base_across, base_within;
  std::vector<double> both_ms, one_ms;
  const auto precision = [&](const std::vector<int64_t>& found, const std::string& want,
                             Share* share) {
    for (size_t i = 0; i < std::min<size_t>(5, found.size()); ++i)
      share->Add(content[found[i]] == want);
  };
  for (size_t i = 0; i < originals.size(); ++i) {
    const int64_t original = originals[i], copy = copies[i];
    const std::string& want = content[original];
    // Whole takes: the query's own clip is left out, its copy is not.
    MOTIONDB_ASSIGN_OR_RETURN(server::SearchOutcome outcome,
                              rigs->Search("both", original, {}, {}, "", 1));
    both_ms.push_back(outcome.request_ms);
    own_first.Add(!outcome.hits.empty() && outcome.hits[0].clip_id == copy);
    if (!outcome.hits.empty() && outcome.hits[0].clip_id != copy && misses++ < 5) {
      // What came first instead, and the copy's own score (searched among the copies).
      MOTIONDB_ASSIGN_OR_RETURN(const server::SearchOutcome copies_only,
                                rigs->Search("both", original, {}, {}, "copy", 1));
      absl::PrintF(
          "   a miss: %s found %s frames %d-%d (score %.4f); its copy %s\n", names[original],
          outcome.hits[0].clip_name, outcome.hits[0].start_frame, outcome.hits[0].end_frame,
          outcome.hits[0].score,
          copies_only.hits.empty()
              ? std::string("not found")
              : absl::StrFormat("%s frames %d-%d (score %.4f)", copies_only.hits[0].clip_name,
                                copies_only.hits[0].start_frame, copies_only.hits[0].end_frame,
                                copies_only.hits[0].score));
    }
    MOTIONDB_ASSIGN_OR_RETURN(outcome, rigs->Search("both", copy, {}, {}, "", 1));
    copy_first.Add(!outcome.hits.empty() && outcome.hits[0].clip_id == original);
    if (!outcome.hits.empty() && outcome.hits[0].clip_id != original && misses++ < 10) {
      absl::PrintF("   a miss: %s's copy found %s frames %d-%d (score %.4f)\n", names[original],
                   outcome.hits[0].clip_name, outcome.hits[0].start_frame,
                   outcome.hits[0].end_frame, outcome.hits[0].score);
    }
    // The exhaustive search: what the representation gives, whatever the fast search's seeds.
    MOTIONDB_ASSIGN_OR_RETURN(outcome, rigs->Search("both", original, {}, {}, "", 1, true));
    exact_own_first.Add(!outcome.hits.empty() && outcome.hits[0].clip_id == copy);
    MOTIONDB_ASSIGN_OR_RETURN(const server::SearchOutcome doubled_outcome,
                              twice->Search("one", doubled[i], {}, {}, "", 1));
    one_ms.push_back(doubled_outcome.request_ms);
    const int last =
        static_cast<int>(std::lround(rigs->Snapshot("both")->clips.at(original).frame_count - 1));
    const std::vector<SearchResult> base_any = both_base.Search(
        original, 0, last, fps, [&](int64_t id) { return id != original; }, 1);
    base_own_first.Add(!base_any.empty() && base_any[0].clip_id == copy);

    // Precision@5 across rigs: among the other takes' copies.
    std::vector<int64_t> found;
    MOTIONDB_ASSIGN_OR_RETURN(outcome, rigs->Search("both", original, {}, {}, "copy", 6));
    for (const server::SearchHit& hit : outcome.hits) {
      if (hit.clip_id != copy) found.push_back(hit.clip_id);
    }
    precision(found, want, &across);
    // Within one rig: among the other originals.
    found.clear();
    MOTIONDB_ASSIGN_OR_RETURN(outcome, rigs->Search("rotations", original, {}, {}, "original", 5));
    for (const server::SearchHit& hit : outcome.hits) found.push_back(hit.clip_id);
    precision(found, want, &within_rotations);
    found.clear();
    MOTIONDB_ASSIGN_OR_RETURN(outcome, rigs->Search("both", original, {}, {}, "original", 5));
    for (const server::SearchHit& hit : outcome.hits) found.push_back(hit.clip_id);
    precision(found, want, &within_canonical);
    // The baseline, the same two.
    found.clear();
    for (const SearchResult& r : both_base.Search(
             original, 0, last, fps,
             [&](int64_t id) { return original_of.contains(id) && id != copy; }, 5)) {
      found.push_back(r.clip_id);
    }
    precision(found, want, &base_across);
    found.clear();
    for (const SearchResult& r : rotation_base.Search(
             original, 0, last, fps, [&](int64_t id) { return id != original; }, 5)) {
      found.push_back(r.clip_id);
    }
    precision(found, want, &base_within);
  }
  absl::PrintF(
      "   own copy first: %s; copy's original first: %s; exact search, own copy first: %s; "
      "baseline own copy first: %s\n",
      own_first.Text(), copy_first.Text(), exact_own_first.Text(), base_own_first.Text());
  absl::PrintF(
      "   precision@5 across rigs %s; within one rig: joint-rotation space %s (ratio %.3f), "
      "canonical space %s\n",
      across.Text(), within_rotations.Text(), across.value() / within_rotations.value(),
      within_canonical.Text());
  absl::PrintF("   baseline precision@5 across rigs %s; within one rig (rotation space) %s\n",
               base_across.Text(), base_within.Text());
  absl::PrintF(
      "4. cost, whole takes as queries (max_results 1): two skeletons %.1f ms, one skeleton of "
      "the same frames %.1f ms median (x%.2f)\n",
      Median(both_ms), Median(one_ms), Median(both_ms) / Median(one_ms));

  // 3. other-skeletons' walks and runs among these originals.
  MOTIONDB_ASSIGN_OR_RETURN(std::unique_ptr<Library> walks, Library::Open("walks"));
  int64_t bandai_skeleton = 0, other_skeleton = 0;
  std::map<int64_t, std::string> walk_content;
  for (const fs::path& file : files) {
    MOTIONDB_ASSIGN_OR_RETURN(const Clip clip, Read(file));
    MOTIONDB_ASSIGN_OR_RETURN(const storage::ClipRecord a,
                              walks->Add(file.stem().string(), clip, "bandai"));
    walk_content[a.clip_id] = ContentOf(file.stem().string());
    bandai_skeleton = a.skeleton_id;
  }
  std::map<std::string, storage::ClipRecord> other;
  for (const std::string name :
       {"cmu1006_walking", "cmu1006_running", "cmu1006_dance", "cmu1006_jumping",
        "cmu1006_skipping", "cmu1006_ROM", "cmu1006_wave_hello_1"}) {
    MOTIONDB_ASSIGN_OR_RETURN(const Clip clip, Read(mocap / "other-skeletons" / (name + ".bvh")));
    MOTIONDB_ASSIGN_OR_RETURN(other[name], walks->Add(name, clip, "other"));
    other_skeleton = other[name].skeleton_id;
  }
  MOTIONDB_RETURN_IF_ERROR(walks->Space("both", {other_skeleton, bandai_skeleton}, true));
  MOTIONDB_ASSIGN_OR_RETURN(const Baseline walk_base, Baseline::Of(walks->Snapshot("both")));
  for (const auto& [name, kind] : std::vector<std::pair<std::string, std::string>>{
           {"cmu1006_walking", "walk"}, {"cmu1006_running", "run"}}) {
    const storage::ClipRecord& query = other.at(name);
    const double query_fps = 1.0 / query.frame_time;
    const int length = static_cast<int>(std::lround(4 * query_fps));
    Share share, base_share;
    std::map<std::string, int> others;  // what the misses were, by content
    const auto is_kind = [&](int64_t id) {
      const std::string& c = walk_content[id];
      return kind == "walk" ? c.rfind("walk", 0) == 0 : c == "run";
    };
    for (int first = 0; first + length <= query.frame_count; first += length) {
      MOTIONDB_ASSIGN_OR_RETURN(
          const server::SearchOutcome outcome,
          walks->Search("both", query.clip_id, first, first + length - 1, "bandai", 5));
      for (const server::SearchHit& hit : outcome.hits) {
        share.Add(is_kind(hit.clip_id));
        if (!is_kind(hit.clip_id)) {
          ++others[absl::StrCat(walk_content[hit.clip_id], " (frames ", first, "-",
                                first + length - 1, ")")];
        }
      }
      for (const SearchResult& r : walk_base.Search(
               query.clip_id, first, first + length - 1, query_fps,
               [&](int64_t id) { return walk_content.contains(id); }, 5)) {
        base_share.Add(is_kind(r.clip_id));
      }
    }
    absl::PrintF(
        "3. %s (27 joints) 4 s ranges among Bandai takes: %ss in the first five %s (the rest: "
        "%s); baseline %s\n",
        name, kind, share.Text(), absl::StrJoin(others, ", ", absl::PairFormatter(" x")),
        base_share.Text());
  }
  return absl::OkStatus();
}

// The take of a file Blender made, read as the import process reads it.
absl::StatusOr<Clip> ReadSceneTake(const fs::path& path, MotionFileFormat format) {
  MOTIONDB_ASSIGN_OR_RETURN(const std::string bytes,
                            ReadFileBytes(path.string(), int64_t{1} << 30));
  MOTIONDB_ASSIGN_OR_RETURN(SceneReadResult read, ReadScene(bytes, format));
  if (read.takes.size() != 1) {
    return absl::InternalError(absl::StrCat(path.string(), ": ", read.takes.size(), " takes"));
  }
  return std::move(read.takes[0].clip);
}

// 5.
absl::Status SceneFilesOfTakes(const fs::path& mocap) {
  if (const std::string missing = testing::BlenderMissing(); !missing.empty()) {
    absl::PrintF("5. FBX and GLB of BVH takes: %s\n", missing);
    return absl::OkStatus();
  }
  MOTIONDB_ASSIGN_OR_RETURN(std::vector<fs::path> files, ReportingHalf(mocap / "bandai2-normal"));
  files.push_back(mocap / "cmu" / "14_14.bvh");
  MOTIONDB_ASSIGN_OR_RETURN(std::unique_ptr<Library> library, Library::Open("scenes"));
  const fs::path made = fs::temp_directory_path() / absl::StrCat("rig_search_made_", ::getpid());
  fs::create_directories(made);
  std::set<int64_t> skeletons;
  std::map<std::string, int64_t> source_of_name;  // a BVH take's stem -> its clip
  std::vector<fs::path> converted;
  std::map<std::string, int> per_content;
  for (const fs::path& file : files) {
    MOTIONDB_ASSIGN_OR_RETURN(const Clip clip, Read(file));
    const std::string stem = file.stem().string();
    MOTIONDB_ASSIGN_OR_RETURN(const storage::ClipRecord record, library->Add(stem, clip, "bvh"));
    skeletons.insert(record.skeleton_id);
    source_of_name[stem] = record.clip_id;
    if (per_content[ContentOf(stem)]++ < 2) converted.push_back(file);
  }
  struct Made {
    int64_t source = 0;
    storage::ClipRecord record;
    std::string format;
  };
  std::vector<Made> copies;
  for (const fs::path& file : converted) {
    const std::string stem = file.stem().string();
    testing::SceneFileRequest request;
    request.takes = {file};
    MOTIONDB_RETURN_IF_ERROR(testing::MakeSceneFiles(request, made / stem));
    for (const auto& [extension, format] :
         {std::pair{".fbx", MotionFileFormat::kFbx}, std::pair{".glb", MotionFileFormat::kGlb}}) {
      MOTIONDB_ASSIGN_OR_RETURN(const Clip clip, ReadSceneTake(made / (stem + extension), format));
      Made& copy = copies.emplace_back();
      copy.source = source_of_name.at(stem);
      copy.format = extension + 1;
      MOTIONDB_ASSIGN_OR_RETURN(
          copy.record, library->Add(stem + "-" + copy.format, clip, copy.format, extension));
      skeletons.insert(copy.record.skeleton_id);
    }
  }
  fs::remove_all(made);
  MOTIONDB_RETURN_IF_ERROR(library->Space("all", {skeletons.begin(), skeletons.end()}, true));
  MOTIONDB_ASSIGN_OR_RETURN(const Baseline baseline, Baseline::Of(library->Snapshot("all")));
  std::set<int64_t> sources;
  for (const auto& [stem, clip] : source_of_name) sources.insert(clip);
  const auto is_source = [&](int64_t id) { return sources.contains(id); };
  std::map<std::string, Share> take_first, range_first, base_take_first, base_range_first;
  for (const Made& copy : copies) {
    const storage::ClipRecord& query = copy.record;
    const double fps = 1.0 / query.frame_time;
    const int last_frame = static_cast<int>(query.frame_count - 1);
    MOTIONDB_ASSIGN_OR_RETURN(const server::SearchOutcome whole,
                              library->Search("all", query.clip_id, {}, {}, "bvh", 1));
    take_first[copy.format].Add(!whole.hits.empty() && whole.hits[0].clip_id == copy.source);
    const std::vector<SearchResult> base_whole =
        baseline.Search(query.clip_id, 0, last_frame, fps, is_source, 1);
    base_take_first[copy.format].Add(!base_whole.empty() && base_whole[0].clip_id == copy.source);
    const int length = static_cast<int>(std::lround(2.0 * fps));
    for (int first = 0; first + length <= query.frame_count; first += length) {
      const int last = first + length - 1;
      MOTIONDB_ASSIGN_OR_RETURN(const server::SearchOutcome outcome,
                                library->Search("all", query.clip_id, first, last, "bvh", 1));
      // The files keep the BVH's frames: the source's frame f is the file's frame f.
      const bool same_frames = !outcome.hits.empty() && outcome.hits[0].clip_id == copy.source &&
                               std::abs(outcome.hits[0].start_frame - first) / fps <= 0.1;
      range_first[copy.format].Add(same_frames);
      if (!same_frames) {
        absl::PrintF("   a miss: %s frames %d-%d found %s frames %d-%d (score %.4f)\n", query.name,
                     first, last, outcome.hits.empty() ? "nothing" : outcome.hits[0].clip_name,
                     outcome.hits.empty() ? 0 : outcome.hits[0].start_frame,
                     outcome.hits.empty() ? 0 : outcome.hits[0].end_frame,
                     outcome.hits.empty() ? 0.0 : outcome.hits[0].score);
      }
      const std::vector<SearchResult> base =
          baseline.Search(query.clip_id, first, last, fps, is_source, 1);
      base_range_first[copy.format].Add(
          !base.empty() && base[0].clip_id == copy.source &&
          std::abs(base[0].first_frame / baseline.rate() - first / fps) <= 0.1);
    }
  }
  absl::PrintF("5. %d takes made FBX and GLB by Blender, among %d BVH takes, %d skeletons\n",
               converted.size(), source_of_name.size(), skeletons.size());
  for (const std::string format : {"fbx", "glb"}) {
    absl::PrintF(
        "   %s: take whole, its source first %s; 2 s ranges, the source's same frames first %s; "
        "baseline %s, %s\n",
        format, take_first[format].Text(), range_first[format].Text(),
        base_take_first[format].Text(), base_range_first[format].Text());
  }
  return absl::OkStatus();
}

}  // namespace
}  // namespace motiondb

int main(int argc, char** argv) {
  std::filesystem::path mocap;
  if (argc == 3 && std::string(argv[1]) == "--mocap") {
    mocap = argv[2];
  } else if (argc != 1) {
    std::fprintf(stderr, "usage: rig_search [--mocap DIR]\n");
    return 2;
  } else if (const auto dir = motiondb::testing::MocapDir()) {
    mocap = *dir;
  } else {
    std::fprintf(stderr, "../shared/mocap is absent: give --mocap\n");
    return 2;
  }
  for (const auto& part :
       {motiondb::SameTakeTwoConventions, motiondb::ReriggedTakes, motiondb::SceneFilesOfTakes}) {
    const absl::Status status = part(mocap);
    if (!status.ok()) {
      std::fprintf(stderr, "%s\n", std::string(status.message()).c_str());
      return 1;
    }
  }
  return 0;
}
