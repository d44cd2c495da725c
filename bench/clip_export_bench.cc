// Where the time of exporting a 10 s range as BVH goes (issue 16's speed at 120 fps): the stored
// clip read and decoded from SQLite, the range's BVH written, the whole ExportClip in process,
// and its response message serialised and parsed back (the copies gRPC adds), on frames 0-1199
// of $MOTIONDB_MOCAP_DIR/cmu/01_01_3dsmax.bvh (2751 frames at 120 fps, 31 joints).
// `ops_measurements speed` times the same call through the server; the difference is gRPC's.
// Without the file the program prints why and exits 0, as the corpus is not in the repository.
#include <unistd.h>

#include <algorithm>
#include <charconv>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "bench/measure.h"
#include "benchmark/benchmark.h"
#include "core/bvh/bvh_reader.h"
#include "core/bvh/bvh_writer.h"
#include "core/motion/rotation.h"
#include "motiondb/v1/clip_service.pb.h"
#include "server/clip_export.h"
#include "storage/database.h"
#include "util/decimal_text.h"
#include "util/file_io.h"

namespace motiondb {
namespace {

constexpr int kRangeFrames = 1200;  // 10 s at 120 fps

struct Fixture {
  std::filesystem::path dir;
  std::unique_ptr<storage::Database> database;
  int64_t clip_id = 0;
  std::optional<Clip> clip;     // as stored and read back
  std::vector<double> numbers;  // the values of the range's BVH rows, as written
};

Fixture& TheFixture() {
  static Fixture fixture;
  return fixture;
}

void Fail(benchmark::State& state, const absl::Status& status) {
  state.SkipWithError(std::string(status.message()).c_str());
}

void ReportFrames(benchmark::State& state, int frames) {
  state.counters["frames/s"] = benchmark::Counter(static_cast<double>(state.iterations() * frames),
                                                  benchmark::Counter::kIsRate);
}

// The stored clip read and decoded: whole (arg 0, 2751 frames), as ExportClip and the operators
// read it before, or only the range (arg 1, 1200 frames), as they read it now.
void BM_GetClip(benchmark::State& state) {
  Fixture& fixture = TheFixture();
  const bool range = state.range(0) == 1;
  const std::optional<FrameRange> frames =
      range ? std::optional<FrameRange>(FrameRange{0, kRangeFrames - 1}) : std::nullopt;
  for (auto _ : state) {
    absl::StatusOr<storage::StoredClip> stored = fixture.database->GetClip(fixture.clip_id, frames);
    if (!stored.ok()) return Fail(state, stored.status());
    benchmark::DoNotOptimize(stored->clip.rotations().data());
  }
  ReportFrames(state, range ? kRangeFrames : fixture.clip->frame_count());
}

void BM_WriteBvh(benchmark::State& state) {
  const Clip& clip = *TheFixture().clip;
  int64_t bytes = 0;
  for (auto _ : state) {
    absl::StatusOr<std::string> text =
        WriteBvh(clip, FrameRange{0, kRangeFrames - 1}, static_cast<int>(state.range(0)));
    if (!text.ok()) return Fail(state, text.status());
    bytes = static_cast<int64_t>(text->size());
    benchmark::DoNotOptimize(text->data());
  }
  state.SetBytesProcessed(state.iterations() * bytes);
  ReportFrames(state, kRangeFrames);
}

// The writer's numbers formatted alone: with std::to_chars(general, 12), as WriteBvh did (arg
// 0), and with WriteDecimal12, which writes the same text (arg 1).
void BM_FormatNumbers(benchmark::State& state) {
  const std::vector<double>& numbers = TheFixture().numbers;
  const bool fast = state.range(0) == 1;
  std::string out;
  out.reserve(numbers.size() * 16);
  for (auto _ : state) {
    out.clear();
    for (const double value : numbers) {
      char buffer[kMaxDecimal12Chars];
      out.append(buffer, fast ? WriteDecimal12(buffer, value)
                              : std::to_chars(buffer, buffer + sizeof(buffer), value,
                                              std::chars_format::general, 12)
                                    .ptr);
      out += ' ';
    }
    benchmark::DoNotOptimize(out.data());
  }
  state.counters["numbers/s"] = benchmark::Counter(
      static_cast<double>(state.iterations() * numbers.size()), benchmark::Counter::kIsRate);
}

// WriteBvh's Euler decomposition alone: every joint of every frame of the range, continuous.
void BM_EulerDecomposition(benchmark::State& state) {
  const Clip& clip = *TheFixture().clip;
  const Skeleton& skeleton = clip.skeleton();
  std::vector<Eigen::Vector3d> previous(skeleton.joint_count());
  for (auto _ : state) {
    std::fill(previous.begin(), previous.end(), Eigen::Vector3d::Zero());
    for (int f = 0; f < kRangeFrames; ++f) {
      for (int j = 0; j < skeleton.joint_count(); ++j) {
        if (!skeleton.has_rotation(j)) continue;
        previous[j] =
            QuaternionToEuler(clip.rotation(f, j), skeleton.rotation_order(j), previous[j]);
      }
    }
    benchmark::DoNotOptimize(previous.data());
  }
  ReportFrames(state, kRangeFrames);
}

// server::ExportClip: the range read and decoded alone, its file (BVH, or binary glTF with
// the argument 1) and the file name.
void BM_ExportClip(benchmark::State& state) {
  Fixture& fixture = TheFixture();
  const server::ClipSelection range{fixture.clip_id, 0, kRangeFrames - 1};
  const server::ExportFormat format =
      state.range(0) == 1 ? server::ExportFormat::kGlb : server::ExportFormat::kBvh;
  for (auto _ : state) {
    absl::StatusOr<server::ExportedFile> exported = server::ExportClip(
        *fixture.database, range, format, server::AnswerLimit(), [] { return false; });
    if (!exported.ok()) return Fail(state, exported.status());
    benchmark::DoNotOptimize(exported->bytes.data());
  }
  ReportFrames(state, kRangeFrames);
}

// The response's own copies: the text into the message, serialised (the server) and parsed
// (the client).
void BM_ExportClipResponseCopies(benchmark::State& state) {
  Fixture& fixture = TheFixture();
  absl::StatusOr<server::ExportedFile> exported =
      server::ExportClip(*fixture.database, {fixture.clip_id, 0, kRangeFrames - 1},
                         server::ExportFormat::kBvh, server::AnswerLimit(), [] { return false; });
  if (!exported.ok()) return Fail(state, exported.status());
  std::string wire;
  for (auto _ : state) {
    v1::ExportClipResponse response;
    response.set_bvh(exported->bytes);
    response.SerializeToString(&wire);
    v1::ExportClipResponse received;
    if (!received.ParseFromString(wire)) return Fail(state, absl::DataLossError("parse"));
    benchmark::DoNotOptimize(received.bvh().data());
  }
  state.SetBytesProcessed(state.iterations() * static_cast<int64_t>(wire.size()));
}

BENCHMARK(BM_GetClip)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_WriteBvh)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FormatNumbers)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_EulerDecomposition)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ExportClip)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ExportClipResponseCopies)->Unit(benchmark::kMillisecond);

