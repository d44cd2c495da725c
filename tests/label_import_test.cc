// Label files and their import (issue 37 defect 9 and the "Also" items on CSV): export
// neutralises the cells a spreadsheet would run as formulas and import reads them back exactly,
// CSV records may hold quoted line breaks (errors name the line a record starts on), the reader
// holds one label at a time, and AddLabels stores a label once however often it is imported.
#include <sstream>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "absl/strings/str_cat.h"
#include "client/label_files.h"
#include "storage/database.h"
#include "storage/schema.h"
#include "storage/sqlite_connection.h"
#include "storage/sqlite_statement.h"
#include "tests/server_fixture.h"

namespace motiondb {
namespace {

using cli::LabelFile;
using cli::LabelFileFormat;
using ::testing::HasSubstr;
using ::testing::Not;

v1::Label StoredLabel(const std::string& clip, int first, int last, const std::string& descriptor,
                      double value) {
  v1::Label label;
  label.set_clip_name(clip);
  label.set_first_frame(first);
  label.set_last_frame(last);
  label.set_descriptor_name(descriptor);
  label.set_value(value);
  return label;
}

// The probe's descriptor =cmd|' /C calc'!A0 was written as a bare cell, which a spreadsheet
// runs. Cells beginning with = + - @ (or a tab or CR) are written after an apostrophe, and so
// is a text beginning with an apostrophe and one of those; import reads each back exactly.
TEST(LabelFiles, ExportNeutralisesFormulasAndImportReadsThemBackExactly) {
  const std::vector<std::string> texts = {"=cmd|' /C calc'!A0",
                                          "+1+1",
                                          "-2+3",
                                          "@SUM(A1:A2)",
                                          "=HYPERLINK(\"http://x\",\"y\")",
                                          "'=already quoted",
                                          "''",
                                          "'",
                                          "'plain",
                                          "kick, left",
                                          "it's",
                                          "=",
                                          "a=b",
                                          "walk-left"};
  std::vector<v1::Label> labels;
  for (size_t i = 0; i < texts.size(); ++i) {
    labels.push_back(StoredLabel(texts[i], 0, static_cast<int>(i), texts[i], 0.5));
  }
  const std::string csv = cli::FormatLabelFile(labels, LabelFileFormat::kCsv);
  EXPECT_THAT(csv, HasSubstr("\n'=cmd|' /C calc'!A0,0,0,'=cmd|' /C calc'!A0,0.5,frames\n"));
  EXPECT_THAT(csv, HasSubstr("\n'+1+1,0,1,'+1+1,"));
  EXPECT_THAT(csv, HasSubstr("\n'-2+3,"));
  EXPECT_THAT(csv, HasSubstr("\n'@SUM(A1:A2),"));
  EXPECT_THAT(csv, HasSubstr("\"'=HYPERLINK(\"\"http://x\"\",\"\"y\"\")\""));
  EXPECT_THAT(csv, HasSubstr("\n''=already quoted,"));
  EXPECT_THAT(csv, HasSubstr("\n''',"));
  EXPECT_THAT(csv, HasSubstr("\n',0,7,',0.5"));
  EXPECT_THAT(csv, HasSubstr("\n'plain,"));
  EXPECT_THAT(csv, HasSubstr("\na=b,"));
  EXPECT_THAT(csv, HasSubstr("\nwalk-left,"));
  // No line of it begins a cell with what starts a formula.
  for (const char* start : {"\n=", "\n+", "\n-", "\n@", ",=", ",+", ",-", ",@"}) {
    EXPECT_THAT(csv, Not(HasSubstr(start))) << start;
  }
  const absl::StatusOr<LabelFile> read = cli::ParseLabelFile(csv, LabelFileFormat::kCsv);
  ASSERT_TRUE(read.ok()) << read.status();
  ASSERT_EQ(read->labels.size(), texts.size());
  for (size_t i = 0; i < texts.size(); ++i) {
    EXPECT_EQ(read->labels[i].clip_name(), texts[i]);
    EXPECT_EQ(read->labels[i].descriptor_name(), texts[i]);
  }
  // JSON is no spreadsheet's: written and read as it is.
  const std::string json = cli::FormatLabelFile(labels, LabelFileFormat::kJson);
  EXPECT_THAT(json, HasSubstr("\"=cmd|' /C calc'!A0\""));
  const absl::StatusOr<LabelFile> from_json = cli::ParseLabelFile(json, LabelFileFormat::kJson);
  ASSERT_TRUE(from_json.ok()) << from_json.status();
  EXPECT_EQ(from_json->labels[0].descriptor_name(), texts[0]);
}

// RFC 4180: a quoted field may hold a line break. It was split as two lines, and the error
// named the wrong one; now the record is read whole and named by the line it starts on.
TEST(LabelFiles, QuotedLineBreaksAreReadAndErrorsNameTheLineTheRecordStartsOn) {
  const std::string text =
      "clip,start,end,descriptor,value\r\n"
      "walk,0,5,\"two\r\nlines\",1\r\n"        // lines 2-3
      "\r\n"                                   // line 4: blank
      "\"wa\nlk\",6,9,\"say \"\"hi\"\"\",1\n"  // lines 5-6
      "walk,1,2,step,x\n";                     // line 7
  const absl::StatusOr<LabelFile> read = cli::ParseLabelFile(text, LabelFileFormat::kCsv);
  ASSERT_FALSE(read.ok());
  EXPECT_EQ(read.status().message(), "line 7: value: 'x' is not a number");
  const std::string good = text.substr(0, text.rfind("walk,1,2"));
  const absl::StatusOr<LabelFile> labels = cli::ParseLabelFile(good, LabelFileFormat::kCsv);
  ASSERT_TRUE(labels.ok()) << labels.status();
  ASSERT_EQ(labels->labels.size(), 2u);
  EXPECT_EQ(labels->labels[0].descriptor_name(), "two\r\nlines");
  EXPECT_EQ(labels->places[0], "line 2");
  EXPECT_EQ(labels->labels[1].clip_name(), "wa\nlk");
  EXPECT_EQ(labels->labels[1].descriptor_name(), "say \"hi\"");
  EXPECT_EQ(labels->places[1], "line 5");
  // Written back, the line breaks are quoted again and read the same.
  std::vector<v1::Label> stored = {StoredLabel("wa\nlk", 6, 9, "two\r\nlines", 1)};
  const absl::StatusOr<LabelFile> again = cli::ParseLabelFile(
      cli::FormatLabelFile(stored, LabelFileFormat::kCsv), LabelFileFormat::kCsv);
  ASSERT_TRUE(again.ok()) << again.status();
  EXPECT_EQ(again->labels[0].clip_name(), "wa\nlk");
  EXPECT_EQ(again->labels[0].descriptor_name(), "two\r\nlines");

  // A quote left open is named by the line it opens on, not by the end of the file.
  const absl::StatusOr<LabelFile> open = cli::ParseLabelFile(
      "clip,start,end,descriptor,value\nwalk,0,1,a,1\nwalk,0,1,\"b,1\nwalk,0,1,c,1\n",
      LabelFileFormat::kCsv);
  EXPECT_EQ(open.status().message(), "line 3: a quoted field is not closed by the end of the file");
}

// A file is read a label at a time: `consume` sees each as the stream reaches it, and its
// error stops the reading there (a 1e6-row file took 1.66 GB in the CLI when read whole).
TEST(LabelFiles, TheReaderHandsOnOneLabelAtATimeAndStopsAtTheFirstError) {
  for (const LabelFileFormat format : {LabelFileFormat::kCsv, LabelFileFormat::kJson}) {
    std::string text = format == LabelFileFormat::kCsv ? "clip,start,end,descriptor,value\n" : "[";
    for (int i = 0; i < 50000; ++i) {
      absl::StrAppend(&text,
                      format == LabelFileFormat::kCsv
                          ? absl::StrCat("walk,", i, ",", i, ",step,1\n")
                          : absl::StrCat(i == 0 ? "" : ",", R"({"clip": "walk", "start": )", i,
                                         R"(, "end": )", i, R"(, "descriptor": "step"})"));
    }
    if (format == LabelFileFormat::kJson) text += "]";
    std::istringstream in(text);
    int seen = 0;
    std::streamoff read_when_first = -1;
    const absl::Status stopped =
        cli::ReadLabelFile(in, format, [&](cli::PlacedLabel placed) -> absl::Status {
          if (seen == 0) read_when_first = in.tellg();
          EXPECT_EQ(placed.label.first_frame(), seen);
          if (++seen == 3) return absl::CancelledError("enough");
          return absl::OkStatus();
        });
    EXPECT_EQ(stopped.code(), absl::StatusCode::kCancelled);
    EXPECT_EQ(seen, 3);
    // The first label came before the stream was read far (a buffer's worth at most).
    EXPECT_GE(read_when_first, 0);
    EXPECT_LT(read_when_first, std::streamoff{1} << 16);
  }
}

// Migration 6 widens labels_by_clip to what identifies a label, so that AddLabels' lookup for
// an identical one is a seek however many labels share a clip's first frame; a file of
// version 5 keeps its labels, and the lookup finds them.
TEST(LabelStorage, MigrationSixIndexesWhatIdentifiesALabel) {
  const std::filesystem::path dir = testing::MakeTempDir("label_storage");
  const std::string path = (dir / "labels.db").string();
  int64_t clip = 0;
  {
    absl::StatusOr<std::unique_ptr<storage::Database>> db = storage::Database::Open(path);
    ASSERT_TRUE(db.ok()) << db.status();
    storage::ClipRecord record;
    record.name = "chain";
    const absl::StatusOr<int64_t> inserted = (*db)->InsertClip(record, ChainClip(), {});
    ASSERT_TRUE(inserted.ok()) << inserted.status();
    clip = *inserted;
    storage::LabelRecord label;
    label.clip_id = clip;
    label.last_frame = 9;
    label.descriptor = "kick";
    ASSERT_TRUE((*db)->AddLabels({label}).ok());
  }
  {
    // The file as version 5 left it: migration 6's index as it was, migrations 7, 8 and 9's
    // tables gone.
    auto raw =
        storage::SqliteConnection::Open(path, storage::SqliteConnection::Mode::kReadWrite, 1000);
    ASSERT_TRUE(raw.ok()) << raw.status();
    ASSERT_TRUE((*raw)
                    ->Execute("DROP INDEX labels_by_clip; CREATE INDEX labels_by_clip ON labels "
                              "(clip_id, first_frame); DROP TABLE skeleton_slot_overrides; "
                              "DROP TABLE clip_sources; DROP TABLE space_skeletons; "
                              "PRAGMA user_version = 5")
                    .ok());
  }
  absl::StatusOr<std::unique_ptr<storage::Database>> db = storage::Database::Open(path);
  ASSERT_TRUE(db.ok()) << db.status();
  auto raw =
      storage::SqliteConnection::Open(path, storage::SqliteConnection::Mode::kReadWrite, 1000);
  ASSERT_TRUE(raw.ok()) << raw.status();
  EXPECT_EQ(*(*raw)->QueryInt64("PRAGMA user_version"), storage::LatestSchemaVersion());
  EXPECT_EQ(*(*raw)->QueryInt64("SELECT count(*) FROM pragma_index_info('labels_by_clip')"), 5);
  absl::StatusOr<storage::SqliteStatement> plan = (*raw)->Prepare(
      "EXPLAIN QUERY PLAN SELECT label_id FROM labels WHERE clip_id = 1 AND first_frame = 0 AND "
      "last_frame = 9 AND descriptor = 'kick' AND value = 1 AND origin = 'manual' AND "
      "source_label_id IS NULL");
  ASSERT_TRUE(plan.ok()) << plan.status();
  ASSERT_TRUE(*plan->Step());
  EXPECT_THAT(plan->ColumnText(3), HasSubstr("USING INDEX labels_by_clip (clip_id=? AND "
                                             "first_frame=? AND last_frame=? AND descriptor=? "
                                             "AND value=?)"));
  storage::LabelRecord again;
  again.clip_id = clip;
  again.last_frame = 9;
  again.descriptor = "kick";
  const absl::StatusOr<storage::AddedLabels> added = (*db)->AddLabels({again, again});
  ASSERT_TRUE(added.ok()) << added.status();
  EXPECT_THAT(added->skipped, ::testing::ElementsAre(0, 1));
  plan = absl::CancelledError("closed");
  raw->reset();
  db->reset();
  std::filesystem::remove_all(dir);
}

class LabelImportTest : public ServerTest {
 protected:
  // Runs the CLI against `server`.
  testing::CommandResult Cli(const testing::ServerProcess& server, std::vector<std::string> args) {
    args.insert(args.end(), {"--server", server.address()});
    return testing::RunCli(args);
  }
};

// AddLabels stores a label once: an identical one (same clip, range, descriptor and value),
// stored before or earlier in the batch, is returned as the stored one and listed as skipped.
TEST_F(LabelImportTest, AddLabelsSkipsLabelsAlreadyStored) {
  testing::ServerProcess* server = StartServer();
  ASSERT_NE(server, nullptr);
  Client client(testing::InsecureChannel(server->address()));
  const int64_t clip = client.IngestOrFail("chain.bvh", BvhText(ChainClip()));
  v1::AddLabelsRequest add;
  const auto label = [&](int first, int last, const std::string& descriptor, double value) {
    v1::NewLabel* added = add.add_labels();
    added->set_clip_id(clip);
    added->set_first_frame(first);
    added->set_last_frame(last);
    added->set_descriptor_name(descriptor);
    added->set_value(value);
  };
  label(0, 9, "kick", 1);
  label(0, 9, "kick", 1);  // the first again
  label(0, 9, "kick", 0.5);
  label(0, 10, "kick", 1);
  label(0, 9, "punch", 1);
  v1::AddLabelsResponse first;
  ASSERT_TRUE(client.labels().AddLabels(client.Context().get(), add, &first).ok());
  ASSERT_EQ(first.labels_size(), 5);
  EXPECT_THAT(first.skipped(), ::testing::ElementsAre(1));
  EXPECT_EQ(first.labels(1).label_id(), first.labels(0).label_id());
  // The same batch again, the second by its clip's name and in seconds: all stored already.
  add.mutable_labels(1)->clear_clip_id();
  add.mutable_labels(1)->set_clip_name("chain");
  add.mutable_labels(1)->clear_first_frame();
  add.mutable_labels(1)->clear_last_frame();
  add.mutable_labels(1)->set_start_s(0);
  add.mutable_labels(1)->set_end_s(9 / 30.0);
  v1::AddLabelsResponse second;
  ASSERT_TRUE(client.labels().AddLabels(client.Context().get(), add, &second).ok());
  EXPECT_THAT(second.skipped(), ::testing::ElementsAre(0, 1, 2, 3, 4));
  for (int i = 0; i < 5; ++i) {
    EXPECT_EQ(second.labels(i).label_id(), first.labels(i).label_id()) << i;
    EXPECT_EQ(second.labels(i).created_unix_ms(), first.labels(i).created_unix_ms()) << i;
  }
  v1::ListLabelsResponse listed;
  ASSERT_TRUE(client.labels().ListLabels(client.Context().get(), {}, &listed).ok());
  EXPECT_EQ(listed.labels_size(), 4);
}

// The probe's cases end to end through the CLI: a formula descriptor exported, re-imported
// (which duplicated every label), deleted and imported again; a file larger than a batch sent
// in batches; a bad line late in a large file stores nothing.
TEST_F(LabelImportTest, ExportedFormulasImportBackOnceAndLargeFilesGoInBatches) {
  testing::ServerProcess* server = StartServer();
  ASSERT_NE(server, nullptr);
  Client client(testing::InsecureChannel(server->address()));
  client.IngestOrFail("chain.bvh", BvhText(ChainClip()));
  const std::string formula = "=cmd|' /C calc'!A0";
  testing::CommandResult r = Cli(*server, {"label", "add", "chain:0-9", formula});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  ASSERT_EQ(Cli(*server, {"label", "add", "chain:5-20", "+step", "--value", "0.5"}).exit_code, 0);
  r = Cli(*server, {"label", "add", "chain:0-9", formula});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("already stored as label 1"));

