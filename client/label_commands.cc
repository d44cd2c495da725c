// motiondb label add CLIP[:FROM-TO] DESCRIPTOR [--value V] [--seconds] | labels list [filters] |
// labels find DESCRIPTOR [--min V] [--tag T]... | labels delete (ID... | --clip ID |
// --descriptor D) | labels import FILE | labels export [-o FILE] [--format csv|json]
// [--origin manual|propagated]
#include <unistd.h>

#include <fstream>
#include <functional>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "absl/strings/match.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_split.h"
#include "client/commands.h"
#include "client/label_files.h"
#include "client/server_connection.h"
#include "motiondb/v1/label_service.grpc.pb.h"
#include "util/cli_conventions.h"
#include "util/file_io.h"
#include "util/status_macros.h"
#include "util/status_prefix.h"

namespace motiondb::cli {
namespace {

// The labels `labels import` sends in one AddLabels call (the server takes up to 100000): a few
// MB a batch, whatever the file's size.
constexpr int kImportBatch = 10000;

constexpr char kLabelFileHelp[] =
    "Label files: CSV with the header clip,start,end,descriptor,value (and optionally unit,\n"
    "frames or seconds), or JSON, a list of objects with those keys. clip is the clip's name,\n"
    "digits too; to give a clip by id, use a clip_id column (or key) instead. An empty start\n"
    "or end is the clip's first or last frame, an empty value 1.";

constexpr char kClipHelp[] =
    "CLIP is a clip's name, digits too (0012 is the clip named 0012), or id:N for clip N.";

nlohmann::json LabelJson(const v1::Label& label) {
  nlohmann::json json = {
      {"label_id", label.label_id()},
      {"clip_id", label.clip_id()},
      {"clip_name", label.clip_name()},
      {"first_frame", label.first_frame()},
      {"last_frame", label.last_frame()},
      {"start_s", label.start_s()},
      {"end_s", label.end_s()},
      {"descriptor", label.descriptor_name()},
      {"value", label.value()},
      {"origin", label.origin() == v1::LABEL_ORIGIN_PROPAGATED ? "propagated" : "manual"},
      {"created_unix_ms", label.created_unix_ms()}};
  if (label.origin() == v1::LABEL_ORIGIN_PROPAGATED) {
    json.update({{"source_label_id", label.source_label_id()},
                 {"space", label.space()},
                 {"score", label.score()},
                 {"job_id", label.job_id()}});
  }
  return json;
}

// A table of labels, or {"labels": [...]} with `next_page_token` when there is one.
void PrintLabels(const std::vector<v1::Label>& labels, const std::string& next_page_token,
                 bool json) {
  if (json) {
    nlohmann::json listed = {{"labels", nlohmann::json::array()}};
    for (const v1::Label& label : labels) listed["labels"].push_back(LabelJson(label));
    if (!next_page_token.empty()) listed["next_page_token"] = next_page_token;
    std::cout << listed.dump() << "\n";
    return;
  }
  absl::PrintF("%8s %6s  %-24s %13s %17s  %-20s %6s  %s\n", "ID", "CLIP", "NAME", "FRAMES",
               "SECONDS", "DESCRIPTOR", "VALUE", "ORIGIN");
  for (const v1::Label& label : labels) {
    absl::PrintF("%8d %6d  %-24s %13s %17s  %-20s %6.3f  %s\n", label.label_id(), label.clip_id(),
                 label.clip_name(), absl::StrCat(label.first_frame(), "-", label.last_frame()),
                 absl::StrFormat("%.2f-%.2f", label.start_s(), label.end_s()),
                 label.descriptor_name(), label.value(),
                 label.origin() == v1::LABEL_ORIGIN_PROPAGATED ? "propagated" : "manual");
  }
  // On stderr, so that stdout stays the table.
  if (!next_page_token.empty()) std::cerr << "next page: --page-token " << next_page_token << "\n";
}

// The labels of every page of a listing (`rpc`), or of one when `one_page`, and the token of the
// page after the last one read.
struct Pages {
  std::vector<v1::Label> labels;
  std::string next_page_token;
};
template <typename Request, typename Response>
absl::StatusOr<Pages> ReadPages(const ServerConnection& connection,
                                grpc::Status (v1::LabelService::Stub::*rpc)(grpc::ClientContext*,
                                                                            const Request&,
                                                                            Response*),
                                Request request, bool one_page, const FlagNames& flags) {
  Pages pages;
  do {
    MOTIONDB_ASSIGN_OR_RETURN(const Response response, CallUnary(connection, rpc, request, flags));
    pages.labels.insert(pages.labels.end(), response.labels().begin(), response.labels().end());
    pages.next_page_token = response.next_page_token();
    request.set_page_token(response.next_page_token());
  } while (!one_page && !request.page_token().empty());
  return pages;
}

v1::LabelOrigin OriginOf(const std::string& origin) {
  if (origin == "manual") return v1::LABEL_ORIGIN_MANUAL;
  if (origin == "propagated") return v1::LABEL_ORIGIN_PROPAGATED;
  return v1::LABEL_ORIGIN_UNSPECIFIED;
}

// --limit and --page-token: one page of a listing; without them, every page.
struct PageFlags {
  std::optional<int> limit;
  std::string page_token;

