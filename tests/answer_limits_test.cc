// Issue 37, deliverable 1: every answer bounded before it is made. In process: the BVH writer in
// pieces and its bound, storage's batched frame reads, and each of the application's calls whose
// answer grows with its request, at a lowered answer limit: the largest request the limit
// admits succeeds with its answer (as the gRPC face converts it) within the limit, and one step
// beyond is refused with RESOURCE_EXHAUSTED naming the limit and its flag, before the work
// (nothing stored). answer_limits_server_test.cc takes the same limits through the real server.
#include <filesystem>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "absl/strings/str_cat.h"
#include "core/bvh/bvh_writer.h"
#include "server/answer_limit.h"
#include "server/catalog.h"
#include "server/clip_export.h"
#include "server/clip_poses.h"
#include "server/edit/blends.h"
#include "server/edit/curves.h"
#include "server/edit/pose_models.h"
#include "server/edit/provenance.h"
#include "server/edit/reconstruct.h"
#include "server/edit/transitions.h"
#include "server/grpc/clip_conversion.h"
#include "server/grpc/edit_conversion.h"
#include "server/grpc/search_conversion.h"
#include "server/grpc/space_conversion.h"
#include "server/label_catalog.h"
#include "server/listing.h"
#include "server/search_runner.h"
#include "server/space_curve.h"
#include "storage/database.h"
#include "tests/synthetic_motion.h"
#include "tests/test_data.h"
#include "util/decimal_text.h"