  const std::string exported = (dir_ / "labels.csv").string();
  r = Cli(*server, {"labels", "export", "-o", exported});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string csv = testing::ReadFileOrDie(exported);
  EXPECT_EQ(csv,
            "clip,start,end,descriptor,value,unit\n"
            "chain,0,9,'=cmd|' /C calc'!A0,1,frames\n"
            "chain,5,20,'+step,0.5,frames\n");
  // Re-imported as it is: nothing added.
  r = Cli(*server, {"labels", "import", exported, "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(r.out),
            (nlohmann::json{{"file", exported}, {"imported", 0}, {"skipped", 2}}));
  // Deleted and imported: the same labels, the formula's text exact.
  ASSERT_EQ(Cli(*server, {"labels", "delete", "--descriptor", formula}).exit_code, 0);
  r = Cli(*server, {"labels", "import", exported});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("imported 1 labels from " + exported +
                               " (1 already stored, not added again)"));
  r = Cli(*server, {"labels", "list", "--json", "--descriptor", formula});
  ASSERT_EQ(nlohmann::json::parse(r.out)["labels"].size(), 1u);
  r = Cli(*server, {"labels", "export"});
  EXPECT_THAT(r.out, HasSubstr("\nchain,0,9,'=cmd|' /C calc'!A0,1,frames\n"));