  bool one_page() const { return limit.has_value() || !page_token.empty(); }
  template <typename Request>
  void Set(Request& request) const {
    request.set_page_size(limit.value_or(1000));
    request.set_page_token(page_token);
  }
};

// The pages of a listing `page` asks for (with `names`, the request's other flags), printed.
template <typename Request, typename Response>
absl::Status PrintPages(const ServerConnection& connection,
                        grpc::Status (v1::LabelService::Stub::*rpc)(grpc::ClientContext*,
                                                                    const Request&, Response*),
                        Request request, const PageFlags& page, FlagNames names, bool json) {
  page.Set(request);
  names.insert(names.end(), {{"page_size", "--limit"}, {"page_token", "--page-token"}});
  MOTIONDB_ASSIGN_OR_RETURN(const Pages pages,
                            ReadPages(connection, rpc, request, page.one_page(), names));
  PrintLabels(pages.labels, page.one_page() ? pages.next_page_token : "", json);
  return absl::OkStatus();
}

void AddPageFlags(CLI::App* command, PageFlags* flags) {
  command->add_option("--limit", flags->limit, "one page of at most N labels (default: all)")
      ->type_name("N")
      ->check(WholeAtLeast(1));
  command->add_option("--page-token", flags->page_token, "the page after the one that printed T")
      ->type_name("T");
}

// The words of a command line (or a file) that gave label `index` of an AddLabels batch, for
// the server's errors, which name "labels[i]" and its fields: `item` for the label, `column`
// for each of clip, start, end, descriptor and value.
FlagNames LabelItemNames(size_t index, const std::string& item,
                         const std::function<std::string(const std::string&)>& column) {
  const std::string label = absl::StrCat("labels[", index, "]");
  FlagNames names = {{label, item}};
  for (const auto& [field, name] :
       std::vector<std::pair<std::string, std::string>>{{"clip_id", "clip_id"},
                                                        {"clip_name", "clip"},
                                                        {"first_frame", "start"},
                                                        {"start_s", "start"},
                                                        {"last_frame", "end"},
                                                        {"end_s", "end"},
                                                        {"descriptor", "descriptor"},
                                                        {"value", "value"}}) {
    names.emplace_back(absl::StrCat(label, ".", field), column(name));
  }
  return names;
}

struct AddFlags {
  std::string target;  // CLIP[:FROM-TO]
  std::string descriptor;
  std::optional<double> value;
  bool seconds = false;
};

// Whether the text after a CLIP's last ':' is meant as a range: digits, '.' and '-', with a '-'
// and a digit ("10-20", "1.5-3", but also the slips "10-" and "-1-5").
bool LooksLikeRange(const std::string& tail) {
  return tail.find('-') != std::string::npos &&
         tail.find_first_of("0123456789") != std::string::npos &&
         tail.find_first_not_of("0123456789.-") == std::string::npos;
}

// "walk_01", "walk_01:30-90", "id:12", "id:12:1.5-3" (with --seconds): the clip by name, or by
// id as id:N, and the range. A name is a name, digits too; a name ending in ':' and a range
// must be given by id.
absl::StatusOr<v1::NewLabel> ParseTarget(const std::string& spec, bool seconds) {
  v1::NewLabel label;
  std::string clip = spec;
  const size_t colon = spec.rfind(':');
  const std::string tail = colon == std::string::npos ? "" : spec.substr(colon + 1);
  if (LooksLikeRange(tail)) {
    clip = spec.substr(0, colon);
    const std::vector<std::string> bounds = absl::StrSplit(tail, '-');
    double from = 0, to = 0;
    if (bounds.size() != 2 || !absl::SimpleAtod(bounds[0], &from) ||
        !absl::SimpleAtod(bounds[1], &to)) {
      return absl::InvalidArgumentError(absl::StrCat(
          "'", spec, "': the range '", tail, "' is not FROM-TO, two numbers from 0 (e.g. 10-20)"));
    }
    if (seconds) {
      label.set_start_s(from);
      label.set_end_s(to);
    } else {
      int first = 0, last = 0;
      if (!absl::SimpleAtoi(bounds[0], &first) || !absl::SimpleAtoi(bounds[1], &last)) {
        return absl::InvalidArgumentError(absl::StrCat(
            "'", spec, "': frames are whole numbers (give --seconds for a range in seconds)"));
      }
      label.set_first_frame(first);
      label.set_last_frame(last);
    }
  } else if (seconds) {
    return absl::InvalidArgumentError(absl::StrCat(
        "--seconds: '", spec, "' has no range; give CLIP:FROM-TO with FROM and TO in seconds"));
  }
  if (clip.empty()) return absl::InvalidArgumentError(absl::StrCat("'", spec, "' names no clip"));
  if (absl::StartsWith(clip, "id:")) {
    const std::string id_text = clip.substr(3);
    int64_t id = 0;
    if (id_text.empty() || id_text.find_first_not_of("0123456789") != std::string::npos ||
        !absl::SimpleAtoi(id_text, &id) || id == 0) {
      return absl::InvalidArgumentError(
          absl::StrCat("'", spec, "': id:N gives a clip by id, N a whole number from 1"));
    }
    label.set_clip_id(id);
  } else {
    label.set_clip_name(clip);
  }
  return label;
}

absl::Status AddLabel(const AddFlags& flags, bool json, const ServerConnection& connection) {
  v1::AddLabelsRequest request;
  MOTIONDB_ASSIGN_OR_RETURN(*request.add_labels(), ParseTarget(flags.target, flags.seconds));
  request.mutable_labels(0)->set_descriptor_name(flags.descriptor);
  if (flags.value) request.mutable_labels(0)->set_value(*flags.value);
  const std::map<std::string, std::string> words = {
      {"clip", "CLIP"}, {"clip_id", "CLIP"},          {"start", "FROM"},
      {"end", "TO"},    {"descriptor", "DESCRIPTOR"}, {"value", "--value"}};
  MOTIONDB_ASSIGN_OR_RETURN(
      const v1::AddLabelsResponse response,
      CallUnary(connection, &v1::LabelService::Stub::AddLabels, request,
                LabelItemNames(0, "the label",
                               [&](const std::string& column) { return words.at(column); })));
  const v1::Label& label = response.labels(0);
  const bool stored_before = response.skipped_size() > 0;
  if (json) {
    nlohmann::json added = LabelJson(label);
    if (stored_before) added["already_stored"] = true;
    std::cout << added.dump() << "\n";
  } else {
    absl::PrintF("%s label %d: clip %d (%s) frames %d-%d (%.3f-%.3f s), %s = %g\n",
                 stored_before ? "already stored as" : "added", label.label_id(), label.clip_id(),
                 label.clip_name(), label.first_frame(), label.last_frame(), label.start_s(),
                 label.end_s(), label.descriptor_name(), label.value());
  }
  return absl::OkStatus();
}

struct LabelListFlags {
  int64_t clip = 0;
  std::string descriptor;
  std::string origin;
  std::optional<double> min;
  PageFlags page;
};

absl::Status ListLabels(const LabelListFlags& flags, bool json,
                        const ServerConnection& connection) {
  v1::ListLabelsRequest request;
  request.set_clip_id(flags.clip);
  request.set_descriptor_name(flags.descriptor);
  request.set_origin(OriginOf(flags.origin));
  if (flags.min) request.set_min_value(*flags.min);
  return PrintPages(connection, &v1::LabelService::Stub::ListLabels, request, flags.page,
                    {{"min_value", "--min"}, {"clip_id", "--clip"}}, json);
}

struct FindFlags {
  std::string descriptor;
  double min = 0;
  std::vector<std::string> tags;
  PageFlags page;
};

absl::Status FindLabels(const FindFlags& flags, bool json, const ServerConnection& connection) {
  v1::FindLabelsRequest request;
  request.set_descriptor_name(flags.descriptor);
  request.set_min_value(flags.min);
  FlagNames names = {{"min_value", "--min"}, {"descriptor", "DESCRIPTOR"}};
  for (size_t i = 0; i < flags.tags.size(); ++i) {
    request.add_tags(flags.tags[i]);
    names.emplace_back(absl::StrCat("tags[", i, "]"), absl::StrCat("--tag ", flags.tags[i]));
  }
  return PrintPages(connection, &v1::LabelService::Stub::FindLabels, request, flags.page, names,
                    json);
}

struct DeleteFlags {
  std::vector<int64_t> ids;
  int64_t clip = 0;
  std::string descriptor;
  std::string origin;
};

absl::Status DeleteLabels(const DeleteFlags& flags, bool json, const ServerConnection& connection) {
  v1::DeleteLabelsRequest request;
  FlagNames names = {{"clip_id", "--clip"}};
  for (size_t i = 0; i < flags.ids.size(); ++i) {
    request.add_label_ids(flags.ids[i]);
    names.emplace_back(absl::StrCat("label_ids[", i, "]"), absl::StrCat("ID ", flags.ids[i]));
  }
  request.set_clip_id(flags.clip);
  request.set_descriptor_name(flags.descriptor);
  request.set_origin(OriginOf(flags.origin));
  MOTIONDB_ASSIGN_OR_RETURN(
      const v1::DeleteLabelsResponse response,
      CallUnary(connection, &v1::LabelService::Stub::DeleteLabels, request, names));
  if (json) {
    std::cout << nlohmann::json{{"deleted", response.deleted()}}.dump() << "\n";
  } else {
    absl::PrintF("deleted %d labels\n", response.deleted());
  }
  return absl::OkStatus();
}

// The server's error about a batch of a file's labels in the file's words: each
// "labels[i].field" it names (i in the batch) said as "FILE: line 12, column".
absl::Status SpeakBatchError(const absl::Status& error, const std::string& path,
                             const std::vector<std::string>& places) {
  const std::string message(error.message());
  FlagNames names;
  for (size_t at = message.find("labels["); at != std::string::npos;
       at = message.find("labels[", at + 1)) {
    size_t index = 0;
    const size_t close = message.find(']', at);
    if (close == std::string::npos ||
        !absl::SimpleAtoi(message.substr(at + 7, close - at - 7), &index) ||
        index >= places.size()) {
      continue;
    }
    const std::string item = absl::StrCat(path, ": ", places[index]);
    const FlagNames item_names = LabelItemNames(
        index, item, [&](const std::string& column) { return absl::StrCat(item, ", ", column); });
    names.insert(names.end(), item_names.begin(), item_names.end());
  }
  return absl::Status(error.code(), SpeakFlags(message, names));
}

// Opens a label file for one reading of it.
absl::StatusOr<std::unique_ptr<std::ifstream>> OpenLabelFile(const std::string& path) {
  auto in = std::make_unique<std::ifstream>(path, std::ios::binary);
  if (!*in) return absl::NotFoundError(absl::StrCat("cannot read ", path));
  return in;
}

// Imports a label file of any size, holding one batch of it at a time. The whole file is read
// first, so that an error in it stores nothing; then it is read again and sent in batches of
// kImportBatch labels, each stored all or nothing: a file of up to that many is stored whole
// or not at all. The server does not store a label twice, so that importing a file again after
// a batch failed (or after it was imported) adds only what is missing.
absl::Status ImportLabels(const std::string& path, bool json, const ServerConnection& connection) {
  MOTIONDB_ASSIGN_OR_RETURN(const LabelFileFormat format, LabelFileFormatOf(path));
  int64_t total = 0;
  {
    MOTIONDB_ASSIGN_OR_RETURN(std::unique_ptr<std::ifstream> in, OpenLabelFile(path));
    MOTIONDB_RETURN_IF_ERROR(Prefixed(path, ReadLabelFile(*in, format, [&total](PlacedLabel) {
                                        ++total;
                                        return absl::OkStatus();
                                      })));
  }
  if (total == 0)
    return absl::InvalidArgumentError(absl::StrCat(path, ": the file holds no labels"));
  const bool progress_bar = ::isatty(STDERR_FILENO) && !json && total > kImportBatch;
  int64_t sent = 0, added = 0, skipped = 0;
  v1::AddLabelsRequest request;
  std::vector<std::string> places;
  absl::Status refused;  // the server's, told in the file's words
  const auto send = [&]() -> absl::Status {
    absl::StatusOr<v1::AddLabelsResponse> response =
        CallUnary(connection, &v1::LabelService::Stub::AddLabels, request);
    if (!response.ok()) {
      refused = SpeakBatchError(response.status(), path, places);
      if (sent > 0) {
        refused = absl::Status(refused.code(),
                               absl::StrCat(refused.message(), " (the file's first ", sent,
                                            " labels were stored; importing the file again adds "
                                            "only the labels missing)"));
      }
      return refused;
    }
    sent += request.labels_size();
    skipped += response->skipped_size();
    added += response->labels_size() - response->skipped_size();
    request.clear_labels();
    places.clear();
    if (progress_bar) {
      std::cerr << absl::StrFormat("\r\033[Klabels import: %d of %d labels", sent, total)
                << std::flush;
    }
    return absl::OkStatus();
  };
  MOTIONDB_ASSIGN_OR_RETURN(std::unique_ptr<std::ifstream> in, OpenLabelFile(path));
  absl::Status read = ReadLabelFile(*in, format, [&](PlacedLabel placed) {
    *request.add_labels() = std::move(placed.label);
    places.push_back(std::move(placed.place));
    return request.labels_size() < kImportBatch ? absl::OkStatus() : send();
  });
  if (read.ok() && request.labels_size() > 0) read = send();
  if (progress_bar) std::cerr << "\n";
  if (!refused.ok()) return refused;
  // An error of the file itself now means it changed since it was read.
  MOTIONDB_RETURN_IF_ERROR(Prefixed(path, read));
  if (json) {
    std::cout << nlohmann::json{{"file", path}, {"imported", added}, {"skipped", skipped}}.dump()
              << "\n";
  } else {
    absl::PrintF("imported %d labels from %s", added, path);
    if (skipped > 0) absl::PrintF(" (%d already stored, not added again)", skipped);
    absl::PrintF("\n");
  }
  return absl::OkStatus();
}

struct LabelExportFlags {
  std::string out;     // empty: stdout
  std::string format;  // empty: the extension of `out`, else csv
  int64_t clip = 0;
  std::string descriptor;
  // The file has no origin column, and imports as manual labels: propagated ones exported with
  // them would come back as manual ones.
  std::string origin = "manual";
};

absl::Status ExportLabels(const LabelExportFlags& flags, bool json,
                          const ServerConnection& connection) {
  LabelFileFormat format = LabelFileFormat::kCsv;
  if (!flags.format.empty()) {
    format = flags.format == "json" ? LabelFileFormat::kJson : LabelFileFormat::kCsv;
  } else if (!flags.out.empty()) {
    MOTIONDB_ASSIGN_OR_RETURN(format, LabelFileFormatOf(flags.out));
  }
  v1::ListLabelsRequest request;
  request.set_page_size(1000);
  request.set_clip_id(flags.clip);
  request.set_descriptor_name(flags.descriptor);
  request.set_origin(OriginOf(flags.origin));
  MOTIONDB_ASSIGN_OR_RETURN(
      const Pages pages, ReadPages(connection, &v1::LabelService::Stub::ListLabels, request, false,
                                   {{"clip_id", "--clip"}}));
  const std::string text = FormatLabelFile(pages.labels, format);
  if (flags.out.empty()) {
    std::cout << text;
    return absl::OkStatus();
  }
  MOTIONDB_RETURN_IF_ERROR(WriteFileAtomically(flags.out, text));
  if (json) {
    std::cout << nlohmann::json{{"file", flags.out},
                                {"labels", pages.labels.size()},
                                {"format", format == LabelFileFormat::kJson ? "json" : "csv"}}
                     .dump()
              << "\n";
  } else {
    absl::PrintF("wrote %d labels to %s\n", pages.labels.size(), flags.out);
  }
  return absl::OkStatus();
}

// --descriptor D and --origin manual|propagated, the filters list, delete and export share.
void AddFilterFlags(CLI::App* command, std::string* descriptor, std::string* origin) {
  command->add_option("--descriptor", *descriptor, "only labels of descriptor D")->type_name("D");
  OneOf(command->add_option("--origin", *origin, "only manual or only propagated labels"),
        {"manual", "propagated"});
}

void AddLabelAdd(Commands& commands) {
  const GlobalOptions& global = commands.global();
  CLI::App* label = commands.AddGroup(commands.root(), "label", "one label: add");
  auto add = std::make_shared<AddFlags>();
  CLI::App* adder = commands.AddServer(label, "add", "label a clip, or a range of it",
                                       [add, &global](const ServerConnection& connection) {
                                         return AddLabel(*add, global.json, connection);
                                       });
  adder
      ->add_option("CLIP", add->target,
                   "the clip's id or name, and optionally its frames FROM-TO (inclusive)")
      ->type_name("CLIP[:FROM-TO]")
      ->required();
  adder->add_option("DESCRIPTOR", add->descriptor, "what the range shows, e.g. raise-right-hand")
      ->required();
  adder->add_option("--value", add->value, "how strongly, in [0, 1]")
      ->type_name("V")
      ->default_str("1")
      ->check(NumberAtLeast(0));
  adder->add_flag("--seconds", add->seconds, "FROM-TO are seconds, not frames (needs FROM-TO)");
  adder->footer(absl::StrCat(
      kClipHelp,
      "\nFrame numbers count from 0 at the clip's own rate; FROM-TO is inclusive. In seconds, TO\n"
      "may be the clip's duration (a half-open end): that is its last frame."));
}

void AddListAndFind(Commands& commands, CLI::App* labels) {
  const GlobalOptions& global = commands.global();
  auto list = std::make_shared<LabelListFlags>();
  CLI::App* lister = commands.AddServer(labels, "list", "list labels, in id order",
                                        [list, &global](const ServerConnection& connection) {
                                          return ListLabels(*list, global.json, connection);
                                        });
  lister->add_option("--clip", list->clip, "only the labels of clip ID")
      ->type_name("ID")
      ->check(WholeAtLeast(1));
  AddFilterFlags(lister, &list->descriptor, &list->origin);
  lister->add_option("--min", list->min, "only labels of value V or more")
      ->type_name("V")
      ->check(NumberAtLeast(0));
  AddPageFlags(lister, &list->page);

  auto find = std::make_shared<FindFlags>();
  CLI::App* finder =
      commands.AddServer(labels, "find", "the ranges labelled DESCRIPTOR, strongest first",
                         [find, &global](const ServerConnection& connection) {
                           return FindLabels(*find, global.json, connection);
                         });
  finder->add_option("DESCRIPTOR", find->descriptor, "the descriptor")->required();
  finder->add_option("--min", find->min, "only labels of value V or more")
      ->type_name("V")
      ->capture_default_str()
      ->check(NumberAtLeast(0));
  finder->add_option("--tag", find->tags, "only clips tagged T (repeat: any of them)")
      ->type_name("T")
      ->allow_extra_args(false);
  AddPageFlags(finder, &find->page);
}

void AddDeleteImportExport(Commands& commands, CLI::App* labels) {
  const GlobalOptions& global = commands.global();
  auto remove = std::make_shared<DeleteFlags>();
  CLI::App* deleter =
      commands.AddServer(labels, "delete", "delete labels by id, or those of a clip or descriptor",
                         [remove, &global](const ServerConnection& connection) {
                           return DeleteLabels(*remove, global.json, connection);
                         });
  deleter->add_option("ID", remove->ids, "labels to delete")->check(WholeAtLeast(1));
  deleter->add_option("--clip", remove->clip, "every label of clip ID")
      ->type_name("ID")
      ->check(WholeAtLeast(1));
  AddFilterFlags(deleter, &remove->descriptor, &remove->origin);
  deleter->footer("Deleting a manual label deletes the labels propagated from it.");

  auto path = std::make_shared<std::string>();
  CLI::App* importer =
      commands.AddServer(labels, "import", "add the labels of a CSV or JSON file not stored yet",
                         [path, &global](const ServerConnection& connection) {
                           return ImportLabels(*path, global.json, connection);
                         });
  importer->add_option("FILE", *path, "a .csv or .json file (see below)")
      ->required()
      ->check(ExistingFile());
  importer->footer(absl::StrCat(
      kLabelFileHelp,
      "\nA bad line stores nothing. A label stored already (same clip, range, descriptor and\n"
      "value) is not added again. A file of up to ",
      kImportBatch,
      " labels is stored whole or not at all;\na larger one in batches of that many, each "
      "whole or not at all: after an error, importing\nthe file again adds what is missing. "
      "CSV text cells that export wrote after an apostrophe\n(= + - @ first: formula "
      "injection) are read without it."));

  auto out = std::make_shared<LabelExportFlags>();
  CLI::App* exporter =
      commands.AddServer(labels, "export", "write labels as a file `labels import` reads",
                         [out, &global](const ServerConnection& connection) {
                           return ExportLabels(*out, global.json, connection);
                         });
  exporter->add_option("-o,--out", out->out, "the file to write (default: stdout)")
      ->type_name("FILE");
  OneOf(exporter->add_option("--format", out->format, "default: -o's extension, else csv"),
        {"csv", "json"});
  exporter->add_option("--clip", out->clip, "only the labels of clip ID")
      ->type_name("ID")
      ->check(WholeAtLeast(1));
  exporter->add_option("--descriptor", out->descriptor, "only labels of descriptor D")
      ->type_name("D");
  OneOf(exporter->add_option("--origin", out->origin, "manual (the default) or propagated labels"),
        {"manual", "propagated"});
  exporter->footer(
      "Exports manual labels unless --origin propagated: the file has no origin column, and\n"
      "every label imported from it is manual.");
}

}  // namespace

void AddLabelCommands(Commands& commands) {
  AddLabelAdd(commands);
  CLI::App* labels =
      commands.AddGroup(commands.root(), "labels", "labels: list, find, delete, import, export");
  labels->footer(kLabelFileHelp);
  AddListAndFind(commands, labels);
  AddDeleteImportExport(commands, labels);
}

}  // namespace motiondb::cli
