// The operators' figures (issue 16) on real capture: pose detection's precision and recall over
// a labelled folder, MC-LERP against SLERP, smoothing of noisy clips by level, and the seams of
// Hermite gap filling against linear. Not part of the test suite; numbers in
// bench/notes/2026-12-05-curve-operators.md and bench/RESULTS.md's table.
//
// usage: ops_measurements detect|interpolate|smooth|gap [--folder DIR] [options]
//        ops_measurements speed [--calls N] [--fps F] [--only TEXT]  (every operator through a
//        server; --only "Scale" times one call alone, e.g. under a profiler; DetectPose needs
//        CreatePoseModel's model, so keep them together: --only Pose)
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <tuple>
#include <vector>

#include <signal.h>
#include <unistd.h>

#include "absl/strings/match.h"
#include "bench/call_context.h"
#include "bench/measure.h"
#include "core/bvh/bvh_reader.h"
#include "core/bvh/bvh_writer.h"
#include "core/motion/resample.h"
#include "core/ops/gap_fill.h"
#include "core/ops/interpolation.h"
#include "core/ops/pose_detection.h"
#include "core/ops/pose_model.h"
#include "core/ops/reconstruction.h"
#include "core/ops/space_motion.h"
#include "core/ops/wavelet_smoothing.h"
#include "motiondb/v1/clip_service.grpc.pb.h"
#include "motiondb/v1/edit_service.grpc.pb.h"
#include "motiondb/v1/space_service.grpc.pb.h"
#include "testing/ops_evaluation.h"
#include "testing/server_process.h"
#include "util/cli_conventions.h"
#include "util/file_io.h"
#include "util/status_macros.h"

