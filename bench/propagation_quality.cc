// Markup propagation quality (issue 13, item 6), through the real server: motiondb-server runs
// as a child on a fresh database; the Bandai clips of ../shared/mocap are ingested over gRPC
// (tagged by dataset and style), one space is trained on them, and for each experiment the
// manual labels are replaced by k examples per content (descriptor = the file name's content,
// the whole clip, value 1), a propagation job runs over the clips the experiment evaluates (its
// tags filter), and the propagated labels are read back with ListLabels and scored:
// - clips: for each evaluated (unlabelled) clip, the strongest propagated descriptor among the
//   labels covering at least half of it: coverage (clips with any such label) and accuracy
//   (that descriptor is the clip's content), over the covered clips and over all;
// - long takes (clips of one actor and style concatenated, root positions made continuous in
//   the ground plane, the facing left as recorded): per frame the strongest descriptor covering
//   it against the true content (no label: wrong), and segment F1@50.
// Experiments: bandai2-normal within its one style; bandai1 within each style; bandai1 across
// styles (examples from k styles, one clip per content each, evaluated on the other styles);
// takes of bandai2-normal's non-example clips; takes of each bandai1 style (from the 14 styles
// recorded by one actor each) with examples from other styles. Only clips whose content has an
// example are evaluated.
// The similarity factor's s0, two ways: the server's (the space's scale, as the labels' values
// imply it) and the job's own (the median last score of the examples' full result lists, the
// server's s0 before the space's scale, from the same searches run here); per way, s0 per job
// and the clips whose strongest covering label reaches value 0.5 (coverage and accuracy there).
// With several --space, every experiment runs in each space (the same clips, labels and
// jobs), and a third calibration shows what one fixed s0 would do: the first space's, used in
// every space.
//
// With --split (issue 39), only bandai1 across styles, sources and targets within one half of
// its styles (kSplits: tuning or reporting), each job run with each --variant (a search's seed
// selection, dtw_dims, the exact search, or a space with a metric learned from the job's
// examples), and per run the coverage and accuracy a threshold or margin rule on the strongest
// covering label would give.
//
// usage: propagation_quality [--seeds N] [--max-results M]... [--take-clips N]
//                            [--space body|uniform|scaled]...
//                            [--split tuning|reporting [--variant V]... [--k K]...]
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <deque>
#include <filesystem>
#include <functional>
#include <map>
#include <random>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include <grpcpp/grpcpp.h>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "bench/measure.h"
#include "core/bvh/bvh_reader.h"
#include "core/bvh/bvh_writer.h"
#include "motiondb/v1/clip_service.grpc.pb.h"
#include "motiondb/v1/job_service.grpc.pb.h"
#include "motiondb/v1/label_service.grpc.pb.h"
#include "motiondb/v1/search_service.grpc.pb.h"
#include "motiondb/v1/space_service.grpc.pb.h"
#include "testing/labelled_index.h"
#include "testing/server_process.h"
#include "util/cli_conventions.h"
#include "util/file_io.h"
#include "util/status_macros.h"

namespace motiondb {
namespace {

namespace fs = std::filesystem;

constexpr int kPool = 3;  // bandai2-normal examples set aside per content and seed (k <= kPool)

struct Flags {
  int seeds = 3;
  std::vector<int> max_results = {20, 100};
  int take_clips = 20;  // bandai2-normal clips per long take
  // The spaces the experiments run in, each trained on every clip: body (the defaults),
  // uniform (every joint weighted 1), scaled (each dimension scaled by its eigenvalue).
  std::vector<std::string> spaces = {"body"};
  // Set: only bandai1 across styles, within this half of its styles (kSplits), with each of
  // `variants` and `ks` source styles.
  std::string split;
  std::vector<std::string> variants = {"baseline"};
  std::vector<int> ks = {1, kPool};
  // With a split: each variant's jobs also with each of these rival_share values (0: unset).
  std::vector<double> rival_shares = {0};
};

// Issue 39's held-out rule for propagation across styles: bandai1's 14 styles recorded by one
// actor (`normal`, four skeletons, left out as in every bandai1 take here), in alphabetical
// order, split by turns: the tuning half, on which a job's defaults are chosen, and the
// reporting half, never chosen on. Sources and targets of an experiment are in one half.
const std::map<std::string, std::set<std::string>> kSplits = {
    {"tuning", {"active", "childish", "feminine", "happy", "musical", "old", "sad"}},
    {"reporting", {"angry", "chimpira", "giant", "masculinity", "not-confident", "proud", "tired"}},
};

// How a job of the split experiments searches: its space (`learned`: a space with a metric
// learned from the experiment's examples, created for the job, or `body` when they cannot fit
// one: fewer than two styles; `others`: learned from the examples and every clip of the other
// half's styles, labelled by its content, whose labels are deleted before the job) and its
// search parameters.
struct Variant {
  bool learned = false;
  bool others = false;
  v1::SeedSelection seeds = v1::SEED_SELECTION_UNSPECIFIED;
  int dtw_dims = 0;  // 0: the default
  bool exact = false;
};

const std::map<std::string, Variant> kVariants = {
    {"baseline", {}},
    {"shapes", {.seeds = v1::SEED_SELECTION_SHAPE_WINDOWS}},
    {"dtw10", {.dtw_dims = 10}},
    {"shapes-dtw10", {.seeds = v1::SEED_SELECTION_SHAPE_WINDOWS, .dtw_dims = 10}},
    {"exact", {.exact = true}},
    {"learned", {.learned = true}},
    {"learned-dtw10", {.learned = true, .dtw_dims = 10}},
    {"learned-shapes", {.learned = true, .seeds = v1::SEED_SELECTION_SHAPE_WINDOWS}},
    {"learned-shapes-dtw10",
     {.learned = true, .seeds = v1::SEED_SELECTION_SHAPE_WINDOWS, .dtw_dims = 10}},
    {"others", {.learned = true, .others = true}},
    {"others-dtw10", {.learned = true, .others = true, .dtw_dims = 10}},
    {"others-shapes", {.learned = true, .others = true, .seeds = v1::SEED_SELECTION_SHAPE_WINDOWS}},
    {"others-shapes-dtw10",
     {.learned = true, .others = true, .seeds = v1::SEED_SELECTION_SHAPE_WINDOWS, .dtw_dims = 10}},
};

constexpr char kNone[] = "-";  // the prediction of a clip or frame without a label
// The value a user asking for confident labels would filter on (FindLabels' min_value): where
// the score scale s0 matters. Which labels a job keeps and which is strongest do not depend on
// s0 (one job's values are one decreasing function of the scores, its examples all of value 1).
constexpr double kConfidentValue = 0.5;

// The calibrations of s0 compared: the server's (the space's scale since issue 13's
// calibration, as the labels' values imply it), the job's own, the median last score of the
// job's full result lists (the server's s0 before), computed here from the same searches, and
// one fixed s0 for every space (the first space's scale).
enum Calibration { kSpaceScale, kJobScale, kFixedScale, kCalibrations };

// A clip of the corpus as ingested.
struct CorpusClip {
  fs::path path;
  std::string dataset, content, style;
  int64_t id = 0;
  int frames = 0;
};

// A long take as ingested: its true content per frame.
struct Take {
  int64_t id = 0;
  std::string tag;
  std::vector<std::string> truth;
};

// What one job is asked and what it is scored on.
struct Experiment {
  std::string name;
  int k = 0;
  std::vector<const CorpusClip*> examples;
  std::vector<const CorpusClip*> clips;  // scored as clips
  std::vector<const Take*> takes;        // scored per frame
  std::vector<std::string> tags;         // the clips searched
};

absl::Status FromGrpc(const grpc::Status& status, const std::string& what) {
  if (status.ok()) return absl::OkStatus();
  return absl::Status(static_cast<absl::StatusCode>(status.error_code()),
                      absl::StrCat(what, ": ", status.error_message()));
}

// The server's services, over one channel.
class Api {
 public:
  explicit Api(const std::shared_ptr<grpc::Channel>& channel)
      : clips_(v1::ClipService::NewStub(channel)),
        spaces_(v1::SpaceService::NewStub(channel)),
        labels_(v1::LabelService::NewStub(channel)),
        jobs_(v1::JobService::NewStub(channel)),
        search_(v1::SearchService::NewStub(channel)) {}