namespace motiondb::server {
namespace {

using ::testing::HasSubstr;

constexpr double kFps = 60.0;  // the clips' rate; the space's is 30, so answers resample
constexpr int kFrames = 600;

const std::function<bool()> kNever = [] { return false; };

Clip Take(int seed) {
  return testing::SyntheticClip(
      testing::HumanoidSkeleton(/*still_root=*/false),
      {.frames = kFrames, .fps = kFps, .turn_rate = 0.2 * seed, .seed = seed});
}

// ---------------------------------------------------------------------------------------------
// The BVH writer in pieces.

TEST(BvhStreamWriter, PiecesJoinedAreWriteBvhsTextHoweverBatched) {
  const Clip clip = Take(1);
  for (const FrameRange range : {FrameRange{0, kFrames - 1}, FrameRange{17, 433}}) {
    const absl::StatusOr<std::string> whole = WriteBvh(clip, range, 2);
    ASSERT_TRUE(whole.ok()) << whole.status();
    for (const int batch : {1, 7, 128, 5000}) {
      BvhStreamWriter writer(clip.shared_skeleton(), 2);
      std::string text = writer.Header(range.size(), clip.frame_time());
      for (int first = range.first; first <= range.last; first += batch) {
        const FrameRange piece{first, std::min(range.last, first + batch - 1)};
        ASSERT_TRUE(writer.AppendRows(clip, piece, text).ok());
      }
      EXPECT_EQ(text, *whole) << "batches of " << batch;
    }
  }
}

TEST(BvhStreamWriter, RefusesFramesOfAnotherSkeleton) {
  BvhStreamWriter writer(testing::HumanoidSkeleton(/*still_root=*/true));
  std::string text;
  EXPECT_EQ(writer.AppendRows(Take(1), std::nullopt, text).code(),
            absl::StatusCode::kInvalidArgument);
}

// Positions at the longest text a number takes: the bound holds, and is met by the rows'
// position values.
TEST(BvhTextBound, HoldsTheLongestNumbers) {
  const Clip take = Take(2);
  RowMatrixXd positions = take.positions();
  positions.setConstant(-1.23456789012e-100);
  const absl::StatusOr<Clip> clip =
      Clip::Create(take.shared_skeleton(), take.frame_time(), take.rotations(), positions);
  ASSERT_TRUE(clip.ok());
  const absl::StatusOr<std::string> text = WriteBvh(*clip);
  ASSERT_TRUE(text.ok());
  EXPECT_LE(static_cast<int64_t>(text->size()), BvhTextBound(clip->skeleton(), kFrames));
  EXPECT_EQ(static_cast<int>(std::string("-1.23456789012e-100").size()), kLongestDecimal12Text);
  // Only the values of a row vary: the bound grows by the same row for each frame.
  EXPECT_EQ(BvhTextBound(clip->skeleton(), kFrames) - BvhTextBound(clip->skeleton(), 100),
            (kFrames - 100) * BvhRowBound(clip->skeleton()));
}

// ---------------------------------------------------------------------------------------------
// A library of two takes, a space, labels and a pose model, shared by the suite.

struct Library {
  std::filesystem::path dir;
  std::unique_ptr<storage::Database> database;
  IndexRegistry registry;
  std::unique_ptr<Catalog> catalog;
  std::vector<int64_t> ids;
};

Library* library = nullptr;

// The largest n in [lo, hi) whose probe is admitted, every n up to it admitted (OK) and every n
// from it refused (RESOURCE_EXHAUSTED): found by bisection, then both sides probed again, the
// refusal's message checked.
int LargestAdmitted(int lo, int hi, const std::function<absl::Status(int)>& probe) {
  EXPECT_TRUE(probe(lo).ok()) << "n = " << lo << ": " << probe(lo);
  EXPECT_EQ(probe(hi).code(), absl::StatusCode::kResourceExhausted) << "n = " << hi;
  while (hi - lo > 1) {
    const int mid = lo + (hi - lo) / 2;
    const absl::Status status = probe(mid);
    EXPECT_TRUE(status.ok() || absl::IsResourceExhausted(status))
        << "n = " << mid << ": " << status;
    (status.ok() ? lo : hi) = mid;
  }
  EXPECT_TRUE(probe(lo).ok());
  const absl::Status beyond = probe(lo + 1);
  EXPECT_EQ(beyond.code(), absl::StatusCode::kResourceExhausted);
  EXPECT_THAT(beyond.message(), HasSubstr("more than the server's answer limit of "));
  EXPECT_THAT(beyond.message(), HasSubstr("(--max-answer-mb)"));
  return lo;
}

template <typename T>
absl::StatusOr<T> Converted(absl::StatusOr<T> value) {
  return value;
}
template <typename T>
absl::StatusOr<T> Converted(T value) {
  return value;
}

// Runs an application call the way its gRPC service does (request converted from the proto,
// answer converted to it) and checks an admitted answer against the limit.
template <typename Response, typename ProtoRequest, typename Call>
absl::Status Serve(const ProtoRequest& proto, int64_t limit, const Call& call) {
  auto request = Converted(FromProto(proto));
  if (!request.ok()) return request.status();
  auto outcome = call(*request);
  if (!outcome.ok()) return outcome.status();
  Response response;
  ToProto(*std::move(outcome), &response);
  EXPECT_LE(static_cast<int64_t>(response.ByteSizeLong()), limit)
      << Response::descriptor()->name() << " past the limit";
  return absl::OkStatus();
}

v1::ClipRange Range(int index, int first, int last) {
  v1::ClipRange range;
  range.set_clip_id(library->ids[index]);
  range.set_first_frame(first);
  range.set_last_frame(last);
  return range;
}

int64_t ClipCount() { return library->database->GetCounts()->clips; }

int64_t ClipByName(const std::string& name) {
  const absl::StatusOr<storage::ClipRecord> record = library->database->GetClipRecordByName(name);
  EXPECT_TRUE(record.ok()) << record.status();
  return record.ok() ? record->clip_id : 0;
}

class AnswerLimitTest : public ::testing::Test {
 protected:
  // A BVH answer's limit: a few hundred of the humanoid's rows beside the fixed part.
  static constexpr int64_t kLimit = kAnswerFixedBytes + (int64_t{300} << 10);

  static void SetUpTestSuite() {
    library = new Library;
    library->dir = testing::MakeTempDir("answer_limits_test");
    auto opened = storage::Database::Open((library->dir / "library.sqlite").string());
    ASSERT_TRUE(opened.ok()) << opened.status();
    library->database = *std::move(opened);
    library->catalog = std::make_unique<Catalog>(*library->database, library->registry);
    for (int seed = 1; seed <= 2; ++seed) {
      storage::ClipRecord record;
      record.name = absl::StrCat("take", seed);
      record.source_file = record.name + ".bvh";
      const absl::StatusOr<IngestedClip> ingested =
          library->catalog->IngestClip(record, Take(seed));
      ASSERT_TRUE(ingested.ok()) << ingested.status();
      library->ids.push_back(ingested->record.clip_id);
    }
    SpaceRequest space;
    space.name = "body";
    ASSERT_TRUE(library->catalog->CreateSpace(space, kNever).ok());
  }
  static void TearDownTestSuite() {
    std::filesystem::remove_all(library->dir);
    delete library;
    library = nullptr;
  }