  // 12,000 labels: two batches; again: all skipped.
  const auto file_of = [](const std::string& descriptor, int count) {
    std::string text = "clip,start,end,descriptor,value\n";
    for (int i = 0; i < count; ++i) {
      absl::StrAppend(&text, "chain,", i % 60, ",", i % 60, ",", descriptor, i / 60, ",1\n");
    }
    return text;
  };
  const std::string large = WriteFile("large.csv", file_of("d", 12000));
  r = Cli(*server, {"labels", "import", large, "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(r.out)["imported"], 12000);
  r = Cli(*server, {"labels", "import", large, "--json"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(r.out)["skipped"], 12000);
  // A bad line after a batch's worth of new labels: nothing of the file is stored.
  const auto stored = [&client]() {
    v1::ServerInfo info;
    EXPECT_TRUE(client.server().GetServerInfo(client.Context().get(), {}, &info).ok());
    return info.counts().labels();
  };
  const int64_t before = stored();
  const std::string bad =
      WriteFile("bad.csv", file_of("e", 12000) + "chain,0,1,\"late\nstep\",x\n");
  r = Cli(*server, {"labels", "import", bad});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("bad.csv: line 12002: value: 'x' is not a number"));
  EXPECT_EQ(stored(), before);
}

}  // namespace
}  // namespace motiondb