namespace motiondb {
namespace {

using testing::LabelledMotions;

// The evaluation of testing/ops_evaluation.h, and how well the clips' best log-likelihoods (held
// for min_frames frames) would separate the label at the best threshold in hindsight.
absl::Status Detect(const LabelledMotions& library,
                    const testing::DetectionEvaluationOptions& options) {
  MOTIONDB_ASSIGN_OR_RETURN(const testing::DetectionEvaluation evaluation,
                            testing::EvaluatePoseDetection(library, options));
  std::vector<std::pair<double, bool>> best;
  int positives = 0;
  for (size_t i = 0; i < library.motions.size(); ++i) {
    if (evaluation.example[i]) continue;  // as the evaluation: the clips the model has not seen
    const Eigen::VectorXd ll = PoseLogLikelihood(evaluation.model, library.motions[i].coordinates);
    double held = -std::numeric_limits<double>::infinity();
    for (Eigen::Index k = 0; k + options.min_frames <= ll.size(); ++k) {
      held = std::max(held, ll.segment(k, options.min_frames).minCoeff());
    }
    best.push_back({held, library.labels[i] == options.label});
    positives += best.back().second;
  }
  std::sort(best.begin(), best.end(),
            [](const auto& a, const auto& b) { return a.first > b.first; });
  double best_f = 0, best_p = 0, best_r = 0;
  int tp = 0, total = 0;
  for (const auto& [score, positive] : best) {
    tp += positive;
    const double p = static_cast<double>(tp) / ++total, r = static_cast<double>(tp) / positives;
    if (2 * p * r / (p + r) > best_f)
      std::tie(best_f, best_p, best_r) = std::tuple(2 * p * r / (p + r), p, r);
  }
  std::printf("model: %d example poses, %d dims, k %d, threshold %.3f\n", evaluation.example_poses,
              evaluation.model.dims, static_cast<int>(evaluation.model.weights.size()),
              evaluation.model.threshold);
  const int example_clips =
      static_cast<int>(std::count(evaluation.example.begin(), evaluation.example.end(), true));
  std::printf("example clips: %d, of which %d fired; the other %zu clips:\n", example_clips,
              evaluation.examples_fired, evaluation.example.size() - example_clips);
  std::printf(
      "precision %.3f (%d of %d fired), recall %.3f (%d of %d); best threshold in "
      "hindsight: precision %.3f, recall %.3f\n",
      evaluation.precision(), evaluation.true_positives, evaluation.fired, evaluation.recall(),
      evaluation.true_positives, evaluation.positives, best_p, best_r);
  for (const auto& [label, counts] : evaluation.by_label) {
    std::printf("  %-22s fired on %3d of %3d\n", label.c_str(), counts.first, counts.second);
  }
  return absl::OkStatus();
}

double MeanAngle(const RowMatrixXd& a, const RowMatrixXd& b) {
  AngleError error;
  AngleErrors(a, b, nullptr, &error);
  return error.mean_rad;
}

absl::Status Interpolate(const LabelledMotions& library, int pairs) {
  std::mt19937_64 generator(16);
  const auto pick = [&](RowMatrixXd* coordinates, RowMatrixXd* rotations) {
    const size_t clip = generator() % library.motions.size();
    const SpaceMotion& motion = library.motions[clip];
    const Eigen::Index frame = static_cast<Eigen::Index>(generator() % motion.coordinates.rows());
    coordinates->conservativeResize(coordinates->rows() + 1, motion.coordinates.cols());
    coordinates->bottomRows(1) = motion.coordinates.row(frame);
    rotations->conservativeResize(rotations->rows() + 1, motion.rotations.cols());
    rotations->bottomRows(1) = motion.rotations.row(frame);
  };
  struct Sample {
    double apart, from_origin, mean, max, distance;
  };
  std::vector<Sample> samples;
  for (int n = 0; n < pairs; ++n) {
    RowMatrixXd poses(0, library.space->dims()), rotations(0, library.motions[0].rotations.cols());
    pick(&poses, &rotations);
    pick(&poses, &rotations);
    MOTIONDB_ASSIGN_OR_RETURN(const Interpolation result,
                              InterpolatePoses(*library.space, poses, rotations));
    AngleError apart;
    AngleErrors(rotations.row(0), rotations.row(1), nullptr, &apart);
    samples.push_back({apart.mean_rad, 0.5 * (poses.row(0).norm() + poses.row(1).norm()),
                       result.difference[5].mean_rad, result.overall.max_rad,
                       result.curve_distance[5]});
  }
  // Quartiles of the pairs' distance from the space's origin (the training mean pose).
  std::sort(samples.begin(), samples.end(),
            [](const Sample& a, const Sample& b) { return a.from_origin < b.from_origin; });
  std::printf("%d random pose pairs, 11 steps each (t = 0.5 for the midpoint columns)\n", pairs);
  std::printf(
      "quartile | |p| mean | pair apart (mean rad) | midpoint MC-LERP vs SLERP mean rad | "
      "max rad over t | midpoint curve distance\n");
  for (int q = 0; q < 4; ++q) {
    const size_t first = samples.size() * q / 4, last = samples.size() * (q + 1) / 4;
    Sample sum{0, 0, 0, 0, 0};
    double worst = 0;
    for (size_t i = first; i < last; ++i) {
      sum.apart += samples[i].apart;
      sum.from_origin += samples[i].from_origin;
      sum.mean += samples[i].mean;
      sum.distance += samples[i].distance;
      worst = std::max(worst, samples[i].max);
    }
    const double n = static_cast<double>(last - first);
    std::printf("%d | %.3f | %.4f | %.5f | %.4f | %.5f\n", q + 1, sum.from_origin / n,
                sum.apart / n, sum.mean / n, worst, sum.distance / n);
  }
  return absl::OkStatus();
}

absl::Status Smooth(const LabelledMotions& library, int clips, double sigma) {
  std::mt19937_64 generator(5);
  const std::vector<double> levels = {0, 0.5, 1, 1.5, 2, 2.5, 3, 4};
  std::vector<double> noisy_error(levels.size(), 0.0), clean_error(levels.size(), 0.0);
  int used = 0;
  for (size_t i = 0; i < library.clips.size() && used < clips; i += library.clips.size() / clips) {
    const SpaceMotion& clean = library.motions[i];
    MOTIONDB_ASSIGN_OR_RETURN(
        const SpaceMotion noisy,
        EnterSpace(*library.space, testing::WithRotationNoise(library.clips[i], sigma, generator)));
    for (size_t l = 0; l < levels.size(); ++l) {
      for (const auto& [source, sum] :
           {std::pair{&noisy, &noisy_error[l]}, {&clean, &clean_error[l]}}) {
        MOTIONDB_ASSIGN_OR_RETURN(const RowMatrixXd smoothed,
                                  SmoothCurve(source->coordinates, {.level = levels[l]}));
        MOTIONDB_ASSIGN_OR_RETURN(const RowMatrixXd rotations,
                                  library.space->Reconstruct(smoothed));
        *sum += MeanAngle(rotations, clean.rotations);
      }
    }
    ++used;
  }
  std::printf("%d clips with noise of %.3f rad per joint and frame; error to the clean clip\n",
              used, sigma);
  std::printf("level | noisy clip smoothed (mean rad) | clean clip smoothed (mean rad)\n");
  for (size_t l = 0; l < levels.size(); ++l) {
    std::printf("%.1f | %.4f | %.4f\n", levels[l], noisy_error[l] / used, clean_error[l] / used);
  }
  return absl::OkStatus();
}

// Seam jumps of a joined curve, and its error to `truth` over the gap when given.
struct GapFigures {
  double jump = 0, gap_error = 0;
};

absl::StatusOr<GapFigures> Join(const LabelledMotions& library, const SpaceMotion& a,
                                const SpaceMotion& b, const GapFillOptions& options,
                                const RowMatrixXd* truth) {
  MOTIONDB_ASSIGN_OR_RETURN(const RowMatrixXd gap, FillGap(a.coordinates, b.coordinates, options));
  RowMatrixXd curve(a.coordinates.rows() + gap.rows() + b.coordinates.rows(), gap.cols());
  curve << a.coordinates, gap, b.coordinates;
  MOTIONDB_ASSIGN_OR_RETURN(const RowMatrixXd rotations, library.space->Reconstruct(curve));
  GapFigures figures;
  const int na = static_cast<int>(a.coordinates.rows());
  const double rate = library.space->sample_rate();
  figures.jump = 0.5 * (VelocityJump(rotations, na - 1, rate).mean_rad +
                        VelocityJump(rotations, na + options.frames, rate).mean_rad);
  if (truth != nullptr) {
    figures.gap_error = MeanAngle(rotations.middleRows(na, options.frames), *truth);
  }
  return figures;
}

absl::Status Gap(const LabelledMotions& library, int frames) {
  const std::vector<std::pair<std::string, GapFillOptions>> methods = {
      {"linear", {.frames = frames, .method = GapMethod::kLinear}},
      {"hermite v=1", {.frames = frames}},
      {"hermite v=0.5", {.frames = frames, .damping = 0.5}},
      {"hermite v=1, derivatives after smoothing level 1",
       {.frames = frames, .derivative_smoothing = 1}}};
  std::vector<GapFigures> within(methods.size()), between(methods.size());
  int cut = 0, joined = 0;
  const int keep = 15;  // frames kept on each side of a cut
  for (size_t i = 0; i < library.motions.size(); ++i) {
    const SpaceMotion& m = library.motions[i];
    const int n = static_cast<int>(m.coordinates.rows());
    const size_t next = (i + library.motions.size() / 2) % library.motions.size();
    for (size_t k = 0; k < methods.size(); ++k) {
      if (n >= 2 * keep + frames) {  // a gap cut out of one clip: the truth is known
        const int start = (n - frames) / 2;
        SpaceMotion a, b;
        a.coordinates = m.coordinates.middleRows(start - keep, keep);
        b.coordinates = m.coordinates.middleRows(start + frames, keep);
        const RowMatrixXd truth = m.rotations.middleRows(start, frames);
        MOTIONDB_ASSIGN_OR_RETURN(const GapFigures f,
                                  Join(library, a, b, methods[k].second, &truth));
        within[k].jump += f.jump;
        within[k].gap_error += f.gap_error;
        cut += k == 0;
      }
      // The end of this clip to the start of another, of another content.
      MOTIONDB_ASSIGN_OR_RETURN(
          const GapFigures f,
          Join(library, library.motions[i], library.motions[next], methods[k].second, nullptr));
      between[k].jump += f.jump;
      joined += k == 0;
    }
  }
  std::printf(
      "gap of %d frames (%.2f s); jump = joint angular velocity change at a seam, mean of "
      "both seams, mean over joints (rad/s)\n",
      frames, frames / library.space->sample_rate());
  std::printf(
      "method | cut out of a clip (%d): jump | error to the removed frames (mean rad) | "
      "between two clips (%d): jump\n",
      cut, joined);
  for (size_t k = 0; k < methods.size(); ++k) {
    std::printf("%s | %.3f | %.4f | %.3f\n", methods[k].first.c_str(), within[k].jump / cut,
                within[k].gap_error / cut, between[k].jump / joined);
  }
  return absl::OkStatus();
}

// --- speed through the server ------------------------------------------------------------

v1::ClipRange Range(int64_t clip, int first, int last) {
  v1::ClipRange range;
  range.set_clip_id(clip);
  range.set_first_frame(first);
  range.set_last_frame(last);
  return range;
}

// `calls` timed calls of `call` after 5 untimed ones: the median and p95 in ms.
absl::StatusOr<std::pair<double, double>> Time(int calls,
                                               const std::function<grpc::Status()>& call) {
  std::vector<double> ms;
  for (int k = 0; k < calls + 5; ++k) {
    const bench::Clock::time_point start = bench::Clock::now();
    const grpc::Status status = call();
    if (!status.ok()) return absl::InternalError(status.error_message());
    if (k >= 5) ms.push_back(1000 * bench::SecondsSince(start));
  }
  return std::make_pair(bench::Percentile(ms, 0.5), bench::Percentile(ms, 0.95));
}

std::unique_ptr<grpc::ClientContext> Context() {
  return bench::ContextWithin(std::chrono::seconds(120));
}

// The clip the speed measurements edit: its id and how many frames make 10 s.
struct TenSeconds {
  int64_t id;
  int frames;
};

// Ingests `file` (resampled to `fps` first when positive) and creates the space "body".
absl::StatusOr<TenSeconds> IngestForSpeed(v1::ClipService::Stub& clips,
                                          v1::SpaceService::Stub& spaces, const std::string& file,
                                          int calls, double fps) {
  MOTIONDB_ASSIGN_OR_RETURN(std::string bvh, ReadFileBytes(file, int64_t{1} << 30));
  if (fps > 0) {  // the file resampled first, as `motiondb convert --fps` would
    MOTIONDB_ASSIGN_OR_RETURN(const BvhReadResult read, ReadBvh(bvh));
    MOTIONDB_ASSIGN_OR_RETURN(const Clip resampled, Resample(read.clip, fps));
    MOTIONDB_ASSIGN_OR_RETURN(bvh, WriteBvh(resampled));
  }
  v1::IngestClipRequest ingest;
  ingest.set_file_name(std::filesystem::path(file).filename().string());
  ingest.set_bvh(bvh);
  v1::IngestClipResponse ingested;
  if (!clips.IngestClip(Context().get(), ingest, &ingested).ok())
    return absl::InternalError("ingest");
  const TenSeconds ten{ingested.clip().clip_id(),
                       static_cast<int>(std::lround(10 * ingested.clip().fps()))};
  v1::CreateSpaceRequest create;
  create.set_name("body");
  v1::Space space;
  if (!spaces.CreateSpace(Context().get(), create, &space).ok())
    return absl::InternalError("space");
  std::printf("%s: %d frames at %.1f fps; 10 s ranges of %d frames; %d calls each\n",
              ingest.file_name().c_str(), ingested.clip().frame_count(), ingested.clip().fps(),
              ten.frames, calls);
  return ten;
}

using TimedCall = std::pair<std::string, std::function<grpc::Status()>>;

// Every operator on 10 s of `clip`, beside ExportClip and GetCurve of the same range.
std::vector<TimedCall> OperatorCalls(v1::ClipService::Stub* clips, v1::SpaceService::Stub* spaces,
                                     v1::EditService::Stub* edits, const TenSeconds& clip) {
  const int64_t id = clip.id;
  const int frames = clip.frames;
  const v1::ClipRange ten = Range(id, 0, frames - 1), later = Range(id, frames, 2 * frames - 1);
  // Two 5 s ranges, joined into about 10 s.
  const v1::ClipRange half = Range(id, 0, frames / 2 - 1),
                      other_half = Range(id, frames, frames + frames / 2 - 1);
  std::vector<TimedCall> runs;
  runs.push_back({"ExportClip (baseline)", [=] {
                    v1::ExportClipRequest r;
                    *r.mutable_clip() = ten;
                    v1::ExportClipResponse o;
                    return clips->ExportClip(Context().get(), r, &o);
                  }});
  runs.push_back({"GetCurve, 3 dims (baseline)", [=] {
                    v1::GetCurveRequest r;
                    r.set_space("body");
                    *r.mutable_clip() = ten;
                    v1::GetCurveResponse o;
                    return spaces->GetCurve(Context().get(), r, &o);
                  }});
  runs.push_back({"Reconstruct, 10 dims", [=] {
                    v1::ReconstructRequest r;
                    r.set_space("body");
                    *r.mutable_clip() = ten;
                    r.set_dims(10);
                    v1::ReconstructResponse o;
                    return edits->Reconstruct(Context().get(), r, &o);
                  }});
  runs.push_back({"Interpolate, means of two 10 s ranges, 11 t", [=] {
                    v1::InterpolateRequest r;
                    r.set_space("body");
                    *r.mutable_from() = ten;
                    *r.mutable_to() = later;
                    v1::InterpolateResponse o;
                    return edits->Interpolate(Context().get(), r, &o);
                  }});
  runs.push_back({"Blend, 3 poses, a 10 s path", [=] {
                    v1::BlendRequest r;
                    r.set_space("body");
                    for (int i = 0; i < 3; ++i) {
                      v1::PlanarPose* p = r.add_poses();
                      *p->mutable_pose() = Range(id, 100 * i, 100 * i);
                      p->set_x(i);
                      p->set_y(i % 2);
                    }
                    r.add_path();
                    r.add_path()->set_x(2);
                    r.set_frames_per_segment(300);
                    v1::BlendResponse o;
                    return edits->Blend(Context().get(), r, &o);
                  }});
  runs.push_back({"FillGap, 5 s each side, 0.5 s Hermite", [=] {
                    v1::FillGapRequest r;
                    r.set_space("body");
                    *r.mutable_first() = half;
                    *r.mutable_second() = other_half;
                    v1::FillGapResponse o;
                    return edits->FillGap(Context().get(), r, &o);
                  }});
  runs.push_back({"FillGap, 5 s each side, 0.5 s overlap warped", [=] {
                    v1::FillGapRequest r;
                    r.set_space("body");
                    *r.mutable_first() = half;
                    *r.mutable_second() = other_half;
                    r.set_overlap_s(0.5);
                    v1::FillGapResponse o;
                    return edits->FillGap(Context().get(), r, &o);
                  }});
  runs.push_back({"Scale x1.5 about the mean, gated", [=] {
                    v1::ScaleRequest r;
                    r.set_space("body");
                    *r.mutable_clip() = ten;
                    r.set_factor(1.5);
                    r.set_centre(v1::SCALE_CENTRE_SELECTION_MEAN);
                    v1::Gate* g = r.mutable_scope()->mutable_gate();
                    g->set_start_s(2);
                    g->set_end_s(8);
                    g->set_lead_in_s(0.5);
                    g->set_lead_out_s(0.5);
                    v1::EditResponse o;
                    return edits->Scale(Context().get(), r, &o);
                  }});
  runs.push_back({"Translate toward a pose", [=] {
                    v1::TranslateRequest r;
                    r.set_space("body");
                    *r.mutable_clip() = ten;
                    *r.mutable_target() = Range(id, 2 * frames, 2 * frames);
                    v1::EditResponse o;
                    return edits->Translate(Context().get(), r, &o);
                  }});
  runs.push_back({"Smooth, level 1.5", [=] {
                    v1::SmoothRequest r;
                    r.set_space("body");
                    *r.mutable_clip() = ten;
                    r.set_level(1.5);
                    v1::EditResponse o;
                    return edits->Smooth(Context().get(), r, &o);
                  }});
  const auto model = std::make_shared<int>(0);
  runs.push_back({"CreatePoseModel, 10 s of examples, k 2", [=] {
                    v1::CreatePoseModelRequest r;
                    r.set_name("m" + std::to_string((*model)++));
                    r.set_space("body");
                    *r.add_examples() = ten;
                    v1::PoseModel o;
                    return edits->CreatePoseModel(Context().get(), r, &o);
                  }});
  runs.push_back({"DetectPose over 10 s", [=] {
                    v1::DetectPoseRequest r;
                    r.set_model("m0");
                    *r.mutable_clip() = later;
                    v1::DetectPoseResponse o;
                    return edits->DetectPose(Context().get(), r, &o);
                  }});
  return runs;
}

// Every operator on a 10 s range of `file` through a real server.
absl::Status Speed(const std::string& file, int calls, double fps, const std::string& only) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("ops_speed_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  testing::ServerProcess server;
  std::string error;
  if (!server.Start({"--db", (dir / "db.sqlite").string(), "--quiet"}, &error)) {
    return absl::InternalError(error);
  }
  const auto channel = testing::InsecureChannel(server.address());
  testing::WaitUntilServing(channel, "");
  auto clips = v1::ClipService::NewStub(channel);
  auto spaces = v1::SpaceService::NewStub(channel);
  auto edits = v1::EditService::NewStub(channel);
  MOTIONDB_ASSIGN_OR_RETURN(const TenSeconds clip,
                            IngestForSpeed(*clips, *spaces, file, calls, fps));
  std::printf("call | median ms | p95 ms\n");
  for (const auto& [name, call] : OperatorCalls(clips.get(), spaces.get(), edits.get(), clip)) {
    if (!absl::StrContains(name, only)) continue;
    MOTIONDB_ASSIGN_OR_RETURN(const auto times, Time(calls, call));
    std::printf("%s | %.2f | %.2f\n", name.c_str(), times.first, times.second);
  }
  server.Stop(SIGTERM);
  std::filesystem::remove_all(dir);
  return absl::OkStatus();
}

}  // namespace
}  // namespace motiondb