  static EditContext Context(int64_t limit) {
    return EditContext{.database = *library->database,
                       .catalog = *library->catalog,
                       .registry = library->registry,
                       .answers = AnswerLimit(limit)};
  }
};

// ---------------------------------------------------------------------------------------------
// Storage's batched reads.

TEST_F(AnswerLimitTest, ClipFramesReadInBatchesAreTheStoredFrames) {
  storage::Database& database = *library->database;
  const int64_t id = library->ids[0];
  const FrameRange range{5, 412};
  const absl::StatusOr<storage::StoredClip> stored = database.GetClip(id, range);
  ASSERT_TRUE(stored.ok());
  for (const int batch : {1, 64, 1000}) {
    int next = 0;
    const Skeleton* shared = nullptr;  // one skeleton for every batch
    ASSERT_TRUE(database
                    .ReadClipFrames(
                        id, range, batch,
                        [&](const Clip& piece) {
                          EXPECT_LE(piece.frame_count(), batch);
                          if (shared == nullptr) shared = &piece.skeleton();
                          EXPECT_EQ(&piece.skeleton(), shared);
                          for (int f = 0; f < piece.frame_count(); ++f, ++next) {
                            EXPECT_EQ(piece.rotations().row(f), stored->clip.rotations().row(next));
                            EXPECT_EQ(piece.positions().row(f), stored->clip.positions().row(next));
                          }
                          return absl::OkStatus();
                        })
                    .ok());
    EXPECT_EQ(next, range.size());
  }
  // The consumer's error ends the read; a bad range or clip is refused before any batch.
  int batches = 0;
  EXPECT_EQ(database
                .ReadClipFrames(id, range, 10,
                                [&](const Clip&) {
                                  ++batches;
                                  return absl::CancelledError("enough");
                                })
                .code(),
            absl::StatusCode::kCancelled);
  EXPECT_EQ(batches, 1);
  const auto none = [](const Clip&) { return absl::InternalError("no batch expected"); };
  EXPECT_EQ(database.ReadClipFrames(id, {0, kFrames}, 10, none).code(),
            absl::StatusCode::kOutOfRange);
  EXPECT_EQ(database.ReadClipFrames(4242, {0, 1}, 10, none).code(), absl::StatusCode::kNotFound);
  EXPECT_EQ(database.ReadClipFrames(id, {0, 1}, 0, none).code(),
            absl::StatusCode::kInvalidArgument);
}

// ---------------------------------------------------------------------------------------------
// Exports.

TEST_F(AnswerLimitTest, ExportIsRefusedPastTheLimitAndStreamsAnySize) {
  const int64_t id = library->ids[0];
  ExportFormat format = ExportFormat::kBvh;
  int64_t limit = kLimit;
  const auto probe = [&](int frames) {
    v1::ClipRange range = Range(0, 0, frames - 1);
    absl::StatusOr<ExportedFile> exported =
        ExportClip(*library->database, FromProto(range), format, AnswerLimit(limit), kNever);
    if (!exported.ok()) return exported.status();
    v1::ExportClipResponse response;
    ToProto(*std::move(exported), &response);
    EXPECT_LE(static_cast<int64_t>(response.ByteSizeLong()), limit);
    return absl::OkStatus();
  };
  const int admitted = LargestAdmitted(1, kFrames, probe);
  const absl::Status refused =
      ExportClip(*library->database, {id, 0, admitted}, format, AnswerLimit(kLimit), kNever)
          .status();
  EXPECT_THAT(refused.message(), HasSubstr("ExportClipStream"));
  // The bound is an upper bound, not a wild one: the largest text admitted takes a good part
  // of the limit.
  const absl::StatusOr<ExportedFile> largest =
      ExportClip(*library->database, {id, 0, admitted - 1}, format, AnswerLimit(kLimit), kNever);
  ASSERT_TRUE(largest.ok());
  EXPECT_GE(static_cast<int64_t>(largest->bytes.size()), (kLimit - kAnswerFixedBytes) / 2);

  // A glTF file is made whole, streamed or not: both are bounded, the bound not a wild one. Its
  // binary numbers are terser than BVH text: a limit of half the whole clip's file.
  format = ExportFormat::kGlb;
  const absl::StatusOr<ExportedFile> whole_glb = ExportClip(
      *library->database, {id, std::nullopt, std::nullopt}, format, AnswerLimit(), kNever);
  ASSERT_TRUE(whole_glb.ok()) << whole_glb.status();
  limit = kAnswerFixedBytes + static_cast<int64_t>(whole_glb->bytes.size()) / 2;
  const int admitted_glb = LargestAdmitted(1, kFrames, probe);
  const absl::StatusOr<ExportedFile> largest_glb =
      ExportClip(*library->database, {id, 0, admitted_glb - 1}, format, AnswerLimit(limit), kNever);
  ASSERT_TRUE(largest_glb.ok());
  EXPECT_GE(static_cast<int64_t>(largest_glb->bytes.size()), (limit - kAnswerFixedBytes) / 2);
  const absl::Status streamed_glb = StreamClipExport(
      *library->database, {id, 0, admitted_glb}, format, AnswerLimit(limit),
      [](ExportedFile) { return absl::OkStatus(); }, kNever);
  EXPECT_EQ(streamed_glb.code(), absl::StatusCode::kResourceExhausted) << streamed_glb;

  // The stream's pieces: the header with the file name first, then rows of at most a piece's
  // bytes, joined the stored clip's WriteBvh text; the unary export is the same text.
  const absl::StatusOr<storage::StoredClip> stored = library->database->GetClip(id);
  ASSERT_TRUE(stored.ok());
  const absl::StatusOr<std::string> expected = WriteBvh(stored->clip);
  ASSERT_TRUE(expected.ok());
  std::string streamed;
  std::vector<ExportedFile> pieces;
  ASSERT_TRUE(StreamClipExport(
                  *library->database, {id, std::nullopt, std::nullopt}, ExportFormat::kBvh,
                  AnswerLimit(kLimit),
                  [&](ExportedFile piece) {
                    streamed += piece.bytes;
                    piece.bytes.resize(std::min<size_t>(piece.bytes.size(), 16));
                    pieces.push_back(std::move(piece));
                    return absl::OkStatus();
                  },
                  kNever)
                  .ok());
  EXPECT_EQ(streamed, *expected);
  ASSERT_GE(pieces.size(), 2u);
  EXPECT_EQ(pieces[0].file_name, "take1.bvh");
  EXPECT_EQ(pieces[0].frames.last, kFrames - 1);
  EXPECT_EQ(pieces[1].file_name, "");
  const absl::StatusOr<ExportedFile> whole =
      ExportClip(*library->database, {id, std::nullopt, std::nullopt}, ExportFormat::kBvh,
                 AnswerLimit(), kNever);
  ASSERT_TRUE(whole.ok());
  EXPECT_EQ(whole->bytes, *expected);
  // A range streams the range's text.
  std::string range_text;
  ASSERT_TRUE(StreamClipExport(
                  *library->database, {id, 100, 250}, ExportFormat::kBvh, AnswerLimit(),
                  [&](ExportedFile piece) {
                    range_text += piece.bytes;
                    return absl::OkStatus();
                  },
                  kNever)
                  .ok());
  EXPECT_EQ(range_text, *WriteBvh(stored->clip, FrameRange{100, 250}));
  // Stopped between pieces, and by the receiver.
  int calls = 0;
  const auto count = [&](ExportedFile) {
    ++calls;
    return absl::OkStatus();
  };
  EXPECT_EQ(StreamClipExport(*library->database, {id, std::nullopt, std::nullopt},
                             ExportFormat::kBvh, AnswerLimit(), count, [] { return true; })
                .code(),
            absl::StatusCode::kCancelled);
  EXPECT_EQ(calls, 1) << "the header only";
  EXPECT_EQ(StreamClipExport(
                *library->database, {id, std::nullopt, std::nullopt}, ExportFormat::kBvh,
                AnswerLimit(), [](ExportedFile) { return absl::CancelledError("gone"); }, kNever)
                .code(),
            absl::StatusCode::kCancelled);
}

TEST_F(AnswerLimitTest, PosesAndCurvesAreRefusedPastTheLimit) {
  constexpr int64_t kPosesLimit = kAnswerFixedBytes + (int64_t{40} << 10);
  const int poses = LargestAdmitted(1, kFrames, [&](int frames) {
    v1::GetClipPosesRequest request;
    *request.mutable_clip() = Range(0, 0, frames - 1);
    request.set_max_rate(0);  // the clip's own rate
    return Serve<v1::ClipPoses>(request, kPosesLimit, [&](const PosesRequest& converted) {
      return ReadClipPoses(*library->database, converted, AnswerLimit(kPosesLimit));
    });
  });
  // frames x joints x 3 float32 fill the limit.
  const int joints = testing::HumanoidSkeleton(false)->joint_count();
  EXPECT_NEAR(poses, (kPosesLimit - kAnswerFixedBytes) / (joints * 12.0), 4);

  constexpr int64_t kCurveLimit = kAnswerFixedBytes + (int64_t{2} << 10);
  LargestAdmitted(1, kFrames, [&](int frames) {
    v1::GetCurveRequest request;
    request.set_space("body");
    *request.mutable_clip() = Range(1, 0, frames - 1);
    request.set_dims(5);
    return Serve<v1::GetCurveResponse>(request, kCurveLimit, [&](const CurveRequest& converted) {
      return ReadCurve(library->registry, *library->database, converted, AnswerLimit(kCurveLimit));
    });
  });
}

// ---------------------------------------------------------------------------------------------
// Searches.

TEST_F(AnswerLimitTest, SearchesAreRefusedPastTheLimitBeforeTheySearch) {
  constexpr int64_t kSearchLimit = kAnswerFixedBytes + (int64_t{24} << 10);
  const SearchRunner runner(library->registry, *library->database, UploadLimits{});
  const AnswerLimit answers(kSearchLimit);
  const auto search = [&](int max_results, int64_t used, bool explain) {
    v1::SearchRequest request;
    request.set_space("body");
    *request.mutable_clip() = Range(0, 100, 159);
    request.set_max_results(max_results);
    request.set_return_path(true);
    request.set_explain(explain);
    return Serve<v1::SearchResponse>(request, kSearchLimit - used, [&](SearchRequest converted) {
      converted.answers = &answers;
      converted.answers_used = used;
      return runner.Run(converted, kNever);
    });
  };
  const int results = LargestAdmitted(1, 1000, [&](int n) { return search(n, 0, false); });
  // Explained results are larger; what a batch's earlier answers took counts.
  EXPECT_LT(LargestAdmitted(1, 1000, [&](int n) { return search(n, 0, true); }), results);
  EXPECT_LT(LargestAdmitted(1, 1000, [&](int n) { return search(n, 8 << 10, false); }), results);
  const absl::Status refused = search(results, 8 << 10, false);
  EXPECT_THAT(refused.message(), HasSubstr("with the batch's earlier answers"));
  // A job's searches (no limit given) are not refused.
  SearchRequest unlimited;
  unlimited.space = "body";
  unlimited.query = ClipSelection{library->ids[0], 100, 159};
  unlimited.params.max_results = 1000;
  unlimited.params.return_path = true;
  EXPECT_TRUE(runner.Run(unlimited, kNever).ok());
}

// ---------------------------------------------------------------------------------------------
// Labels: pages hold what the limit admits; a batch's answer is checked before it is stored.

TEST_F(AnswerLimitTest, LabelPagesHoldWhatTheLimitAdmitsAndBatchesAreRefusedPastIt) {
  constexpr int kPage = 7;
  const AnswerLimit answers(kAnswerFixedBytes + kPage * LabelAnswerBytes());
  ASSERT_EQ(answers.MostItems(LabelAnswerBytes()), kPage);
  std::vector<NewLabel> batch;
  for (int i = 0; i < 30; ++i) {
    batch.push_back(
        {.clip_id = library->ids[1], .first_frame = i, .last_frame = i + 5, .descriptor = "wave"});
  }
  // Admitted: a batch of a page; one more label is refused, and nothing is stored.
  const auto labels_now = [] { return library->database->GetCounts()->labels; };
  const int64_t before = labels_now();
  const std::vector<NewLabel> too_many(batch.begin(), batch.begin() + kPage + 1);
  const auto refused = AddLabels(*library->database, too_many, answers);
  EXPECT_EQ(refused.status().code(), absl::StatusCode::kResourceExhausted);
  EXPECT_THAT(refused.status().message(), HasSubstr("send at most 7 labels a call"));
  EXPECT_EQ(labels_now(), before);
  for (size_t first = 0; first < batch.size(); first += kPage) {
    const std::vector<NewLabel> page(batch.begin() + first,
                                     batch.begin() + std::min(batch.size(), first + kPage));
    ASSERT_TRUE(AddLabels(*library->database, page, answers).ok());
  }
  // Listings: a page_size of 1000 is read as the limit's page, and the pages hold every label.
  const auto read_all =
      [&](const std::function<absl::StatusOr<storage::LabelPage>(const PageRequest&)>& list) {
        int total = 0;
        PageRequest page{1000, ""};
        do {
          const absl::StatusOr<storage::LabelPage> read = list(page);
          EXPECT_TRUE(read.ok()) << read.status();
          if (!read.ok()) break;
          EXPECT_LE(static_cast<int>(read->labels.size()), kPage);
          total += static_cast<int>(read->labels.size());
          page.page_token = read->next_page_token;
        } while (!page.page_token.empty());
        return total;
      };
  EXPECT_EQ(read_all([&](const PageRequest& page) {
              return ListLabels(*library->database, page, {.clip_id = library->ids[1]}, answers);
            }),
            30);
  EXPECT_EQ(read_all([&](const PageRequest& page) {
              return FindLabels(*library->database, page, {.descriptor = "wave"}, answers);
            }),
            30);
  EXPECT_EQ(read_all([&](const PageRequest& page) -> absl::StatusOr<storage::LabelPage> {
              absl::StatusOr<ClipTimeline> timeline =
                  GetClipTimeline(*library->database, library->ids[1], page, answers);
              if (!timeline.ok()) return timeline.status();
              return storage::LabelPage{timeline->labels, timeline->next_page_token};
            }),
            30);
  // The timeline's pages are in its order: by first frame.
  const absl::StatusOr<ClipTimeline> first =
      GetClipTimeline(*library->database, library->ids[1], {0, ""}, AnswerLimit());
  ASSERT_TRUE(first.ok());
  ASSERT_EQ(first->labels.size(), 30u);
  EXPECT_EQ(first->labels[0].first_frame, 0);
  EXPECT_EQ(first->labels[29].first_frame, 29);
  ASSERT_TRUE(DeleteLabels(*library->database, {{}, {.clip_id = library->ids[1]}}).ok());
}

// An operator's clip's provenance holds its request, so a clip's record has no small bound: a
// listing's page ends before the clip whose text would take its answer past the limit.
TEST_F(AnswerLimitTest, ClipPagesHoldWhatTheLimitAdmits) {
  std::vector<int64_t> heavy;
  for (int i = 0; i < 4; ++i) {
    Provenance provenance{"blend", "body", {{library->ids[0], {0, 9}}, {library->ids[1], {0, 9}}}};
    provenance.parameters_json =
        absl::StrCat("{\"note\": \"", std::string(300 << 10, 'a' + i), "\"}");
    storage::ClipRecord record;
    record.name = absl::StrCat("heavy", i);
    record.source_file = record.name;
    record.provenance = ProvenanceJson(provenance);
    const absl::StatusOr<IngestedClip> ingested =
        library->catalog->IngestClip(record, Take(10 + i));
    ASSERT_TRUE(ingested.ok()) << ingested.status();
    heavy.push_back(ingested->record.clip_id);
  }
  const auto read_all = [](const AnswerLimit& answers, int* pages) {
    int64_t total = 0;
    ClipListRequest request;
    request.page = {1000, ""};
    *pages = 0;
    do {
      const absl::StatusOr<storage::ClipPage> page =
          ListClips(*library->database, request, answers);
      EXPECT_TRUE(page.ok()) << page.status();
      if (!page.ok()) break;
      v1::ListClipsResponse response;
      ToProto(*page, &response);
      EXPECT_LE(static_cast<int64_t>(response.ByteSizeLong()), answers.max_bytes());
      EXPECT_FALSE(page->clips.empty());
      total += static_cast<int64_t>(page->clips.size());
      ++*pages;
      request.page.page_token = page->next_page_token;
    } while (!request.page.page_token.empty());
    return total;
  };
  int pages = 0;
  // 1 MiB, the flag's least: the four heavy clips' 300 KiB provenances take four pages.
  EXPECT_EQ(read_all(AnswerLimit(int64_t{1} << 20), &pages), ClipCount());
  EXPECT_GE(pages, 4);
  EXPECT_EQ(read_all(AnswerLimit(), &pages), ClipCount());
  EXPECT_EQ(pages, 1);
  for (const int64_t id : heavy) ASSERT_TRUE(library->database->DeleteClip(id).ok());
}

// ---------------------------------------------------------------------------------------------
// The operators: each refused past the limit before it works, nothing stored.

TEST_F(AnswerLimitTest, CurveEditsAndReconstructionAreRefusedPastTheLimit) {
  const EditContext context = Context(kLimit);
  const int64_t clips = ClipCount();
  LargestAdmitted(2, kFrames, [&](int frames) {
    v1::ReconstructRequest request;
    request.set_space("body");
    *request.mutable_clip() = Range(0, 0, frames - 1);
    request.set_error_curve(true);
    return Serve<v1::ReconstructResponse>(request, kLimit, [&](const ReconstructRequest& r) {
      return Reconstruct(context, r, kNever);
    });
  });
  LargestAdmitted(2, kFrames, [&](int frames) {
    v1::ScaleRequest request;
    request.set_space("body");
    *request.mutable_clip() = Range(0, 0, frames - 1);
    request.mutable_output()->set_store_name("scaled");  // refused ones store nothing
    const absl::Status status = Serve<v1::EditResponse>(
        request, kLimit, [&](const ScaleRequest& r) { return Scale(context, r, kNever); });
    if (status.ok()) {
      EXPECT_TRUE(library->catalog->DeleteClip(ClipByName("scaled")).ok());
    }
    return status;
  });
  EXPECT_EQ(ClipCount(), clips);
  LargestAdmitted(2, kFrames, [&](int frames) {
    v1::TranslateRequest request;
    request.set_space("body");
    *request.mutable_clip() = Range(0, 0, frames - 1);
    *request.mutable_target() = Range(1, 10, 10);
    return Serve<v1::EditResponse>(
        request, kLimit, [&](const TranslateRequest& r) { return Translate(context, r, kNever); });
  });
  LargestAdmitted(2, kFrames, [&](int frames) {
    v1::SmoothRequest request;
    request.set_space("body");
    *request.mutable_clip() = Range(1, 0, frames - 1);
    return Serve<v1::EditResponse>(
        request, kLimit, [&](const SmoothRequest& r) { return Smooth(context, r, kNever); });
  });
}

TEST_F(AnswerLimitTest, BlendsAndInterpolationsAreRefusedPastTheLimit) {
  const EditContext context = Context(kLimit);
  // Frames from the path: two points and frames_per_segment between them.
  LargestAdmitted(1, 10000, [&](int per_segment) {
    v1::BlendRequest request;
    request.set_space("body");
    for (int i = 0; i < 2; ++i) {
      v1::PlanarPose* pose = request.add_poses();
      *pose->mutable_pose() = Range(i, 50 * (i + 1), 50 * (i + 1));
      pose->set_x(i);
    }
    request.add_path()->set_x(0);
    request.add_path()->set_x(1);
    request.set_frames_per_segment(per_segment);
    return Serve<v1::BlendResponse>(
        request, kLimit, [&](const BlendRequest& r) { return Blend(context, r, kNever); });
  });
  // Two BVH answers, a frame a step.
  LargestAdmitted(2, 10000, [&](int steps) {
    v1::InterpolateRequest request;
    request.set_space("body");
    *request.mutable_from() = Range(0, 30, 30);
    *request.mutable_to() = Range(1, 90, 90);
    request.set_steps(steps);
    return Serve<v1::InterpolateResponse>(request, kLimit, [&](const InterpolateRequest& r) {
      return Interpolate(context, r, kNever);
    });
  });
  // A count over its fixed maximum is INVALID_ARGUMENT naming the field, not the limit.
  v1::InterpolateRequest request;
  request.set_space("body");
  *request.mutable_from() = Range(0, 30, 30);
  *request.mutable_to() = Range(1, 90, 90);
  request.set_steps(10001);
  const absl::Status status = Serve<v1::InterpolateResponse>(
      request, kLimit,
      [&](const InterpolateRequest& r) { return Interpolate(context, r, kNever); });
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(status.message(), HasSubstr("steps"));
}

TEST_F(AnswerLimitTest, GapsAndOverlapsAreRefusedPastTheLimit) {
  const EditContext context = Context(kLimit);
  // The gap's frames at the space's 30 fps, between two 10-frame ranges.
  LargestAdmitted(1, 3000, [&](int gap_frames) {
    v1::FillGapRequest request;
    request.set_space("body");
    *request.mutable_first() = Range(0, 0, 9);
    *request.mutable_second() = Range(1, 0, 9);
    request.set_gap_s(gap_frames / 30.0);
    return Serve<v1::FillGapResponse>(
        request, kLimit, [&](const FillGapRequest& r) { return FillGap(context, r, kNever); });
  });
  LargestAdmitted(40, kFrames, [&](int frames) {
    v1::FillGapRequest request;
    request.set_space("body");
    *request.mutable_first() = Range(0, 0, frames - 1);
    *request.mutable_second() = Range(1, 0, 19);
    request.set_overlap_s(0.25);
    return Serve<v1::FillGapResponse>(
        request, kLimit, [&](const FillGapRequest& r) { return FillGap(context, r, kNever); });
  });
}

TEST_F(AnswerLimitTest, PoseModelsAndDetectionsAreRefusedPastTheLimit) {
  const EditContext unlimited = Context(AnswerLimit().max_bytes());
  v1::CreatePoseModelRequest create;
  create.set_name("limit-pose");
  create.set_space("body");
  *create.add_examples() = Range(0, 40, 60);
  create.set_components(1);
  ASSERT_TRUE(
      Serve<v1::PoseModel>(create, AnswerLimit().max_bytes(), [&](const PoseModelRequest& r) {
        return CreatePoseModel(unlimited, r, kNever);
      }).ok());
  // A detection's curve and intervals grow with the range.
  constexpr int64_t kDetectLimit = kAnswerFixedBytes + (int64_t{6} << 10);
  const EditContext context = Context(kDetectLimit);
  LargestAdmitted(1, kFrames, [&](int frames) {
    v1::DetectPoseRequest request;
    request.set_model("limit-pose");
    *request.mutable_clip() = Range(1, 0, frames - 1);
    return Serve<v1::DetectPoseResponse>(
        request, kDetectLimit, [&](const DetectRequest& r) { return DetectPose(context, r, {}); });
  });
  // A model's answer holds its request: its examples grow it.
  constexpr int64_t kModelLimit = kAnswerFixedBytes + (int64_t{4} << 10);
  const EditContext small = Context(kModelLimit);
  LargestAdmitted(1, 1000, [&](int examples) {
    v1::CreatePoseModelRequest request = create;
    request.set_name(absl::StrCat("limit-pose-", examples));
    request.clear_examples();
    for (int i = 0; i < examples; ++i) *request.add_examples() = Range(0, 40, 60);
    const absl::Status status = Serve<v1::PoseModel>(
        request, kModelLimit,
        [&](const PoseModelRequest& r) { return CreatePoseModel(small, r, kNever); });
    if (status.ok()) {
      EXPECT_TRUE(DeletePoseModel(small, request.name(), kNever).ok());
    }
    return status;
  });
}

}  // namespace
}  // namespace motiondb::server
