// How long past its deadline each long operation of a request returns (issue 37): every
// operation runs on the largest inputs the server's limits admit (a query of --max-query-frames
// frames, long stored clips), with a stop function that turns true at a deadline set midway
// through its work, as a call's StopWhenCallEnds does; the time from the deadline to the
// operation's return is its overshoot. In process, through the server's own code
// (server::SearchRunner, the edit operators), on a synthetic library stored as the server stores
// one (a measurement program).
//
// With --memory, instead: the peak resident memory of the real motiondb-server, started afresh on
// the same library for each query, while it searches queries of increasing length.
//
// usage: deadline_overshoot [--hours H] [--query-frames N] [--repetitions R] [--only NAME]
//          [--db PATH] [--memory]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "bench/measure.h"
#include "bench/synthetic_library.h"
#include "core/search/warp/time_warp.h"
#include "motiondb/v1/search_service.grpc.pb.h"
#include "server/edit/blends.h"
#include "server/edit/curves.h"
#include "server/edit/pose_models.h"
#include "server/edit/reconstruct.h"
#include "server/edit/transitions.h"
#include "server/search_runner.h"
#include "testing/server_process.h"
#include "testing/synthetic_corpus.h"
#include "util/cli_conventions.h"
#include "util/status_macros.h"

namespace motiondb {
namespace {

using bench::Clock;
using bench::SecondsSince;
using testing::GenerateSyntheticCorpus;
using testing::SyntheticCorpus;
using testing::SyntheticCorpusOptions;

// The edits' take: 20 minutes at 120 fps of the 21-joint humanoid, whose BVH (144,000 frames of
// 66 channels, up to 20 bytes a value as the answer limit counts it: 181 MiB) is about as long
// as an edit's answer may be at the default answer limit of 256 MiB.
constexpr double kLongTakeSeconds = 1200;

struct Options {
  bool memory = false;
  double hours = 1.0;
  int query_frames = server::kDefaultMaxQueryFrames;
  int repetitions = 10;
  std::string only;
  std::string db;
};

// One long operation: runs it with `should_stop`.
struct Operation {
  std::string name;
  std::string input;  // what it works on, for the table
  std::function<absl::Status(const std::function<bool()>& should_stop)> run;
};

// The p-quantile by nearest rank: of 20 values, p95 is the 19th (bench::Percentile's is the 20th).
double NearestRank(std::vector<double> v, double p) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const auto rank = static_cast<size_t>(std::ceil(p * static_cast<double>(v.size())));
  return v[std::clamp<size_t>(rank, 1, v.size()) - 1];
}

double Milliseconds(Clock::duration d) {
  return std::chrono::duration<double, std::milli>(d).count();
}

// The operation's time without a deadline (up to `cap`: past it, the cap), then `repetitions`
// runs with a deadline drawn from a quarter to three quarters of that time (at most `cap`),
// each one's overshoot: from the deadline to the return. A run that ended before its deadline
// is counted apart.
absl::Status Measure(const Operation& op, int repetitions, std::mt19937_64& random) {
  constexpr double kCapMs = 4000;
  const Clock::time_point start = Clock::now();
  const Clock::time_point cap = start + std::chrono::milliseconds(static_cast<int>(kCapMs));
  const absl::Status full = op.run([cap] { return Clock::now() > cap; });
  const double full_ms = Milliseconds(Clock::now() - start);
  if (!full.ok() && !absl::IsCancelled(full)) return full;
  std::vector<double> overshoots;
  int finished = 0;
  std::uniform_real_distribution<double> share(0.25, 0.75);
  for (int r = 0; r < repetitions; ++r) {
    const double deadline_ms = share(random) * std::min(full_ms, kCapMs);
    const Clock::time_point begin = Clock::now();
    const Clock::time_point deadline =
        begin + std::chrono::microseconds(static_cast<int64_t>(deadline_ms * 1000));
    const absl::Status status = op.run([deadline] { return Clock::now() > deadline; });
    const Clock::time_point end = Clock::now();
    if (!status.ok() && !absl::IsCancelled(status)) return status;
    // An operation that went on to the end past its deadline overshot it all the same.
    if (end <= deadline) {
      ++finished;
    } else {
      overshoots.push_back(Milliseconds(end - deadline));
    }
  }
  std::printf("| %s | %s | %s%.0f | %d | %.1f | %.1f | %d |\n", op.name.c_str(), op.input.c_str(),
              full.ok() ? "" : ">", full_ms, static_cast<int>(overshoots.size()),
              NearestRank(overshoots, 0.95),
              overshoots.empty() ? 0.0 : *std::max_element(overshoots.begin(), overshoots.end()),
              finished);
  std::fflush(stdout);
  return absl::OkStatus();
}

// The server's peak resident memory (VmHWM) after one search of `request`, started afresh on
// `db`, less its resident memory once serving: what that search took.
absl::StatusOr<double> SearchPeakMiB(const std::string& db, int max_query_frames,
                                     const v1::SearchRequest& request) {
  testing::ServerProcess server;
  std::string error;
  if (!server.Start({"--db", db, "--max-query-frames", absl::StrCat(max_query_frames), "--quiet"},
                    &error)) {
    return absl::InternalError(error);
  }
  const auto channel = testing::InsecureChannel(server.address());
  if (!testing::WaitUntilServing(channel, "")) {
    return absl::InternalError("the server never reported SERVING");
  }
  const double serving = bench::StatusMiB(server.pid(), "VmHWM");
  grpc::ClientContext context;
  v1::SearchResponse response;
  const grpc::Status status =
      v1::SearchService::NewStub(channel)->Search(&context, request, &response);
  if (!status.ok()) return absl::InternalError(status.error_message());
  return bench::StatusMiB(server.pid(), "VmHWM") - serving;
}

// The memory a query takes by its length: the fast search as it runs by default, without
// refinement (its warps at every frame), and the exact search with paths.
absl::Status MeasureMemory(const std::string& db, int64_t clip_id, int longest) {
  std::printf(
      "| query frames (at 30 Hz) | fast search (MiB) | without refinement (MiB) | exact "
      "search with paths (MiB) |\n|---:|---:|---:|---:|\n");
  for (const int frames : {500, 1000, 2000, 4000, 8000}) {
    if (frames > longest) break;
    v1::SearchRequest request;
    request.set_space("body");
    request.mutable_clip()->set_clip_id(clip_id);
    request.mutable_clip()->set_first_frame(0);
    request.mutable_clip()->set_last_frame(frames - 1);
    MOTIONDB_ASSIGN_OR_RETURN(const double fast, SearchPeakMiB(db, frames, request));
    request.set_refine(false);
    MOTIONDB_ASSIGN_OR_RETURN(const double unrefined, SearchPeakMiB(db, frames, request));
    request.clear_refine();
    request.set_exact(true);
    request.set_return_path(true);
    MOTIONDB_ASSIGN_OR_RETURN(const double exact, SearchPeakMiB(db, frames, request));
    std::printf("| %d | %.0f | %.0f | %.0f |\n", frames, fast, unrefined, exact);
    std::fflush(stdout);
  }
  return absl::OkStatus();
}

absl::Status Run(const Options& options) {
  const std::string db =
      options.db.empty()
          ? (std::filesystem::temp_directory_path() / "deadline_overshoot.sqlite").string()
          : options.db;
  const bool stored = std::filesystem::exists(db);
  if (!stored) {
    const Clock::time_point start = Clock::now();
    MOTIONDB_RETURN_IF_ERROR(bench::StoreSyntheticLibrary(db, options.hours, 30, "body").status());
    std::fprintf(stderr, "stored %.1f h of synthetic capture in %.0f s\n", options.hours,
                 SecondsSince(start));
  }
  MOTIONDB_ASSIGN_OR_RETURN(std::unique_ptr<storage::Database> database,
                            storage::Database::Open(db));
  server::IndexRegistry registry;
  server::Catalog catalog(*database, registry);
  MOTIONDB_RETURN_IF_ERROR(catalog.LoadIndices());
  if (!stored) {
    // The edits' source: one take as long as an edit's answer may be (its BVH within the default
    // answer limit of 256 MiB).
    SyntheticCorpusOptions take;
    take.fps = 120;
    take.seed = 2;
    take.target_duration_s = kLongTakeSeconds;
    take.max_clip_duration_s = kLongTakeSeconds + 60;
    MOTIONDB_ASSIGN_OR_RETURN(const SyntheticCorpus generated, GenerateSyntheticCorpus(take));
    storage::ClipRecord record;
    record.name = "long_take";
    record.source_file = "long_take.bvh";
    MOTIONDB_RETURN_IF_ERROR(catalog.IngestClip(record, generated.clips.front()).status());
  }
  struct {
    int64_t clip_id = 0;
    int frame_count = 0;
  } long_take;
  const server::SearchRunner runner(registry, *database, {}, options.query_frames);
  const std::shared_ptr<const server::SpaceSnapshot> snapshot = registry.Find("body");
  if (snapshot == nullptr) return absl::NotFoundError(absl::StrCat(db, " has no space 'body'"));
  // The longest clip holds the query; the space samples at the clips' 30 Hz, so its frames are
  // the query's frames at the space's rate.
  const auto longest = *std::max_element(
      snapshot->clips.begin(), snapshot->clips.end(), [](const auto& a, const auto& b) {
        const auto at_30 = [](const auto& clip) {
          return std::abs(clip.second.fps - 30) < 1e-6 ? clip.second.frame_count : 0;
        };
        return at_30(a) < at_30(b);
      });
  const int query_frames = std::min(options.query_frames, longest.second.frame_count);
  for (int c = 0; c < snapshot->index->clip_count(); ++c) {
    if (snapshot->index->clip(c).name != "long_take") continue;
    long_take.clip_id = snapshot->index->clip(c).clip_id;
    long_take.frame_count = snapshot->clips.at(long_take.clip_id).frame_count;
  }
  const auto search_op = [&](std::string name, std::string input,
                             std::function<void(server::SearchRequest&)> set, int frames = 0) {
    server::SearchRequest request;
    request.space = "body";
    request.query =
        server::ClipSelection{longest.first, 0, (frames > 0 ? frames : query_frames) - 1};
    set(request);
    return Operation{std::move(name), std::move(input),
                     [&runner, request](const std::function<bool()>& should_stop) {
                       return runner.Run(request, should_stop).status();
                     }};
  };
  if (options.memory) {
    return MeasureMemory(db, longest.first, longest.second.frame_count);
  }
  const std::string query = absl::StrCat(query_frames, "-frame query");
  // At slope limit 8 a query's warps fill the table of a --max-query-frames query at slope 2
  // with fewer frames (server/search_runner.cc): the longest admitted.
  int steep_frames = query_frames;
  while (AnchoredWarpTableBytes(steep_frames, 8) >
         AnchoredWarpTableBytes(options.query_frames, kDefaultSlopeLimit)) {
    --steep_frames;
  }
  std::vector<Operation> operations = {
      search_op("search", query, [](server::SearchRequest&) {}),
      search_op("search, 100 results with paths", query,
                [](server::SearchRequest& r) {
                  r.params.max_results = 100;
                  r.params.return_path = true;
                }),
      search_op("search without refinement", query,
                [](server::SearchRequest& r) { r.params.refine = false; }),
      search_op(
          "search, slope limit 8, no refinement",
          absl::StrCat(steep_frames, "-frame query (the longest admitted)"),
          [](server::SearchRequest& r) {
            r.params.refine = false;
            r.params.slope_limit = 8;
          },
          steep_frames),
      search_op("search, 16 characteristic points", query,
                [](server::SearchRequest& r) { r.params.characteristic_points = 16; }),
      search_op("search, 1,000,000 neighbours", query,
                [](server::SearchRequest& r) { r.params.neighbours = 1'000'000; }),
      search_op("exact search (every core)", query,
                [](server::SearchRequest& r) { r.exact = true; }),
      search_op("exact search, every dimension, slope limit 8", query,
                [](server::SearchRequest& r) {
                  r.exact = true;
                  r.dtw_dims = 10;
                  r.params.slope_limit = 8;
                }),
      search_op("exact search with paths", query,
                [](server::SearchRequest& r) {
                  r.exact = true;
                  r.params.return_path = true;
                  r.params.max_results = 100;
                }),
  };
  const server::EditContext edits{*database, catalog, registry};
  const server::ClipSelection take{long_take.clip_id, std::nullopt, std::nullopt};
  const std::string take_input = absl::StrCat(long_take.frame_count, "-frame take at 120 fps (",
                                              long_take.frame_count / 120, " s)");
  const auto edit_op = [&](std::string name, std::string input,
                           std::function<absl::Status(const std::function<bool()>&)> run) {
    operations.push_back({std::move(name), std::move(input), std::move(run)});
  };
  const auto curve_edit = [&] {
    server::CurveEdit edit;
    edit.space = "body";
    edit.clip = take;
    return edit;
  };
  edit_op("smooth", take_input, [&](const std::function<bool()>& stop) {
    server::SmoothRequest request{curve_edit(), {}};
    return server::Smooth(edits, request, stop).status();
  });
  edit_op("scale", take_input, [&](const std::function<bool()>& stop) {
    server::ScaleRequest request{curve_edit(), {}};
    return server::Scale(edits, request, stop).status();
  });
  edit_op("translate", take_input, [&](const std::function<bool()>& stop) {
    server::TranslateRequest request{curve_edit(), {{long_take.clip_id, 0, 0}}, {}};
    return server::Translate(edits, request, stop).status();
  });
  edit_op("reconstruct with its error curve", take_input, [&](const std::function<bool()>& stop) {
    server::ReconstructRequest request;
    request.space = "body";
    request.clip = take;
    request.options.dims = 5;
    request.options.error_curve = true;
    return server::Reconstruct(edits, request, stop).status();
  });
  // The take's two halves joined by a gap of `gap_s`, or overlapping by `overlap_s`.
  const auto halves = [&](double gap_s, double overlap_s) {
    return [&, gap_s, overlap_s](const std::function<bool()>& stop) {
      server::FillGapRequest request;
      request.space = "body";
      const int half = long_take.frame_count / 2;
      request.first = {long_take.clip_id, 0, half};
      request.second = {long_take.clip_id, half + 1, std::nullopt};
      if (gap_s > 0) request.gap_s = gap_s;
      request.overlap_s = overlap_s;
      return server::FillGap(edits, request, stop).status();
    };
  };
  edit_op("fill gap", "two halves of the take, a 400 s gap", halves(400, 0));
  edit_op("fill gap, aligned overlap", "two halves of the take, the longest overlap",
          halves(0, (options.query_frames - 1) / 30.0));
  edit_op("blend", "2 poses, a 50,001-frame path", [&](const std::function<bool()>& stop) {
    server::BlendRequest request;
    request.space = "body";
    request.poses = {{{long_take.clip_id, 0, 0}, 0, 0}, {{long_take.clip_id, 500, 500}, 1, 0}};
    request.path = {{0, 0}, {1, 1}};
    request.path.resize(6, {0.5, 0.5});
    request.frames_per_segment = 10000;
    return server::Blend(edits, request, stop).status();
  });
  edit_op("interpolate", "10,000 steps", [&](const std::function<bool()>& stop) {
    server::InterpolateRequest request;
    request.space = "body";
    request.from = {long_take.clip_id, 0, 0};
    request.to = {long_take.clip_id, 500, 500};
    request.options.steps = 10000;
    return server::Interpolate(edits, request, stop).status();
  });
  edit_op("pose model fit (EM)", take_input, [&](const std::function<bool()>& stop) {
    server::PoseModelRequest request;
    request.name = "bench_model";
    request.space = "body";
    request.examples = {take};
    request.options.components = 8;
    request.options.max_iterations = 10000;
    request.options.tolerance = 0;
    const absl::Status status = server::CreatePoseModel(edits, request, stop).status();
    if (status.ok()) return server::DeletePoseModel(edits, request.name, {});
    return status;
  });
  std::printf(
      "| operation | input | full run (ms) | runs past the deadline | overshoot p95 (ms) | "
      "max (ms) | ended before the deadline |\n|---|---|---:|---:|---:|---:|---:|\n");
  std::mt19937_64 random(37);
  for (const Operation& op : operations) {
    if (!options.only.empty() && !absl::StrContains(op.name, options.only)) continue;
    MOTIONDB_RETURN_IF_ERROR(Measure(op, options.repetitions, random));
  }
  return absl::OkStatus();
}

}  // namespace
}  // namespace motiondb

int main(int argc, char** argv) {
  CLI::App app("How long past a deadline each long operation returns (issue 37).");
  motiondb::Options options;
  app.add_option("--hours", options.hours, "hours of synthetic capture at 30 fps")
      ->capture_default_str();
  app.add_option("--query-frames", options.query_frames, "the query's frames (the limit)")
      ->capture_default_str();
  app.add_option("--repetitions", options.repetitions, "stopped runs per operation")
      ->capture_default_str();
  app.add_option("--only", options.only, "only the operations whose name holds this");
  app.add_option("--db", options.db, "the library's database (made when missing)");
  app.add_flag("--memory", options.memory,
               "measure the server's peak memory by query length instead");
  if (const std::optional<int> exit_code = motiondb::cli::ParseCommandLine(app, argc, argv)) {
    return *exit_code;
  }
  const absl::Status status = motiondb::Run(options);
  if (!status.ok()) {
    std::fprintf(stderr, "deadline_overshoot: %s\n", std::string(status.message()).c_str());
    return 1;
  }
  return 0;
}
