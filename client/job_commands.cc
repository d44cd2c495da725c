// motiondb propagate --space S [--descriptor D]... [--max-results N] [--tag T]... [--exact]
// [--seeds frames|places|windows|shapes] [--dtw-dims N] [--rival-share R] [--wait] |
// jobs | job show|watch|cancel ID
#include <unistd.h>

#include <chrono>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "client/commands.h"
#include "client/server_connection.h"
#include "motiondb/v1/job_service.grpc.pb.h"
#include "util/cli_conventions.h"
#include "util/status_macros.h"

namespace motiondb::cli {
namespace {

std::string StateName(v1::JobState state) {
  switch (state) {
    case v1::JOB_STATE_QUEUED:
      return "queued";
    case v1::JOB_STATE_RUNNING:
      return "running";
    case v1::JOB_STATE_SUCCEEDED:
      return "succeeded";
    case v1::JOB_STATE_FAILED:
      return "failed";
    case v1::JOB_STATE_CANCELLED:
      return "cancelled";
    case v1::JOB_STATE_INTERRUPTED:
      return "interrupted";
    default:
      return "unknown";
  }
}

nlohmann::json JobJson(const v1::Job& job) {
  return {{"job_id", job.job_id()},
          {"kind", job.kind()},
          {"state", StateName(job.state())},
          {"space", job.space()},
          {"descriptors",
           std::vector<std::string>(job.descriptor_names().begin(), job.descriptor_names().end())},
          {"parameters", nlohmann::json::parse(job.parameters(), nullptr, false)},
          {"done", job.done()},
          {"total", job.total()},
          {"queries", job.queries()},
          {"queries_skipped", job.queries_skipped()},
          {"labels_written", job.labels_written()},
          {"error", job.error()},
          {"created_unix_ms", job.created_unix_ms()},
          {"started_unix_ms", job.started_unix_ms()},
          {"finished_unix_ms", job.finished_unix_ms()}};
}

// One job: a JSON object, or a line ("job-3 succeeded: ...") and its error.
void PrintJob(const v1::Job& job, bool json) {
  if (json) {
    std::cout << JobJson(job).dump() << "\n";
    return;
  }
  absl::PrintF("%s %s: %s in space %s, %d/%d labels searched (%d skipped), %d labels written\n",
               job.job_id(), StateName(job.state()), absl::StrJoin(job.descriptor_names(), ", "),
               job.space(), job.done(), job.total(), job.queries_skipped(), job.labels_written());
  if (!job.error().empty()) absl::PrintF("error: %s\n", job.error());
}

// A job that ended otherwise than succeeding fails the command that waited for it.
absl::Status OutcomeOf(const v1::Job& job) {
  if (job.state() == v1::JOB_STATE_SUCCEEDED) return absl::OkStatus();
  return absl::AbortedError(absl::StrCat(job.job_id(), " ", StateName(job.state()),
                                         job.error().empty() ? "" : ": ", job.error()));
}

// Follows the job until it ends: a progress bar on stderr when it is a terminal (and not
// --json), then the job as it ended.
absl::Status Watch(const ServerConnection& connection, const std::string& job_id, bool json) {
  const std::unique_ptr<v1::JobService::Stub> stub = v1::JobService::NewStub(connection.channel());
  v1::WatchJobRequest request;
  request.set_job_id(job_id);
  std::unique_ptr<grpc::ClientContext> context = connection.NewContext();
  // A job may outlast --timeout, which bounds single calls; the watch ends with the job.
  context->set_deadline(std::chrono::system_clock::time_point::max());
  auto reader = stub->WatchJob(context.get(), request);
  const bool progress_bar = ::isatty(STDERR_FILENO) && !json;
  v1::Job job;
  bool any = false;
  for (v1::Job update; reader->Read(&update);) {
    job = update;
    any = true;
    if (!progress_bar) continue;
    const int width = 30;
    const int done = job.total() > 0 ? static_cast<int>(width * job.done() / job.total()) : 0;
    std::cerr << absl::StrFormat("\r\033[K[%s%s] %d/%d %s %s", std::string(done, '#'),
                                 std::string(width - done, ' '), job.done(), job.total(),
                                 job.job_id(), StateName(job.state()))
              << std::flush;
  }
  if (progress_bar && any) std::cerr << "\n";
  const grpc::Status status = reader->Finish();
  if (!status.ok()) {
    return absl::Status(static_cast<absl::StatusCode>(status.error_code()),
                        DescribeError(status, connection.address()));
  }
  PrintJob(job, json);
  return OutcomeOf(job);
}

struct PropagateFlags {
  std::string space;
  std::vector<std::string> descriptors;
  std::optional<int> max_results;
  std::vector<std::string> tags;
  bool exact = false;
  std::optional<std::string> seeds;
  std::optional<int> dtw_dims;
  std::optional<double> rival_share;
  bool wait = false;
};

absl::Status Propagate(const PropagateFlags& flags, bool json, const ServerConnection& connection) {
  v1::StartPropagationRequest request;
  request.set_space(flags.space);
  FlagNames names = {{"space", "--space"},
                     {"max_results", "--max-results"},
                     {"dtw_dims", "--dtw-dims"},
                     {"rival_share", "--rival-share"}};
  for (size_t i = 0; i < flags.descriptors.size(); ++i) {
    request.add_descriptor_names(flags.descriptors[i]);
    names.emplace_back(absl::StrCat("descriptors[", i, "]"),
                       absl::StrCat("--descriptor '", flags.descriptors[i], "'"));
  }
  if (flags.max_results) request.mutable_search()->set_max_results(*flags.max_results);
  request.mutable_search()->set_exact(flags.exact);
  if (flags.seeds) request.mutable_search()->set_seed_selection(SeedSelectionNamed(*flags.seeds));
  if (flags.dtw_dims) request.mutable_search()->set_dtw_dims(*flags.dtw_dims);
  if (flags.rival_share) request.set_rival_share(*flags.rival_share);
  for (const std::string& tag : flags.tags) request.add_tags(tag);
  MOTIONDB_ASSIGN_OR_RETURN(
      const v1::Job job,
      CallUnary(connection, &v1::JobService::Stub::StartPropagation, request, names));
  if (!flags.wait) {
    PrintJob(job, json);
    return absl::OkStatus();
  }
  return Watch(connection, job.job_id(), json);
}

absl::Status ListJobs(bool json, const ServerConnection& connection) {
  v1::ListJobsRequest request;
  request.set_page_size(1000);
  std::vector<v1::Job> jobs;
  do {
    MOTIONDB_ASSIGN_OR_RETURN(const v1::ListJobsResponse page,
                              CallUnary(connection, &v1::JobService::Stub::ListJobs, request));
    jobs.insert(jobs.end(), page.jobs().begin(), page.jobs().end());
    request.set_page_token(page.next_page_token());
  } while (!request.page_token().empty());
  if (json) {
    nlohmann::json listed = {{"jobs", nlohmann::json::array()}};
    for (const v1::Job& job : jobs) listed["jobs"].push_back(JobJson(job));
    std::cout << listed.dump() << "\n";
    return absl::OkStatus();
  }
  absl::PrintF("%-10s %-11s %-12s %-24s %11s %8s\n", "JOB", "STATE", "SPACE", "DESCRIPTORS",
               "PROGRESS", "LABELS");
  for (const v1::Job& job : jobs) {
    absl::PrintF("%-10s %-11s %-12s %-24s %11s %8d\n", job.job_id(), StateName(job.state()),
                 job.space(), absl::StrJoin(job.descriptor_names(), ","),
                 absl::StrCat(job.done(), "/", job.total()), job.labels_written());
  }
  return absl::OkStatus();
}

// `job show|cancel ID`: one unary call on the job, printed.
template <typename Request>
absl::Status OnJob(const ServerConnection& connection,
                   grpc::Status (v1::JobService::Stub::*rpc)(grpc::ClientContext*, const Request&,
                                                             v1::Job*),
                   const std::string& job_id, bool json) {
  Request request;
  request.set_job_id(job_id);
  MOTIONDB_ASSIGN_OR_RETURN(const v1::Job job,
                            CallUnary(connection, rpc, request, {{"job_id", "ID"}}));
  PrintJob(job, json);
  return absl::OkStatus();
}

void AddPropagate(Commands& commands) {
  const GlobalOptions& global = commands.global();
  auto flags = std::make_shared<PropagateFlags>();
  CLI::App* propagate = commands.AddServer(
      commands.root(), "propagate", "spread manual labels to similar ranges (a background job)",
      [flags, &global](const ServerConnection& connection) {
        return Propagate(*flags, global.json, connection);
      });
  propagate->add_option("--space", flags->space, "the space to search in")
      ->type_name("S")
      ->required();
  propagate
      ->add_option("--descriptor", flags->descriptors,
                   "a descriptor to propagate (repeat; default: every manual one)")
      ->type_name("D")
      ->allow_extra_args(false);
  propagate->add_option("--max-results", flags->max_results, "results per label (default 100)")
      ->type_name("N")
      ->check(WholeAtLeast(1));
  propagate->add_option("--tag", flags->tags, "only search clips tagged T (repeat: any of them)")
      ->type_name("T")
      ->allow_extra_args(false);
  propagate->add_flag("--exact", flags->exact, "exhaustive searches: slower, the true best");
  OneOf(propagate->add_option("--seeds", flags->seeds,
                              "each search's seeds, as search --seeds (default frames)"),
        kSeedNames);
  propagate
      ->add_option("--dtw-dims", flags->dtw_dims,
                   "each search's time-warp distance dimensions, as search --dtw-dims (default 5)")
      ->type_name("N");
  propagate
      ->add_option("--rival-share", flags->rival_share,
                   "write a range only where every overlapping range of another descriptor has "
                   "less than R times its value (0 < R <= 1; default: write every descriptor's)")
      ->type_name("R");
  propagate->add_flag("--wait", flags->wait,
                      "follow the job to its end (a progress bar on stderr); exit 1 unless it "
                      "succeeds");
  propagate->footer(
      "Each manual label is searched for in the space; every result range gets its descriptor\n"
      "with value = label value x 2^-((score/s0)^2), s0 the space's score scale. A re-run\n"
      "replaces the job's earlier output. Follow a job with 'motiondb job watch ID'.");
}

void AddJobSubcommands(Commands& commands, CLI::App* job) {
  const GlobalOptions& global = commands.global();
  auto id = std::make_shared<std::string>();
  const auto add = [&](const std::string& name, const std::string& description,
                       std::function<absl::Status(const ServerConnection&)> body) {
    commands.AddServer(job, name, description, std::move(body))
        ->add_option("ID", *id, "the job, e.g. job-3")
        ->required();
  };
  add("show", "a job's state, progress and counts", [id, &global](const auto& connection) {
    return OnJob(connection, &v1::JobService::Stub::GetJob, *id, global.json);
  });
  add("watch", "follow a job to its end; exit 1 unless it succeeds",
      [id, &global](const auto& connection) { return Watch(connection, *id, global.json); });
  add("cancel", "cancel a queued or running job, and wait for a running one to stop",
      [id, &global](const auto& connection) -> absl::Status {
        v1::CancelJobRequest request;
        request.set_job_id(*id);
        MOTIONDB_ASSIGN_OR_RETURN(
            const v1::Job job,
            CallUnary(connection, &v1::JobService::Stub::CancelJob, request, {{"job_id", "ID"}}));
        if (job.state() != v1::JOB_STATE_RUNNING && job.state() != v1::JOB_STATE_QUEUED) {
          PrintJob(job, global.json);
          return absl::OkStatus();
        }
        // The server answers at once and the job stops at its next check: watched to its end,
        // cancelled (or its own end, when it finished first, which is no error of the cancel).
        const absl::Status watched = Watch(connection, *id, global.json);
        return absl::IsAborted(watched) ? absl::OkStatus() : watched;
      });
}

}  // namespace

void AddJobCommands(Commands& commands) {
  AddPropagate(commands);
  const GlobalOptions& global = commands.global();
  commands.AddServer(
      commands.root(), "jobs", "list jobs, newest first",
      [&global](const ServerConnection& connection) { return ListJobs(global.json, connection); });
  CLI::App* job = commands.AddGroup(commands.root(), "job", "one job: show, watch, cancel");
  AddJobSubcommands(commands, job);
}

}  // namespace motiondb::cli