  // The clip as stored.
  absl::StatusOr<v1::Clip> Ingest(const std::string& name, const std::string& bvh,
                                  const std::vector<std::string>& tags) {
    v1::IngestClipRequest request;
    request.set_file_name(name + ".bvh");
    request.set_bvh(bvh);
    for (const std::string& tag : tags) request.add_tags(tag);
    v1::IngestClipResponse response;
    grpc::ClientContext context;
    MOTIONDB_RETURN_IF_ERROR(FromGrpc(clips_->IngestClip(&context, request, &response), name));
    return response.clip();
  }

  // A space of Flags::spaces, trained on every clip; `learned`: in the metric learned from the
  // manual labels (the defaults otherwise).
  absl::Status CreateSpace(const std::string& name, bool learned = false) {
    v1::CreateSpaceRequest request;
    request.set_name(name);
    if (name == "uniform") request.set_weight_preset(v1::WEIGHT_PRESET_UNIFORM);
    if (name == "scaled") request.set_metric(v1::SPACE_METRIC_EIGENVALUE_SCALED);
    if (learned) request.mutable_learned_metric();
    v1::Space space;
    grpc::ClientContext context;
    return FromGrpc(spaces_->CreateSpace(&context, request, &space), "CreateSpace");
  }

  absl::Status DeleteSpace(const std::string& name) {
    v1::DeleteSpaceRequest request;
    request.set_name(name);
    v1::DeleteSpaceResponse response;
    grpc::ClientContext context;
    return FromGrpc(spaces_->DeleteSpace(&context, request, &response), "DeleteSpace");
  }

  // Deletes every manual label (and so every propagated one) and adds `examples`.
  absl::Status SetExamples(const std::vector<const CorpusClip*>& examples) {
    v1::DeleteLabelsRequest remove;
    remove.set_origin(v1::LABEL_ORIGIN_MANUAL);
    v1::DeleteLabelsResponse removed;
    grpc::ClientContext remove_context;
    MOTIONDB_RETURN_IF_ERROR(
        FromGrpc(labels_->DeleteLabels(&remove_context, remove, &removed), "DeleteLabels"));
    v1::AddLabelsRequest add;
    for (const CorpusClip* example : examples) {
      v1::NewLabel* label = add.add_labels();
      label->set_clip_id(example->id);  // no range: the whole clip
      label->set_descriptor_name(example->content);
      label->set_value(1);
    }
    v1::AddLabelsResponse added;
    grpc::ClientContext add_context;
    return FromGrpc(labels_->AddLabels(&add_context, add, &added), "AddLabels");
  }

  // Propagates every manual descriptor over the clips carrying one of `tags`, waits for the
  // job and returns the propagated labels.
  absl::StatusOr<std::vector<v1::Label>> Propagate(const std::string& space,
                                                   const std::vector<std::string>& tags,
                                                   int max_results, const Variant& variant = {},
                                                   double rival_share = 0) {
    v1::StartPropagationRequest start;
    start.set_space(space);
    v1::SearchRequest& search = *start.mutable_search();
    search.set_max_results(max_results);
    search.set_seed_selection(variant.seeds);
    if (variant.dtw_dims > 0) search.set_dtw_dims(variant.dtw_dims);
    search.set_exact(variant.exact);
    if (rival_share > 0) start.set_rival_share(rival_share);
    for (const std::string& tag : tags) start.add_tags(tag);
    v1::Job job;
    grpc::ClientContext context;
    MOTIONDB_RETURN_IF_ERROR(
        FromGrpc(jobs_->StartPropagation(&context, start, &job), "StartPropagation"));
    MOTIONDB_ASSIGN_OR_RETURN(job, WaitForJob(job.job_id()));
    if (job.state() != v1::JOB_STATE_SUCCEEDED) {
      return absl::InternalError(
          absl::StrCat(job.job_id(), " ended ", v1::JobState_Name(job.state()), ": ", job.error()));
    }
    return PropagatedLabels();
  }