int main(int argc, char** argv) {
  using namespace motiondb;
  CLI::App app("operator figures on real capture", "ops_measurements");
  std::string folder = (bench::MocapRoot() / "bandai2-normal").string();
  std::string weights = "mass";
  SpaceOptions space;
  testing::DetectionEvaluationOptions detect;
  app.add_option("--folder", folder);
  cli::OneOf(app.add_option("--weights", weights, "the space's weights"),
             {"mass", "uniform", "arms"});
  CLI::App* d = app.add_subcommand("detect", "pose detection precision and recall");
  d->add_option("--label", detect.label);
  d->add_option("--examples", detect.examples);
  d->add_option("--window", detect.window);
  d->add_option("--stride", detect.stride);
  d->add_option("--min-frames", detect.min_frames);
  d->add_option("--dims", detect.model.dims);
  d->add_option("--components", detect.model.components);
  d->add_option("--quantile", detect.model.threshold_quantile);
  d->add_option("--regularization", detect.model.regularization);
  int pairs = 2000, clips = 60, gap_frames = 15;
  double sigma = 0.05;
  CLI::App* interpolate = app.add_subcommand("interpolate", "MC-LERP against SLERP");
  interpolate->add_option("--pairs", pairs);
  CLI::App* smooth = app.add_subcommand("smooth", "smoothing noisy clips, by level");
  smooth->add_option("--clips", clips);
  smooth->add_option("--sigma", sigma);
  CLI::App* gap = app.add_subcommand("gap", "Hermite gap filling against linear");
  gap->add_option("--frames", gap_frames);
  std::string speed_file = (bench::MocapRoot() / "cmu" / "01_01_3dsmax.bvh").string();
  int calls = 50;
  double speed_fps = 0;
  CLI::App* speed = app.add_subcommand("speed", "every operator on a 10 s range, through a server");
  speed->add_option("--file", speed_file);
  speed->add_option("--calls", calls);
  speed->add_option("--fps", speed_fps, "resample the file to this rate first (0: as it is)");
  std::string only;
  speed->add_option("--only", only, "time only the calls whose name holds this text");
  app.require_subcommand(1);
  CLI11_PARSE(app, argc, argv);
  if (speed->parsed()) {
    if (!std::filesystem::exists(speed_file)) {
      std::printf("ops_measurements: %s is absent; nothing measured\n", speed_file.c_str());
      return 0;
    }
    const absl::Status status = Speed(speed_file, calls, speed_fps, only);
    if (!status.ok()) std::fprintf(stderr, "%s\n", std::string(status.message()).c_str());
    return status.ok() ? 0 : 1;
  }
  if (!std::filesystem::is_directory(folder)) {
    std::printf("ops_measurements: %s is absent; nothing measured\n", folder.c_str());
    return 0;
  }
  if (weights == "uniform") space.weights.preset = WeightPreset::kUniform;
  if (weights == "arms") space = testing::ArmsSpace();
  const absl::StatusOr<LabelledMotions> library = testing::LoadLabelledMotions(folder, space);
  if (!library.ok()) {
    std::fprintf(stderr, "%s\n", std::string(library.status().message()).c_str());
    return 1;
  }
  absl::Status status = absl::OkStatus();
  if (d->parsed()) status = Detect(*library, detect);
  if (interpolate->parsed()) status = Interpolate(*library, pairs);
  if (smooth->parsed()) status = Smooth(*library, clips, sigma);
  if (gap->parsed()) status = Gap(*library, gap_frames);
  if (!status.ok()) {
    std::fprintf(stderr, "%s\n", std::string(status.message()).c_str());
    return 1;
  }
  return 0;
}