// Stores the file's clip in a fresh database in a temporary folder. False (after saying why)
// when there is nothing to measure.
bool SetUp(const std::filesystem::path& file, Fixture& fixture) {
  if (!std::filesystem::exists(file)) {
    std::cout << "clip_export_bench: " << file.string()
              << " not found; set MOTIONDB_MOCAP_DIR to the shared mocap folder. Skipping.\n";
    return false;
  }
  const auto fail = [](const absl::Status& status) {
    std::cerr << "clip_export_bench: " << status << "\n";
    std::exit(1);
  };
  absl::StatusOr<std::string> text = ReadFileBytes(file.string(), int64_t{1} << 30);
  if (!text.ok()) fail(text.status());
  absl::StatusOr<BvhReadResult> read = ReadBvh(*text);
  if (!read.ok()) fail(read.status());
  fixture.dir =
      std::filesystem::temp_directory_path() / ("clip_export_bench_" + std::to_string(::getpid()));
  std::filesystem::create_directories(fixture.dir);
  absl::StatusOr<std::unique_ptr<storage::Database>> database =
      storage::Database::Open((fixture.dir / "db.sqlite").string());
  if (!database.ok()) fail(database.status());
  fixture.database = *std::move(database);
  storage::ClipRecord record;
  record.name = file.stem().string();
  absl::StatusOr<int64_t> id = fixture.database->InsertClip(record, read->clip, {});
  if (!id.ok()) fail(id.status());
  fixture.clip_id = *id;
  absl::StatusOr<storage::StoredClip> stored = fixture.database->GetClip(*id);
  if (!stored.ok()) fail(stored.status());
  fixture.clip = std::move(stored->clip);
  if (fixture.clip->frame_count() < kRangeFrames) {
    std::cerr << "clip_export_bench: " << file.string() << " has fewer than " << kRangeFrames
              << " frames\n";
    std::exit(1);
  }
  absl::StatusOr<std::string> range = WriteBvh(*fixture.clip, FrameRange{0, kRangeFrames - 1});
  if (!range.ok()) fail(range.status());
  const char* p = range->data() + range->find("Frame Time:");
  p = std::strchr(p, '\n') + 1;
  for (const char* end = range->data() + range->size(); p < end;) {
    double value = 0;
    const std::from_chars_result parsed = std::from_chars(p, end, value);
    if (parsed.ec == std::errc()) {
      fixture.numbers.push_back(value);
      p = parsed.ptr;
    } else {
      ++p;  // a space or a line end
    }
  }
  return true;
}

}  // namespace
}  // namespace motiondb

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  const std::filesystem::path file = motiondb::bench::MocapRoot() / "cmu" / "01_01_3dsmax.bvh";
  motiondb::Fixture& fixture = motiondb::TheFixture();
  if (!motiondb::SetUp(file, fixture)) return 0;
  std::cout << "clip_export_bench: " << file.string() << ", " << fixture.clip->frame_count()
            << " frames at " << fixture.clip->fps() << " fps; the range: frames 0-"
            << motiondb::kRangeFrames - 1 << ", " << fixture.numbers.size() << " numbers\n";
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  fixture.database.reset();
  std::filesystem::remove_all(fixture.dir);
  return 0;
}