  // The job's own s0 as the server computed it before the space's scale: the median, over the
  // examples' searches that return all max_results hits with a positive last score, of that
  // score; 1 when there is none.
  absl::StatusOr<double> JobScale(const std::string& space,
                                  const std::vector<const CorpusClip*>& examples,
                                  const std::vector<std::string>& tags, int max_results) {
    std::vector<double> last_scores;
    for (const CorpusClip* example : examples) {
      v1::SearchRequest search;
      search.set_space(space);
      search.mutable_clip()->set_clip_id(example->id);
      search.set_max_results(max_results);
      for (const std::string& tag : tags) search.add_tags(tag);
      v1::SearchResponse found;
      grpc::ClientContext context;
      MOTIONDB_RETURN_IF_ERROR(FromGrpc(search_->Search(&context, search, &found), "Search"));
      if (found.results_size() == max_results && found.results().rbegin()->score() > 0) {
        last_scores.push_back(found.results().rbegin()->score());
      }
    }
    return last_scores.empty() ? 1 : bench::Percentile(last_scores, 0.5);
  }

 private:
  absl::StatusOr<v1::Job> WaitForJob(const std::string& job_id) {
    v1::GetJobRequest get;
    get.set_job_id(job_id);
    v1::Job job;
    do {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
      grpc::ClientContext context;
      MOTIONDB_RETURN_IF_ERROR(FromGrpc(jobs_->GetJob(&context, get, &job), "GetJob"));
    } while (job.state() == v1::JOB_STATE_QUEUED || job.state() == v1::JOB_STATE_RUNNING);
    return job;
  }

  absl::StatusOr<std::vector<v1::Label>> PropagatedLabels() {
    v1::ListLabelsRequest list;
    list.set_origin(v1::LABEL_ORIGIN_PROPAGATED);
    list.set_page_size(1000);
    std::vector<v1::Label> labels;
    do {
      v1::ListLabelsResponse page;
      grpc::ClientContext context;
      MOTIONDB_RETURN_IF_ERROR(FromGrpc(labels_->ListLabels(&context, list, &page), "ListLabels"));
      labels.insert(labels.end(), page.labels().begin(), page.labels().end());
      list.set_page_token(page.next_page_token());
    } while (!list.page_token().empty());
    return labels;
  }

