#include "tests/fuzz/fuzz_library.h"

#include <stdlib.h>

#include <cstdio>
#include <filesystem>
#include <string>

#include <google/protobuf/stubs/logging.h>

#include "absl/strings/str_cat.h"
#include "testing/synthetic_corpus.h"

namespace motiondb::fuzz {
namespace {

using testing::GenerateSyntheticCorpus;
using testing::SyntheticAction;
using testing::SyntheticCorpus;
using testing::SyntheticCorpusOptions;

[[noreturn]] void Die(const absl::Status& status) {
  std::fprintf(stderr, "fuzz library: %s\n", status.ToString().c_str());
  std::abort();
}

std::string FreshFolder() {
  const std::filesystem::path base = std::filesystem::is_directory("/dev/shm")
                                         ? std::filesystem::path("/dev/shm")
                                         : std::filesystem::temp_directory_path();
  std::string pattern = (base / "motiondb_fuzz_XXXXXX").string();
  if (::mkdtemp(pattern.data()) == nullptr) Die(absl::InternalError("mkdtemp failed"));
  return pattern;
}

// The three actions of the libraries, each `repeats` times, at 30 frames a second.
SyntheticCorpusOptions ThreeActions(int repeats) {
  SyntheticCorpusOptions options;
  options.fps = 30;
  options.script = {{SyntheticAction::kRightArmRaise, repeats},
                    {SyntheticAction::kLeftArmRaise, repeats},
                    {SyntheticAction::kShrug, repeats}};
  return options;
}

FuzzLibrary* Make(const SyntheticCorpusOptions& options) {
  // Random bytes make protobuf log every string field that is not UTF-8: noise, and slow.
  google::protobuf::SetLogHandler(nullptr);
  auto library = new FuzzLibrary;
  library->path = FreshFolder() + "/fuzz.sqlite";
  absl::StatusOr<std::unique_ptr<storage::Database>> database =
      storage::Database::Open(library->path);
  if (!database.ok()) Die(database.status());
  library->database = *std::move(database);
  library->catalog = std::make_unique<server::Catalog>(*library->database, library->registry);
  absl::StatusOr<SyntheticCorpus> corpus = GenerateSyntheticCorpus(options);
  if (!corpus.ok()) Die(corpus.status());
  for (size_t c = 0; c < corpus->clips.size(); ++c) {
    storage::ClipRecord record;
    record.name = absl::StrCat("clip_", c);
    record.tags = {c % 2 == 0 ? "even" : "odd"};
    if (absl::Status status = library->catalog->IngestClip(record, corpus->clips[c]).status();
        !status.ok()) {
      Die(status);
    }
  }
  server::SpaceRequest space;
  space.name = "body";
  if (absl::Status status = library->catalog->CreateSpace(space, [] { return false; }).status();
      !status.ok()) {
    Die(status);
  }
  return library;
}

}  // namespace

FuzzLibrary& TheFuzzLibrary() {
  static FuzzLibrary* const library = [] {
    SyntheticCorpusOptions options = ThreeActions(2);
    options.max_clip_duration_s = 8;
    return Make(options);
  }();
  return *library;
}

FuzzLibrary& TheSmallFuzzLibrary() {
  static FuzzLibrary* const library = [] {
    // Short rests and no stretched actions, so that a clip of 4 s holds any action.
    SyntheticCorpusOptions options = ThreeActions(1);
    options.rest_max_s = options.rest_min_s;
    options.timing_scale_max = 1.0;
    options.max_clip_duration_s = 4;
    return Make(options);
  }();
  return *library;
}

void CheckNotInternal(const absl::Status& status, const char* what) {
  if (status.code() != absl::StatusCode::kInternal && status.code() != absl::StatusCode::kUnknown) {
    return;
  }
  std::fprintf(stderr, "%s answered %s\n", what, status.ToString().c_str());
  std::abort();
}

}  // namespace motiondb::fuzz
