// Pose pipeline throughput (issue 3): joint quaternions at the space rate -> facing removal and
// yaw rate -> pose vectors -> projection onto every dimension of a space, for 22-joint Bandai
// clips. The batched path (what MotionSpace::ProjectClip runs: whole clips as n x d blocks and
// one matrix product) is measured beside the unbatched per-frame path (one frame at a time,
// a vector-matrix product per frame) in the same run, so that the ratio holds whatever the
// machine.
//
// The clips are every .bvh under $MOTIONDB_MOCAP_DIR/bandai2-normal (default: the build's
// MOTIONDB_MOCAP_DIR, ../shared/mocap beside the checkout), already at the space's 30 Hz. Without
// that folder the program prints why and exits 0, as the corpus is not part of the repository.
#include <cstdint>
#include <filesystem>
#include <iostream>
#include <optional>
#include <vector>

#include "bench/measure.h"
#include "benchmark/benchmark.h"
#include "core/bvh/bvh_reader.h"
#include "core/motion/resample.h"
#include "core/space/heading.h"
#include "core/space/motion_space.h"
#include "core/space/pose_encoder.h"

namespace motiondb {
namespace {

struct Corpus {
  std::vector<Clip> clips;  // at the space rate
  int64_t frames = 0;
  std::optional<MotionSpace> space;
};

// Loaded once in main(), before any benchmark runs, so file I/O is never timed.
Corpus& TheCorpus() {
  static Corpus corpus;
  return corpus;
}

std::filesystem::path BandaiDir() { return bench::MocapRoot() / "bandai2-normal"; }

bool LoadCorpus() {
  const std::filesystem::path dir = BandaiDir();
  std::error_code error;
  if (!std::filesystem::is_directory(dir, error)) {
    std::cerr << "pose_pipeline_bench: " << dir.string()
              << " is absent; nothing to measure (the corpus is not part of the repository)\n";
    return false;
  }
  Corpus& corpus = TheCorpus();
  std::vector<TrainingClip> training;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.path().extension() != ".bvh") continue;
    absl::StatusOr<BvhReadResult> read = ReadBvhFile(entry.path().string());
    if (!read.ok()) {
      std::cerr << "pose_pipeline_bench: " << read.status() << "\n";
      return false;
    }
    training.push_back({entry.path().filename().string(), read->clip, std::nullopt});
    corpus.clips.push_back(*Resample(read->clip, SpaceOptions().sample_rate));
    corpus.frames += corpus.clips.back().frame_count();
  }
  absl::StatusOr<MotionSpace> space = MotionSpace::Build(training);
  if (!space.ok()) {
    std::cerr << "pose_pipeline_bench: " << space.status() << "\n";
    return false;
  }
  corpus.space.emplace(*std::move(space));
  std::cerr << "pose_pipeline_bench: " << corpus.clips.size() << " clips, " << corpus.frames
            << " frames, " << corpus.space->skeleton().joint_count() << " joints, "
            << corpus.space->dims() << " dimensions\n";
  return true;
}

// The benchmarks' argument: how many leading dimensions to project onto, 0 for all of them.
int Dims(const benchmark::State& state) {
  return state.range(0) == 0 ? TheCorpus().space->dims() : static_cast<int>(state.range(0));
}

void SetCounters(benchmark::State& state) {
  state.counters["dims"] = Dims(state);
  state.counters["frames_per_second"] = benchmark::Counter(
      static_cast<double>(TheCorpus().frames), benchmark::Counter::kIsIterationInvariantRate);
}

// Whole clips as blocks: one facing pass, one linearisation pass, one matrix product.
void BM_PosePipelineBatched(benchmark::State& state) {
  const Corpus& corpus = TheCorpus();
  const MotionSpace& space = *corpus.space;
  const int dims = Dims(state);
  for (auto _ : state) {
    for (const Clip& clip : corpus.clips) {
      const PoseRotations pose = ComputePoseRotations(clip, space.data().pose);
      absl::StatusOr<RowMatrixXd> coordinates =
          space.Project(EncodePoses(pose, space.data().references), dims);
      benchmark::DoNotOptimize(coordinates->data());
    }
  }
  SetCounters(state);
}

// The same steps one frame at a time: the facing of one row, a log map per joint into a pose
// vector, then (once the yaw rates are known, as they need neighbouring frames) one
// vector-matrix product per frame.
void BM_PosePipelinePerFrame(benchmark::State& state) {
  const Corpus& corpus = TheCorpus();
  const SpaceData& data = corpus.space->data();
  const RowMatrixXd basis = data.basis.leftCols(Dims(state));
  const Eigen::RowVectorXd weights = corpus.space->pose_weights().transpose();
  const Eigen::RowVectorXd mean = data.mean.transpose();
  const int joints = data.skeleton->joint_count();
  std::vector<Quat> references;
  for (int j = 0; j < joints; ++j) {
    references.emplace_back(data.references(j, 0), data.references(j, 1), data.references(j, 2),
                            data.references(j, 3));
  }
  for (auto _ : state) {
    for (const Clip& clip : corpus.clips) {
      const int frames = clip.frame_count();
      std::vector<Eigen::RowVectorXd> poses(frames, Eigen::RowVectorXd(weights.size()));
      Eigen::VectorXd yaw(frames);
      for (int f = 0; f < frames; ++f) {
        RowMatrixXd row = clip.rotations().row(f);
        yaw[f] = RemoveHeading(*data.skeleton, &row)[0];
        for (int j = 0; j < joints; ++j) {
          const Quat q(row(0, 4 * j), row(0, 4 * j + 1), row(0, 4 * j + 2), row(0, 4 * j + 3));
          poses[f].segment<3>(3 * j) = LogMapAbout(q, references[j]).transpose();
        }
      }
      const Eigen::VectorXd rate = YawRate(yaw, clip.fps(), data.pose.yaw_rate_window);
      for (int f = 0; f < frames; ++f) {
        poses[f][3 * joints] = rate[f];
        const Eigen::RowVectorXd point = (poses[f].cwiseProduct(weights) - mean) * basis;
        benchmark::DoNotOptimize(point.data());
      }
    }
  }
  SetCounters(state);
}

// The public entry point a server calls at ingestion: adds the topology check and resampling
// (here from 30 Hz to 30 Hz, which copies) to the batched path.
void BM_ProjectClip(benchmark::State& state) {
  const Corpus& corpus = TheCorpus();
  const int dims = Dims(state);
  for (auto _ : state) {
    for (const Clip& clip : corpus.clips) {
      absl::StatusOr<RowMatrixXd> coordinates = corpus.space->ProjectClip(clip, dims);
      benchmark::DoNotOptimize(coordinates->data());
    }
  }
  SetCounters(state);
}

// All 67 dimensions, and the first 10 (a search's usual truncation).
BENCHMARK(BM_PosePipelineBatched)->Arg(0)->Arg(10)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_PosePipelinePerFrame)->Arg(0)->Arg(10)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ProjectClip)->Arg(0)->Arg(10)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace motiondb

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (!motiondb::LoadCorpus()) return 0;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
