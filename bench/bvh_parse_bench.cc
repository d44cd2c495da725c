// BVH parse throughput (issue 2): motiondb::ReadBvh against a naive std::istringstream parser on
// the same in-memory texts, in the same run, so that the ratio holds whatever the machine.
//
// The texts are every .bvh under $MOTIONDB_MOCAP_DIR/bandai2-normal (default: the build's
// MOTIONDB_MOCAP_DIR, ../shared/mocap beside the checkout). Without that folder the program
// prints why and exits 0, as the corpus is not part of the repository.
#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "bench/measure.h"
#include "benchmark/benchmark.h"
#include "core/bvh/bvh_reader.h"

namespace {

struct Corpus {
  std::vector<std::string> texts;
  int64_t bytes = 0;
  int64_t frames = 0;
};

// Loaded once in main(), before any benchmark runs, so file I/O is never timed.
Corpus& TheCorpus() {
  static Corpus corpus;
  return corpus;
}

// The baseline a hand-written parser would start from: formatted extraction from a stream.
// It tokenises the hierarchy only to count channels and converts nothing but the frame values,
// so it does strictly less work than ReadBvh (no validation, no quaternions). Returns the
// number of frame rows read.
int64_t NaiveIstreamParse(const std::string& text, std::vector<double>& values) {
  std::istringstream in(text);
  std::string token;
  int64_t channels = 0;
  while (in >> token && token != "MOTION") {
    if (token == "CHANNELS") {
      int count = 0;
      in >> count;
      channels += count;
    }
  }
  int64_t header_frames = 0;
  double frame_time = 0.0;
  in >> token >> header_frames;        // "Frames:" N
  in >> token >> token >> frame_time;  // "Frame" "Time:" T
  values.clear();
  values.reserve(static_cast<size_t>(std::max<int64_t>(header_frames * channels, 0)));
  double value = 0.0;
  while (in >> value) values.push_back(value);
  benchmark::DoNotOptimize(frame_time);
  return channels > 0 ? static_cast<int64_t>(values.size()) / channels : 0;
}

// Both benchmarks report the same two rates: bytes/s from SetBytesProcessed, and frames/s.
void ReportRates(benchmark::State& state, const Corpus& corpus) {
  state.SetBytesProcessed(state.iterations() * corpus.bytes);
  state.counters["frames/s"] = benchmark::Counter(
      static_cast<double>(state.iterations() * corpus.frames), benchmark::Counter::kIsRate);
  state.counters["files"] = static_cast<double>(corpus.texts.size());
}

void BM_ReadBvh(benchmark::State& state) {
  const Corpus& corpus = TheCorpus();
  for (auto _ : state) {
    for (const std::string& text : corpus.texts) {
      absl::StatusOr<motiondb::BvhReadResult> result = motiondb::ReadBvh(text);
      if (!result.ok()) {
        state.SkipWithError(std::string(result.status().message()).c_str());
        return;
      }
      benchmark::DoNotOptimize(result->clip.rotations().data());
    }
  }
  ReportRates(state, corpus);
}

// As an IngestClipStream receives it: each file in 64 KiB pieces (BvhStreamReader).
void BM_ReadBvhInPieces(benchmark::State& state) {
  const Corpus& corpus = TheCorpus();
  constexpr size_t kPiece = 64 * 1024;
  for (auto _ : state) {
    for (const std::string& text : corpus.texts) {
      motiondb::BvhStreamReader reader;
      absl::Status appended = absl::OkStatus();
      for (size_t at = 0; at < text.size() && appended.ok(); at += kPiece) {
        appended = reader.Append(absl::string_view(text).substr(at, kPiece));
      }
      absl::StatusOr<motiondb::BvhReadResult> result = reader.Finish();
      if (!result.ok()) {
        state.SkipWithError(std::string(result.status().message()).c_str());
        return;
      }
      benchmark::DoNotOptimize(result->clip.rotations().data());
    }
  }
  ReportRates(state, corpus);
}

void BM_NaiveIstreamBaseline(benchmark::State& state) {
  const Corpus& corpus = TheCorpus();
  std::vector<double> values;
  for (auto _ : state) {
    for (const std::string& text : corpus.texts) {
      benchmark::DoNotOptimize(NaiveIstreamParse(text, values));
      benchmark::DoNotOptimize(values.data());
    }
  }
  ReportRates(state, corpus);
}

// One thread each (the default): the target is throughput on one core. An iteration parses the
// whole corpus (hundreds of milliseconds), hence the unit.
BENCHMARK(BM_ReadBvh)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ReadBvhInPieces)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_NaiveIstreamBaseline)->Unit(benchmark::kMillisecond);

// Reads the corpus into memory and checks that both parsers see the same frames, so that the
// two rates are comparable. Returns false (after saying why) when there is nothing to measure.
bool LoadCorpus(const std::filesystem::path& dir, Corpus& corpus) {
  std::error_code error;
  if (!std::filesystem::is_directory(dir, error)) {
    std::cout << "bvh_parse_bench: " << dir.string()
              << " not found; set MOTIONDB_MOCAP_DIR to the shared mocap folder. Skipping.\n";
    return false;
  }
  std::vector<std::filesystem::path> paths;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.is_regular_file() && entry.path().extension() == ".bvh") {
      paths.push_back(entry.path());
    }
  }
  std::sort(paths.begin(), paths.end());  // a stable order from run to run
  if (paths.empty()) {
    std::cout << "bvh_parse_bench: no .bvh files in " << dir.string() << ". Skipping.\n";
    return false;
  }
  std::vector<double> values;
  for (const auto& path : paths) {
    std::ifstream in(path, std::ios::binary);
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    absl::StatusOr<motiondb::BvhReadResult> result = motiondb::ReadBvh(text);
    if (!result.ok()) {
      std::cerr << "bvh_parse_bench: " << path.string() << ": " << result.status() << "\n";
      std::exit(1);
    }
    const int64_t frames = result->clip.frame_count();
    if (NaiveIstreamParse(text, values) != frames) {
      std::cerr << "bvh_parse_bench: " << path.string()
                << ": the naive baseline reads a different frame count than ReadBvh\n";
      std::exit(1);
    }
    corpus.bytes += static_cast<int64_t>(text.size());
    corpus.frames += frames;
    corpus.texts.push_back(std::move(text));
  }
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  const std::filesystem::path dir = motiondb::bench::MocapRoot() / "bandai2-normal";
  if (!LoadCorpus(dir, TheCorpus())) return 0;
  const Corpus& corpus = TheCorpus();
  std::cout << "bvh_parse_bench: " << corpus.texts.size() << " files, " << corpus.bytes
            << " bytes, " << corpus.frames << " frames from " << dir.string() << "\n";
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