  std::unique_ptr<v1::ClipService::Stub> clips_;
  std::unique_ptr<v1::SpaceService::Stub> spaces_;
  std::unique_ptr<v1::LabelService::Stub> labels_;
  std::unique_ptr<v1::JobService::Stub> jobs_;
  std::unique_ptr<v1::SearchService::Stub> search_;
};

// ---------------------------------------------------------------------------------------------
// The corpus and the long takes.

absl::StatusOr<std::vector<CorpusClip>> IngestFolder(Api& api, const fs::path& folder,
                                                     const std::string& dataset) {
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(folder)) {
    if (entry.path().extension() == ".bvh") files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  std::vector<CorpusClip> clips;
  for (const fs::path& path : files) {
    CorpusClip& clip = clips.emplace_back();
    clip = {path, dataset, testing::ContentLabel(path), testing::StyleLabel(path)};
    MOTIONDB_ASSIGN_OR_RETURN(const std::string bvh, ReadFileBytes(path.string(), 64 << 20));
    MOTIONDB_ASSIGN_OR_RETURN(
        const v1::Clip stored,
        api.Ingest(path.stem().string(), bvh, {dataset, dataset + ":" + clip.style}));
    clip.id = stored.clip_id();
    clip.frames = stored.frame_count();
  }
  return clips;
}

// The clips of `parts` one after the other, on the first one's skeleton (all must have the same
// offsets: one actor). Each part's root is moved in the ground plane (x, z) to start where the
// previous part ended; its height and every rotation are as recorded.
absl::StatusOr<Clip> Concatenate(const std::vector<Clip>& parts) {
  const Clip& first = parts.front();
  const int slot = first.skeleton().position_slot(0);
  int rows = 0;
  for (const Clip& part : parts) {
    for (int j = 0; j < first.skeleton().joint_count(); ++j) {
      if (part.skeleton().joint(j).offset != first.skeleton().joint(j).offset) {
        return absl::InvalidArgumentError("a take's clips must share their skeleton's offsets");
      }
    }
    rows += part.frame_count();
  }
  RowMatrixXd rotations(rows, first.rotations().cols()), positions(rows, first.positions().cols());
  int row = 0;
  for (const Clip& part : parts) {
    rotations.middleRows(row, part.frame_count()) = part.rotations();
    positions.middleRows(row, part.frame_count()) = part.positions();
    if (slot >= 0 && row > 0) {
      for (const int axis : {0, 2}) {
        const double shift = positions(row - 1, 3 * slot + axis) - positions(row, 3 * slot + axis);
        positions.block(row, 3 * slot + axis, part.frame_count(), 1).array() += shift;
      }
    }
    row += part.frame_count();
  }
  return Clip::Create(first.shared_skeleton(), first.frame_time(), std::move(rotations),
                      std::move(positions));
}

absl::StatusOr<Take> IngestTake(Api& api, const std::string& name, const std::string& tag,
                                const std::vector<const CorpusClip*>& members) {
  std::vector<Clip> parts;
  Take take;
  take.tag = tag;
  for (const CorpusClip* member : members) {
    MOTIONDB_ASSIGN_OR_RETURN(BvhReadResult read, ReadBvhFile(member->path.string()));
    take.truth.insert(take.truth.end(), read.clip.frame_count(), member->content);
    parts.push_back(std::move(read.clip));
  }
  MOTIONDB_ASSIGN_OR_RETURN(const Clip clip, Concatenate(parts));
  MOTIONDB_ASSIGN_OR_RETURN(const std::string bvh, WriteBvh(clip));
  MOTIONDB_ASSIGN_OR_RETURN(const v1::Clip stored, api.Ingest(name, bvh, {tag}));
  take.id = stored.clip_id();
  return take;
}

template <typename T>
void Shuffle(std::vector<T>& items, uint32_t seed) {
  std::mt19937 random(seed);
  std::shuffle(items.begin(), items.end(), random);
}

std::vector<const CorpusClip*> Select(const std::vector<CorpusClip>& clips,
                                      const std::function<bool(const CorpusClip&)>& keep) {
  std::vector<const CorpusClip*> selected;
  for (const CorpusClip& clip : clips) {
    if (keep(clip)) selected.push_back(&clip);
  }
  return selected;
}

// Per content, its clips among `clips` in an order drawn from `seed`.
std::map<std::string, std::vector<const CorpusClip*>> ByContent(
    const std::vector<const CorpusClip*>& clips, uint32_t seed) {
  std::map<std::string, std::vector<const CorpusClip*>> by_content;
  for (const CorpusClip* clip : clips) by_content[clip->content].push_back(clip);
  for (auto& [content, members] : by_content) Shuffle(members, seed);
  return by_content;
}

// ---------------------------------------------------------------------------------------------
// The experiments.

// The clips of `candidates` that are not examples and whose content has one.
std::vector<const CorpusClip*> Unlabelled(const std::vector<const CorpusClip*>& candidates,
                                          const std::vector<const CorpusClip*>& examples) {
  std::set<const CorpusClip*> given(examples.begin(), examples.end());
  std::set<std::string> contents;
  for (const CorpusClip* example : examples) contents.insert(example->content);
  std::vector<const CorpusClip*> left;
  for (const CorpusClip* clip : candidates) {
    if (!given.contains(clip) && contents.contains(clip->content)) left.push_back(clip);
  }
  return left;
}

// bandai2-normal within its style, and its takes: the examples are the first k of the seed's
// pool; the takes (ingested here) hold the clips outside the pool.
absl::StatusOr<std::vector<Experiment>> Bandai2Experiments(Api& api,
                                                           const std::vector<CorpusClip>& corpus,
                                                           int seed, const Flags& flags,
                                                           std::deque<Take>* takes) {
  const std::vector<const CorpusClip*> all =
      Select(corpus, [](const CorpusClip& c) { return c.dataset == "bandai2"; });
  std::map<int, std::vector<const CorpusClip*>> examples;  // by k
  std::vector<const CorpusClip*> rest;
  for (const auto& [content, members] : ByContent(all, seed)) {
    for (const int k : {1, kPool}) {
      examples[k].insert(examples[k].end(), members.begin(), members.begin() + k);
    }
    rest.insert(rest.end(), members.begin() + kPool, members.end());
  }
  Shuffle(rest, seed);
  const std::string tag = absl::StrCat("take:bandai2:", seed);
  const size_t first_take = takes->size();
  for (size_t i = 0; i < rest.size(); i += flags.take_clips) {
    const std::vector<const CorpusClip*> members(
        rest.begin() + i, rest.begin() + std::min(rest.size(), i + flags.take_clips));
    MOTIONDB_ASSIGN_OR_RETURN(
        takes->emplace_back(),
        IngestTake(api, absl::StrCat("take-bandai2-s", seed, "-", i / flags.take_clips), tag,
                   members));
  }
  std::vector<Experiment> experiments;
  for (const int k : {1, kPool}) {
    experiments.push_back({"bandai2-normal, within style",
                           k,
                           examples[k],
                           Unlabelled(all, examples[k]),
                           {},
                           {"bandai2"}});
    Experiment on_takes{"bandai2-normal long takes, within style", k, examples[k], {}, {}, {tag}};
    for (size_t t = first_take; t < takes->size(); ++t) on_takes.takes.push_back(&(*takes)[t]);
    experiments.push_back(std::move(on_takes));
  }
  return experiments;
}

// bandai1 within each style: k clips per content of the style are the examples.
std::vector<Experiment> Bandai1WithinStyle(const std::vector<CorpusClip>& corpus, int seed) {
  std::set<std::string> styles;
  for (const CorpusClip& clip : corpus) {
    if (clip.dataset == "bandai1") styles.insert(clip.style);
  }
  std::vector<Experiment> experiments;
  for (const int k : {1, kPool}) {
    for (const std::string& style : styles) {
      const std::vector<const CorpusClip*> in_style = Select(
          corpus, [&](const CorpusClip& c) { return c.dataset == "bandai1" && c.style == style; });
      Experiment experiment{"bandai1, within each style", k, {}, {}, {}, {"bandai1:" + style}};
      for (const auto& [content, members] : ByContent(in_style, seed)) {
        const size_t n = std::min<size_t>(k, members.size());
        experiment.examples.insert(experiment.examples.end(), members.begin(), members.begin() + n);
      }
      experiment.clips = Unlabelled(in_style, experiment.examples);
      experiments.push_back(std::move(experiment));
    }
  }
  return experiments;
}

// bandai1 across `styles`: for each of `ks`, k source styles drawn from `seed`, one clip per
// content from each; evaluated on the other styles' clips, and on their takes among
// `style_takes`.
std::vector<Experiment> Bandai1AcrossStyles(const std::vector<CorpusClip>& corpus,
                                            std::vector<std::string> styles,
                                            const std::vector<Take>& style_takes, int seed,
                                            const std::vector<int>& ks) {
  Shuffle(styles, seed);
  std::vector<Experiment> experiments;
  for (const int k : ks) {
    const std::set<std::string> sources(styles.begin(), styles.begin() + k);
    Experiment clips{"bandai1, across styles", k, {}, {}, {}, {}};
    Experiment takes{"bandai1 long takes, across styles", k, {}, {}, {}, {}};
    for (const std::string& source : sources) {
      const auto in_source = Select(
          corpus, [&](const CorpusClip& c) { return c.dataset == "bandai1" && c.style == source; });
      for (const auto& [content, members] : ByContent(in_source, seed)) {
        clips.examples.push_back(members.front());
      }
    }
    std::set<std::string> targets;
    for (const std::string& style : styles) {
      if (sources.contains(style)) continue;
      targets.insert(style);
      clips.tags.push_back("bandai1:" + style);
      takes.tags.push_back("take:bandai1:" + style);
    }
    const auto in_targets = Select(corpus, [&](const CorpusClip& c) {
      return c.dataset == "bandai1" && targets.contains(c.style);
    });
    clips.clips = Unlabelled(in_targets, clips.examples);
    for (const Take& take : style_takes) {
      if (std::count(takes.tags.begin(), takes.tags.end(), take.tag) > 0)
        takes.takes.push_back(&take);
    }
    takes.examples = clips.examples;
    experiments.push_back(std::move(clips));
    if (!takes.takes.empty()) experiments.push_back(std::move(takes));
  }
  return experiments;
}

// One take per bandai1 style recorded by one actor (every style but `normal`, whose clips come
// from four skeletons): its clips in a fixed shuffled order.
absl::StatusOr<std::vector<Take>> IngestStyleTakes(Api& api,
                                                   const std::vector<CorpusClip>& corpus) {
  std::map<std::string, std::vector<const CorpusClip*>> by_style;
  for (const CorpusClip& clip : corpus) {
    if (clip.dataset == "bandai1" && clip.style != "normal") by_style[clip.style].push_back(&clip);
  }
  std::vector<Take> takes;
  for (auto& [style, members] : by_style) {
    Shuffle(members, 1);
    MOTIONDB_ASSIGN_OR_RETURN(takes.emplace_back(), IngestTake(api, "take-bandai1-" + style,
                                                               "take:bandai1:" + style, members));
  }
  return takes;
}

// ---------------------------------------------------------------------------------------------
// Scoring.

// A scored clip's strongest covering label's value, the strongest of another descriptor's
// (0: none), and whether the strongest is right: what a threshold or margin rule would keep.
struct ClipCall {
  double best = 0, second = 0;
  bool right = false;
};

// Counts of (true content, prediction), and the frame and segment counts of takes.
struct Score {
  std::vector<ClipCall> calls;  // the covered clips
  int64_t clips = 0;            // scored, covered or not
  int learned_fallbacks = 0;    // `learned` jobs run in `body`: the examples fit no metric
  std::map<std::string, std::map<std::string, int64_t>> confusion;
  // Per calibration: clips whose strongest covering label has a value of at least
  // kConfidentValue, how many of those are right, and each job's s0.
  int64_t confident[kCalibrations] = {}, confident_right[kCalibrations] = {};
  std::vector<double> scales[kCalibrations];
  int64_t frames = 0, frames_right = 0;
  int64_t segments_true = 0, segments_predicted = 0, segments_matched = 0;
  int jobs = 0;
};

using LabelsByClip = std::map<int64_t, std::vector<const v1::Label*>>;

// The strongest among `labels` that cover at least `min_frames` of their clip, or null.
const v1::Label* Strongest(const std::vector<const v1::Label*>& labels, int64_t min_frames) {
  const v1::Label* best = nullptr;
  for (const v1::Label* label : labels) {
    if (label->last_frame() - label->first_frame() + 1 < min_frames) continue;
    if (best == nullptr || label->value() > best->value()) best = label;
  }
  return best;
}

// server/jobs/propagation.h's factor, for examples of value 1.
double Factor(double score, double scale) { return std::exp2(-std::pow(score / scale, 2)); }

// The s0 of a job whose examples have value 1: each propagated label of value v < 1 and score s
// gives s / sqrt(-log2 v), inverting Factor; the median of those, 0 if none.
double ImpliedScale(const std::vector<v1::Label>& labels) {
  std::vector<double> scales;
  for (const v1::Label& label : labels) {
    if (label.value() > 0 && label.value() < 1 && label.score() > 0) {
      scales.push_back(label.score() / std::sqrt(-std::log2(label.value())));
    }
  }
  return bench::Percentile(scales, 0.5);
}

// `scales`: the job's s0 per calibration.
void ScoreClips(const Experiment& experiment, const LabelsByClip& labels,
                const double (&scales)[kCalibrations], Score* score) {
  for (const CorpusClip* clip : experiment.clips) {
    const auto found = labels.find(clip->id);
    const v1::Label* best =
        found == labels.end() ? nullptr : Strongest(found->second, (clip->frames + 1) / 2);
    const std::string predicted = best == nullptr ? kNone : best->descriptor_name();
    ++score->confusion[clip->content][predicted];
    ++score->clips;
    if (best != nullptr) {
      ClipCall& call = score->calls.emplace_back();
      call.best = best->value();
      call.right = predicted == clip->content;
      for (const v1::Label* label : found->second) {
        if (label->descriptor_name() != predicted &&
            2 * (label->last_frame() - label->first_frame() + 1) >= clip->frames + 1) {
          call.second = std::max(call.second, label->value());
        }
      }
    }
    for (int c = 0; c < kCalibrations; ++c) {
      if (best != nullptr && Factor(best->score(), scales[c]) >= kConfidentValue) {
        ++score->confident[c];
        score->confident_right[c] += predicted == clip->content;
      }
    }
  }
}

// Per frame, the strongest descriptor covering it (kNone where none does).
std::vector<std::string> FramePrediction(size_t frames,
                                         const std::vector<const v1::Label*>& labels) {
  std::vector<std::string> predicted(frames, kNone);
  std::vector<double> strength(frames, -1);
  for (const v1::Label* label : labels) {
    for (int f = label->first_frame(); f <= label->last_frame() && f < static_cast<int>(frames);
         ++f) {
      if (label->value() > strength[f]) {
        strength[f] = label->value();
        predicted[f] = label->descriptor_name();
      }
    }
  }
  return predicted;
}

struct Segment {
  std::string label;
  int first = 0, last = 0;
};

// The maximal runs of one label, kNone's left out.
std::vector<Segment> Segments(const std::vector<std::string>& frames) {
  std::vector<Segment> segments;
  for (int f = 0; f < static_cast<int>(frames.size()); ++f) {
    if (f > 0 && frames[f] == frames[f - 1]) {
      if (frames[f] != kNone) segments.back().last = f;
    } else if (frames[f] != kNone) {
      segments.push_back({frames[f], f, f});
    }
  }
  return segments;
}

double IoU(const Segment& a, const Segment& b) {
  const int shared = std::min(a.last, b.last) - std::max(a.first, b.first) + 1;
  if (shared <= 0) return 0;
  return static_cast<double>(shared) / (std::max(a.last, b.last) - std::min(a.first, b.first) + 1);
}

// Predicted segments matched to true ones at IoU >= 0.5 (each true segment once; a predicted
// segment takes its best-overlapping true segment of its label), as in MS-TCN's F1@k.
int64_t MatchedSegments(const std::vector<Segment>& predicted, const std::vector<Segment>& truth) {
  std::vector<bool> used(truth.size(), false);
  int64_t matched = 0;
  for (const Segment& segment : predicted) {
    int best = -1;
    double best_iou = 0;
    for (size_t t = 0; t < truth.size(); ++t) {
      const double iou = truth[t].label == segment.label ? IoU(segment, truth[t]) : 0;
      if (iou > best_iou) best = static_cast<int>(t), best_iou = iou;
    }
    if (best >= 0 && best_iou >= 0.5 && !used[best]) used[best] = true, ++matched;
  }
  return matched;
}

void ScoreTakes(const Experiment& experiment, const LabelsByClip& labels, Score* score) {
  static const std::vector<const v1::Label*> kNoLabels;
  for (const Take* take : experiment.takes) {
    const auto found = labels.find(take->id);
    const std::vector<std::string> predicted =
        FramePrediction(take->truth.size(), found == labels.end() ? kNoLabels : found->second);
    for (size_t f = 0; f < predicted.size(); ++f) {
      ++score->confusion[take->truth[f]][predicted[f]];
      score->frames_right += predicted[f] == take->truth[f];
    }
    score->frames += predicted.size();
    const std::vector<Segment> predicted_segments = Segments(predicted);
    const std::vector<Segment> true_segments = Segments(take->truth);
    score->segments_predicted += predicted_segments.size();
    score->segments_true += true_segments.size();
    score->segments_matched += MatchedSegments(predicted_segments, true_segments);
  }
}

constexpr char kLearnedSpace[] = "learned";

// `fixed_scale`: the fixed s0 of every space, set from the first job's space scale when 0.
// `others`: labelled too while an `others` variant's space is created.
absl::Status RunExperiment(Api& api, const std::string& body, const Variant& variant,
                           double rival_share, const Experiment& experiment,
                           const std::vector<const CorpusClip*>& others, int max_results,
                           double* fixed_scale, Score* score) {
  if (experiment.clips.empty() && experiment.takes.empty()) return absl::OkStatus();
  std::vector<const CorpusClip*> fitted = experiment.examples;
  if (variant.others) fitted.insert(fitted.end(), others.begin(), others.end());
  MOTIONDB_RETURN_IF_ERROR(api.SetExamples(fitted));
  std::string space = body;
  if (variant.learned) {
    const absl::Status created = api.CreateSpace(kLearnedSpace, /*learned=*/true);
    if (variant.others) MOTIONDB_RETURN_IF_ERROR(api.SetExamples(experiment.examples));
    if (created.ok()) {
      space = kLearnedSpace;
    } else if (absl::IsFailedPrecondition(created)) {
      ++score->learned_fallbacks;
    } else {
      return created;
    }
  }
  MOTIONDB_ASSIGN_OR_RETURN(
      const std::vector<v1::Label> labels,
      api.Propagate(space, experiment.tags, max_results, variant, rival_share));
  LabelsByClip by_clip;
  for (const v1::Label& label : labels) by_clip[label.clip_id()].push_back(&label);
  ++score->jobs;
  double scales[kCalibrations];
  scales[kSpaceScale] = ImpliedScale(labels);
  MOTIONDB_ASSIGN_OR_RETURN(scales[kJobScale],
                            api.JobScale(space, experiment.examples, experiment.tags, max_results));
  if (*fixed_scale == 0) *fixed_scale = scales[kSpaceScale];
  scales[kFixedScale] = *fixed_scale;
  for (int c = 0; c < kCalibrations; ++c) score->scales[c].push_back(scales[c]);
  ScoreTakes(experiment, by_clip, score);
  ScoreClips(experiment, by_clip, scales, score);
  return space == body ? absl::OkStatus() : api.DeleteSpace(space);
}

// ---------------------------------------------------------------------------------------------
// The report.

struct Tally {
  int64_t total = 0, covered = 0, right = 0;
};

Tally TallyOf(const std::map<std::string, int64_t>& predictions, const std::string& truth) {
  Tally tally;
  for (const auto& [predicted, count] : predictions) {
    tally.total += count;
    if (predicted != kNone) tally.covered += count;
    if (predicted == truth) tally.right += count;
  }
  return tally;
}

double Ratio(int64_t a, int64_t b) { return b == 0 ? 0 : static_cast<double>(a) / b; }

// "walk 40/45 (covered 44): run 3, - 1": right of all, then the wrong predictions, most first.
void PrintConfusion(const Score& score) {
  for (const auto& [truth, predictions] : score.confusion) {
    const Tally tally = TallyOf(predictions, truth);
    std::vector<std::pair<int64_t, std::string>> wrong;
    for (const auto& [predicted, count] : predictions) {
      if (predicted != truth) wrong.emplace_back(-count, absl::StrCat(predicted, " ", count));
    }
    std::sort(wrong.begin(), wrong.end());
    std::vector<std::string> parts;
    for (const auto& [order, text] : wrong) parts.push_back(text);
    std::printf("    %s %lld/%lld (covered %lld)%s%s\n", truth.c_str(),
                static_cast<long long>(tally.right), static_cast<long long>(tally.total),
                static_cast<long long>(tally.covered), parts.empty() ? "" : ": ",
                absl::StrJoin(parts, ", ").c_str());
  }
}

void PrintRow(const std::string& name, int k, int max_results, const Score& score) {
  Tally all;
  for (const auto& [truth, predictions] : score.confusion) {
    const Tally tally = TallyOf(predictions, truth);
    all.total += tally.total, all.covered += tally.covered, all.right += tally.right;
  }
  std::string takes = " | | ";
  if (score.frames > 0) {
    const double precision = Ratio(score.segments_matched, score.segments_predicted);
    const double recall = Ratio(score.segments_matched, score.segments_true);
    takes =
        absl::StrFormat(" | %.3f | %.3f (P %.2f R %.2f) ", Ratio(score.frames_right, score.frames),
                        precision + recall > 0 ? 2 * precision * recall / (precision + recall) : 0,
                        precision, recall);
  }
  // Per calibration: coverage and accuracy at the confident value (clips only), and s0.
  std::string calibrated;
  for (int c = 0; c < kCalibrations; ++c) {
    absl::StrAppend(&calibrated,
                    score.frames > 0
                        ? " | | "
                        : absl::StrFormat(" %.3f | %.3f |", Ratio(score.confident[c], all.total),
                                          Ratio(score.confident_right[c], score.confident[c])));
    const std::vector<double>& scales = score.scales[c];
    if (scales.empty()) {  // an experiment with nothing to evaluate runs no job
      absl::StrAppend(&calibrated, " |");
      continue;
    }
    const auto [low, high] = std::minmax_element(scales.begin(), scales.end());
    absl::StrAppend(&calibrated, absl::StrFormat(" %.3f (%.3f-%.3f) |",
                                                 bench::Percentile(scales, 0.5), *low, *high));
  }
  std::printf("| %s | %d | %d | %d | %lld | %.3f | %.3f | %.3f%s|%s\n", name.c_str(), k,
              max_results, score.jobs, static_cast<long long>(all.total),
              Ratio(all.covered, all.total), Ratio(all.right, all.covered),
              Ratio(all.right, all.total), takes.c_str(), calibrated.c_str());
}

// What a rule deciding which clips keep their strongest label would give: coverage and accuracy
// of the covered clips, the strongest kept when its value is at least a threshold, or when the
// strongest of another descriptor is below a share of it.
void PrintRules(const std::string& name, int k, int max_results, const Score& score) {
  if (score.clips == 0) return;
  const auto row = [&](const std::string& rule, const std::function<bool(const ClipCall&)>& keep) {
    int64_t kept = 0, right = 0;
    for (const ClipCall& call : score.calls) {
      if (!keep(call)) continue;
      ++kept;
      right += call.right;
    }
    std::printf("| %s | %d | %d | %s | %.3f | %.3f | %.3f |\n", name.c_str(), k, max_results,
                rule.c_str(), Ratio(kept, score.clips), Ratio(right, kept),
                Ratio(right, score.clips));
  };
  row("strongest", [](const ClipCall&) { return true; });
  for (const double at_least : {0.001, 0.01, 0.05, 0.1, 0.2, 0.3, 0.5}) {
    row(absl::StrFormat("value >= %g", at_least),
        [&](const ClipCall& call) { return call.best >= at_least; });
  }
  for (const double share : {0.95, 0.9, 0.85, 0.8, 0.75, 0.7, 0.6, 0.5, 0.3}) {
    row(absl::StrFormat("other < %g x strongest", share),
        [&](const ClipCall& call) { return call.second < share * call.best; });
  }
}

absl::StatusOr<std::vector<Experiment>> AllExperiments(Api& api,
                                                       const std::vector<CorpusClip>& corpus,
                                                       const Flags& flags,
                                                       std::deque<Take>* bandai2_takes,
                                                       const std::vector<Take>& style_takes) {
  std::vector<Experiment> experiments;
  if (!flags.split.empty()) {
    const std::set<std::string>& half = kSplits.at(flags.split);
    for (int seed = 1; seed <= flags.seeds; ++seed) {
      std::vector<Experiment> some =
          Bandai1AcrossStyles(corpus, {half.begin(), half.end()}, {}, seed, flags.ks);
      for (Experiment& experiment : some) experiment.name += ", " + flags.split + " split";
      experiments.insert(experiments.end(), some.begin(), some.end());
    }
    return experiments;
  }
  std::vector<std::string> take_styles;
  for (const Take& take : style_takes) {
    take_styles.push_back(take.tag.substr(take.tag.rfind(':') + 1));
  }
  for (int seed = 1; seed <= flags.seeds; ++seed) {
    MOTIONDB_ASSIGN_OR_RETURN(std::vector<Experiment> some,
                              Bandai2Experiments(api, corpus, seed, flags, bandai2_takes));
    for (const std::vector<Experiment>& more :
         {some, Bandai1WithinStyle(corpus, seed),
          Bandai1AcrossStyles(corpus, take_styles, style_takes, seed, {1, kPool})}) {
      experiments.insert(experiments.end(), more.begin(), more.end());
    }
  }
  return experiments;
}

absl::Status Measure(Api& api, const fs::path& mocap, const Flags& flags) {
  MOTIONDB_ASSIGN_OR_RETURN(std::vector<CorpusClip> corpus,
                            IngestFolder(api, mocap / "bandai1", "bandai1"));
  MOTIONDB_ASSIGN_OR_RETURN(std::vector<CorpusClip> bandai2,
                            IngestFolder(api, mocap / "bandai2-normal", "bandai2"));
  corpus.insert(corpus.end(), bandai2.begin(), bandai2.end());
  // Trained on the clips; the takes, ingested after, are projected into them.
  for (const std::string& space : flags.spaces) MOTIONDB_RETURN_IF_ERROR(api.CreateSpace(space));
  std::vector<Take> style_takes;  // the split experiments evaluate clips only
  if (flags.split.empty()) {
    MOTIONDB_ASSIGN_OR_RETURN(style_takes, IngestStyleTakes(api, corpus));
  }
  std::deque<Take> bandai2_takes;  // the experiments point into it
  MOTIONDB_ASSIGN_OR_RETURN(const std::vector<Experiment> experiments,
                            AllExperiments(api, corpus, flags, &bandai2_takes, style_takes));
  // Each space with the default search, or with a split each variant and rival share in the
  // first space.
  std::vector<std::tuple<std::string, std::string, double>> runs;  // space, variant, share
  for (const std::string& space : flags.spaces) {
    if (flags.split.empty()) runs.emplace_back(space, "baseline", 0);
  }
  for (const std::string& variant : flags.variants) {
    for (const double share : flags.rival_shares) {
      if (!flags.split.empty()) runs.emplace_back(flags.spaces.front(), variant, share);
    }
  }
  // The clips of bandai1's other half (its one-actor styles), for the `others` variants.
  const std::vector<const CorpusClip*> others = Select(corpus, [&](const CorpusClip& c) {
    return !flags.split.empty() && c.dataset == "bandai1" && c.style != "normal" &&
           !kSplits.at(flags.split).contains(c.style);
  });
  // By space or variant and experiment ("body: bandai2-normal, within style"), k and
  // max_results.
  std::map<std::tuple<std::string, int, int>, Score> scores;
  double fixed_scale = 0;
  for (const auto& [space, variant, share] : runs) {
    const std::string run = flags.split.empty() ? space
                            : share > 0         ? absl::StrCat(variant, " rival ", share)
                                                : variant;
    for (const int max_results : flags.max_results) {
      for (const Experiment& experiment : experiments) {
        MOTIONDB_RETURN_IF_ERROR(RunExperiment(
            api, space, kVariants.at(variant), share, experiment, others, max_results, &fixed_scale,
            &scores[{absl::StrCat(run, ": ", experiment.name), experiment.k, max_results}]));
      }
    }
  }
  std::printf(
      "| space: experiment | k | max_results | jobs | evaluated | coverage | accuracy (covered) | "
      "accuracy (all) | frame accuracy | F1@50 | space s0: coverage at value >= 0.5 | accuracy "
      "there | s0 median (range) | job s0: coverage at value >= 0.5 | accuracy there | s0 median "
      "(range) | the first space's s0: coverage at value >= 0.5 | accuracy there | s0 "
      "|\n|---|---:|---:|---:|---:|---:|---:|---:|---:|---|---:|---:|---|---:|---:|---|---:|---:|--"
      "-|"
      "\n");
  for (const auto& [key, score] : scores) {
    PrintRow(std::get<0>(key), std::get<1>(key), std::get<2>(key), score);
  }
  std::printf(
      "\n| run: experiment | k | max_results | rule | coverage | accuracy (covered) | accuracy "
      "(all) |\n|---|---:|---:|---|---:|---:|---:|\n");
  for (const auto& [key, score] : scores) {
    PrintRules(std::get<0>(key), std::get<1>(key), std::get<2>(key), score);
  }
  for (const auto& [key, score] : scores) {
    if (score.learned_fallbacks > 0) {
      std::printf("%s, k = %d: %d jobs in %s (their examples fit no metric)\n",
                  std::get<0>(key).c_str(), std::get<1>(key), score.learned_fallbacks,
                  flags.spaces.front().c_str());
    }
  }
  for (const auto& [key, score] : scores) {
    std::printf("\n%s, k = %d, max_results %d: per content, right/all (covered): wrong\n",
                std::get<0>(key).c_str(), std::get<1>(key), std::get<2>(key));
    PrintConfusion(score);
  }
  return absl::OkStatus();
}

absl::Status Run(const Flags& flags) {
  const fs::path mocap = bench::MocapRoot();
  if (!fs::exists(mocap / "bandai1") || !fs::exists(mocap / "bandai2-normal")) {
    std::printf("skipped: %s has no bandai1 and bandai2-normal\n", mocap.c_str());
    return absl::OkStatus();
  }
  const fs::path work =
      fs::temp_directory_path() / ("motiondb_propagation_quality_" + std::to_string(::getpid()));
  fs::create_directories(work);
  testing::ServerProcess server;
  std::string error;
  if (!server.Start({"--db", (work / "library.sqlite").string(), "--quiet"}, &error)) {
    return absl::InternalError(error);
  }
  const auto channel = testing::InsecureChannel(server.address());
  if (!testing::WaitUntilServing(channel, "")) {
    return absl::InternalError("the server did not start serving");
  }
  Api api(channel);
  const absl::Status measured = Measure(api, mocap, flags);
  server.Stop(SIGTERM);
  fs::remove_all(work);
  return measured;
}

}  // namespace
}  // namespace motiondb

