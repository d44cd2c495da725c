#include "tests/server_fixture.h"

#include <thread>

#include "core/bvh/bvh_writer.h"
#include "tests/clip_builder.h"

namespace motiondb {

using testing::GenerateSyntheticCorpus;
using testing::SyntheticAction;
using testing::SyntheticCorpus;
using testing::SyntheticCorpusOptions;
using testing::SyntheticSegment;

const SyntheticCorpus& Humanoid() {
  static const SyntheticCorpus* const library = [] {
    SyntheticCorpusOptions options;
    options.seed = 7;
    options.script = {{SyntheticAction::kRightArmRaise, 4},
                      {SyntheticAction::kLeftArmRaise, 4},
                      {SyntheticAction::kBothArmsRaise, 3},
                      {SyntheticAction::kShrug, 3}};
    options.max_clip_duration_s = 20;
    options.threads = 2;
    absl::StatusOr<SyntheticCorpus> generated = GenerateSyntheticCorpus(options);
    EXPECT_TRUE(generated.ok()) << generated.status();
    return new SyntheticCorpus(*std::move(generated));
  }();
  return *library;
}

const SyntheticSegment& FirstRaise() { return Humanoid().segments.front(); }

std::string BvhText(const Clip& clip) {
  absl::StatusOr<std::string> text = WriteBvh(clip);
  EXPECT_TRUE(text.ok()) << text.status();
  return text.ok() ? *text : "";
}

Clip ChainClip(double speed) {
  return testing::MakeClip(
      testing::ChainSkeleton(), 61, 1.0 / 30,
      [speed](int f, int j) {
        return Quat(Eigen::AngleAxisd(speed * f * (j + 1), Eigen::Vector3d::UnitY()));
      },
      [](int f, int) { return Eigen::Vector3d(0.1 * f, 90, 0); });
}

v1::SearchRequest ClipQuery(const std::string& space, int64_t clip_id, int first, int last) {
  v1::SearchRequest request;
  request.set_space(space);
  request.mutable_clip()->set_clip_id(clip_id);
  request.mutable_clip()->set_first_frame(first);
  request.mutable_clip()->set_last_frame(last);
  request.set_exclude_query(false);
  return request;
}

v1::NewLabel FrameLabel(int64_t clip_id, std::optional<int> first, std::optional<int> last,
                        const std::string& descriptor, std::optional<double> value) {
  v1::NewLabel label;
  label.set_clip_id(clip_id);
  if (first) label.set_first_frame(*first);
  if (last) label.set_last_frame(*last);
  label.set_descriptor_name(descriptor);
  if (value) label.set_value(*value);
  return label;
}

void ExpectSameResults(const v1::SearchResponse& after, const v1::SearchResponse& before) {
  ASSERT_EQ(after.results_size(), before.results_size());
  for (int i = 0; i < before.results_size(); ++i) {
    EXPECT_EQ(after.results(i).clip_id(), before.results(i).clip_id()) << i;
    EXPECT_EQ(after.results(i).start_frame(), before.results(i).start_frame()) << i;
    EXPECT_EQ(after.results(i).end_frame(), before.results(i).end_frame()) << i;
    EXPECT_EQ(after.results(i).score(), before.results(i).score()) << i;
  }
}

std::vector<v1::Label> AddLabelsOrFail(Client& client, const std::vector<v1::NewLabel>& labels) {
  v1::AddLabelsRequest add;
  for (const v1::NewLabel& label : labels) *add.add_labels() = label;
  v1::AddLabelsResponse added;
  const grpc::Status status = client.labels().AddLabels(client.Context().get(), add, &added);
  EXPECT_TRUE(status.ok()) << status.error_message();
  return {added.labels().begin(), added.labels().end()};
}

v1::StartPropagationRequest Propagation(const std::vector<std::string>& descriptors,
                                        int max_results) {
  v1::StartPropagationRequest request;
  request.set_space("body");
  for (const std::string& descriptor : descriptors) request.add_descriptor_names(descriptor);
  request.mutable_search()->set_max_results(max_results);
  return request;
}

v1::Job StartOrFail(Client& client, const v1::StartPropagationRequest& request) {
  v1::Job job;
  const grpc::Status status = client.jobs().StartPropagation(client.Context().get(), request, &job);
  EXPECT_TRUE(status.ok()) << status.error_message();
  EXPECT_EQ(job.state(), v1::JOB_STATE_QUEUED);
  return job;
}

bool Ended(const v1::Job& job) {
  return job.state() != v1::JOB_STATE_QUEUED && job.state() != v1::JOB_STATE_RUNNING;
}

v1::Job PollJob(Client& client, const std::string& job_id,
                const std::function<bool(const v1::Job&)>& done) {
  v1::GetJobRequest get;
  get.set_job_id(job_id);
  v1::Job job;
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  while (std::chrono::steady_clock::now() < give_up) {
    const grpc::Status status = client.jobs().GetJob(client.Context().get(), get, &job);
    EXPECT_TRUE(status.ok()) << status.error_message();
    if (!status.ok() || done(job)) return job;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ADD_FAILURE() << job_id << " never got there: " << job.ShortDebugString();
  return job;
}

std::vector<v1::Label> Propagated(Client& client) {
  v1::ListLabelsRequest list;
  list.set_origin(v1::LABEL_ORIGIN_PROPAGATED);
  list.set_page_size(1000);
  std::vector<v1::Label> labels;
  v1::ListLabelsResponse page;
  do {
    const grpc::Status status = client.labels().ListLabels(client.Context().get(), list, &page);
    EXPECT_TRUE(status.ok()) << status.error_message();
    if (!status.ok()) break;
    labels.insert(labels.end(), page.labels().begin(), page.labels().end());
    list.set_page_token(page.next_page_token());
  } while (!list.page_token().empty());
  return labels;
}

std::vector<v1::Label> LabelManyRanges(Client& client, const std::vector<int64_t>& ids, int count) {
  std::vector<v1::NewLabel> given;
  for (int i = 0; i < count; ++i) {
    const size_t clip = i % ids.size();
    const int frames = Humanoid().clips[clip].frame_count();
    const int first = (i / static_cast<int>(ids.size()) * 37) % (frames - 80);
    given.push_back(FrameLabel(ids[clip], first, first + 60, "long", 1.0));
  }
  return AddLabelsOrFail(client, given);
}

}  // namespace motiondb