int main(int argc, char** argv) {
  CLI::App app("Markup propagation quality on the Bandai clips, through the real server.",
               "propagation_quality");
  motiondb::Flags flags;
  app.add_option("--seeds", flags.seeds, "draws of the examples (and of bandai2's takes)")
      ->capture_default_str()
      ->check(CLI::Range(1, 100));
  app.add_option("--max-results", flags.max_results,
                 "each query's max_results (repeat for several)")
      ->capture_default_str()
      ->check(CLI::Range(1, 10000));
  app.add_option("--take-clips", flags.take_clips, "bandai2-normal clips per long take")
      ->capture_default_str()
      ->check(CLI::Range(2, 1000));
  app.add_option("--space", flags.spaces,
                 "run every experiment in this space (repeat for several): body (defaults), "
                 "uniform (uniform joint weights), scaled (eigenvalue-scaled metric)")
      ->capture_default_str()
      ->check(CLI::IsMember({"body", "uniform", "scaled"}));
  app.add_option("--split", flags.split,
                 "only bandai1 across styles within this half of its styles: tuning or reporting")
      ->check(CLI::IsMember({"tuning", "reporting"}));
  std::vector<std::string> variant_names;
  for (const auto& [name, variant] : motiondb::kVariants) variant_names.push_back(name);
  app.add_option("--variant", flags.variants,
                 "with --split: how the jobs search (repeat for several); learned: in a space "
                 "with a metric learned from the examples, created for each job")
      ->capture_default_str()
      ->check(CLI::IsMember(variant_names));
  app.add_option("--rival-share", flags.rival_shares,
                 "with --split: each job also with this StartPropagation rival_share (repeat; "
                 "0: unset)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1.0));
  app.add_option("--k", flags.ks, "with --split: source styles of the examples (repeat)")
      ->capture_default_str()
      ->check(CLI::Range(1, 6));
  if (const std::optional<int> exit_code = motiondb::cli::ParseCommandLine(app, argc, argv)) {
    return *exit_code;
  }
  const absl::Status status = motiondb::Run(flags);
  if (!status.ok()) {
    std::fprintf(stderr, "propagation_quality: %s\n", std::string(status.message()).c_str());
    return 1;
  }
  return 0;
}
