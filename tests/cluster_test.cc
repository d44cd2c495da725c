// The cluster layer against real etcd processes on loopback (testing/etcd_processes.h): the
// client, the shard map's compare-and-swap, membership under a lease, the map's watch, the
// election of a leader, failover between etcd members, and a real motiondb-server --cluster
// through etcd going away and back. Every wait polls with a generous bound; nothing asserts how
// long something took.
#include <signal.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <thread>
#include <tuple>

#include <gmock/gmock.h>
#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>

#include "absl/cleanup/cleanup.h"
#include "absl/strings/escaping.h"
#include "cluster/clip_id_blocks.h"
#include "cluster/clip_names.h"
#include "cluster/clip_router.h"
#include "cluster/cluster_keys.h"
#include "cluster/etcd_client.h"
#include "cluster/leader_election.h"
#include "cluster/node_address.h"
#include "cluster/node_info.h"
#include "cluster/node_registration.h"
#include "cluster/shard_map.h"
#include "cluster/shard_map_store.h"
#include "cluster/shard_map_watcher.h"
#include "grpc/health/v1/health.grpc.pb.h"
#include "motiondb/shard/v1/shard_service.grpc.pb.h"
#include "motiondb/v1/clip_service.grpc.pb.h"
#include "motiondb/v1/server_service.grpc.pb.h"
#include "testing/etcd_processes.h"
#include "testing/server_process.h"
#include "tests/clip_builder.h"
#include "tests/server_fixture.h"
#include "tests/test_data.h"
// Last: httplib.h includes <resolv.h>, whose _res macro breaks the Eigen headers above.
#include <httplib.h>

namespace motiondb::cluster {
namespace {

using motiondb::testing::EtcdProcesses;
using ::testing::HasSubstr;

// Far beyond any wait these tests need on a loaded machine: a bound, not an expectation.
constexpr auto kBound = std::chrono::seconds(60);

bool PollUntil(const std::function<bool()>& condition) {
  const auto give_up = std::chrono::steady_clock::now() + kBound;
  while (std::chrono::steady_clock::now() < give_up) {
    if (condition()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return condition();
}

std::unique_ptr<EtcdClient> ClientOf(const EtcdProcesses& etcd) {
  return *EtcdClient::Create(EtcdOptions{.endpoints = etcd.endpoints(),
                                         .call_timeout = absl::Seconds(5),
                                         .attempt_timeout = absl::Seconds(2)});
}

ClusterOptions NodeOptions(const EtcdProcesses& etcd, const std::string& cluster,
                           const std::string& node_id, const std::string& role = "shard") {
  ClusterOptions options;
  options.etcd.endpoints = etcd.endpoints();
  options.cluster = cluster;
  options.node.node_id = node_id;
  options.node.address = "127.0.0.1:1";
  options.node.role = role;
  options.lease_ttl = absl::Seconds(2);
  return options;
}

bool Listed(const EtcdClient& client, const std::string& cluster, const std::string& node_id) {
  const absl::StatusOr<std::vector<NodeInfo>> nodes = ListNodes(client, cluster);
  if (!nodes.ok()) return false;
  for (const NodeInfo& node : *nodes) {
    if (node.node_id == node_id) return true;
  }
  return false;
}

// What a candidate's on_change said, in order.
class Changes {
 public:
  std::function<void(bool)> Recorder() {
    return [this](bool leading) {
      std::lock_guard<std::mutex> lock(mutex_);
      said_.push_back(leading);
    };
  }
  std::vector<bool> said() {
    std::lock_guard<std::mutex> lock(mutex_);
    return said_;
  }

 private:
  std::mutex mutex_;
  std::vector<bool> said_;
};

// A candidate for the office "jobs" of the cluster "elect".
std::unique_ptr<LeaderElection> Candidate(const EtcdClient& client, const std::string& node_id,
                                          std::function<void(bool)> on_change = nullptr,
                                          absl::Duration lease_ttl = absl::Seconds(2)) {
  absl::StatusOr<std::unique_ptr<LeaderElection>> election =
      LeaderElection::Start(client, "elect", "jobs", node_id, lease_ttl, std::move(on_change));
  EXPECT_TRUE(election.ok()) << election.status();
  return election.ok() ? std::move(*election) : nullptr;
}

std::optional<std::string> LeaderOf(const LeaderElection& election) {
  const absl::StatusOr<std::optional<std::string>> leader = election.CurrentLeader();
  EXPECT_TRUE(leader.ok()) << leader.status();
  return leader.ok() ? *leader : std::nullopt;
}

TEST(ShardMapTest, ShardOfClipIsFixedForEver) {
  // Pinned: these say where stored clips live; a change here strands every cluster's data.
  EXPECT_EQ(ShardOfClip(0, 64), 0);
  EXPECT_EQ(ShardOfClip(1, 64), 37);
  EXPECT_EQ(ShardOfClip(2, 64), 10);
  EXPECT_EQ(ShardOfClip(42, 64), 34);
  EXPECT_EQ(ShardOfClip(123456789, 64), 32);
  EXPECT_EQ(ShardOfClip(-1, 64), 59);
  EXPECT_EQ(ShardOfClip(42, 7), 3);
}

TEST(NodeAddressTest, AdvertisedAddressIsReachable) {
  // Without --advertise: the listening host at the port served, a wildcard made the host name.
  EXPECT_EQ(*AdvertisedAddress("", "127.0.0.1:0", 50123, "box"), "127.0.0.1:50123");
  EXPECT_EQ(*AdvertisedAddress("", "0.0.0.0:50051", 50051, "box"), "box:50051");
  EXPECT_EQ(*AdvertisedAddress("", "[::]:50051", 50051, "box"), "box:50051");
  EXPECT_EQ(*AdvertisedAddress("", "[::1]:0", 4000, "box"), "[::1]:4000");
  // --advertise: a host takes the port served; a port of its own stays.
  EXPECT_EQ(*AdvertisedAddress("shard-0.motiondb", "0.0.0.0:0", 4000, "box"),
            "shard-0.motiondb:4000");
  EXPECT_EQ(*AdvertisedAddress("shard-0.motiondb:7000", "0.0.0.0:0", 4000, "box"),
            "shard-0.motiondb:7000");
  EXPECT_EQ(*AdvertisedAddress("[fd00::7]:7000", "0.0.0.0:0", 4000, "box"), "[fd00::7]:7000");
  EXPECT_EQ(*AdvertisedAddress("fd00::7", "0.0.0.0:0", 4000, "box"), "[fd00::7]:4000");
  for (const char* bad : {"0.0.0.0", "[::]:7000", ":7000", "host:0", "host:70000", "host:x",
                          "a host", "host/path", "[fd00::7", "[fd00::7]x"}) {
    const absl::StatusOr<std::string> address = AdvertisedAddress(bad, "127.0.0.1:0", 1, "box");
    EXPECT_TRUE(absl::IsInvalidArgument(address.status())) << bad;
    EXPECT_THAT(address.status().message(), HasSubstr("--advertise")) << bad;
  }
}

TEST(ShardMapTest, JsonRoundTripAndBadValues) {
  const ShardMap map{.epoch = 3, .owners = {"a", "b", "a"}};
  const absl::StatusOr<ShardMap> back = ShardMap::FromJson(map.ToJson());
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(back->epoch, 3);
  EXPECT_EQ(back->owners, map.owners);
  EXPECT_EQ(back->ShardsOf("a"), (std::vector<int>{0, 2}));
  for (const char* bad : {"", "{}", "[1]", R"({"epoch":0,"owners":["a"]})",
                          R"({"epoch":1,"owners":[]})", R"({"epoch":1,"owners":[3]})"}) {
    EXPECT_EQ(ShardMap::FromJson(bad).status().code(), absl::StatusCode::kInvalidArgument) << bad;
  }
}

// Real etcd for each test, with a client to it; the test is skipped when etcd is not installed.
class ClusterEtcdTest : public ::testing::Test {
 protected:
  explicit ClusterEtcdTest(int members = 1) : members_(members) {}

  void SetUp() override {
    if (EtcdProcesses::Binary().empty()) GTEST_SKIP() << "etcd is not installed (etcd-server)";
    std::string error;
    ASSERT_TRUE(etcd_.Start(members_, &error)) << error;
    client_ = ClientOf(etcd_);
  }

  EtcdProcesses etcd_;
  std::unique_ptr<EtcdClient> client_;

 private:
  const int members_;
};

TEST_F(ClusterEtcdTest, KeysAndCompareAndSwap) {
  ASSERT_TRUE(client_->Put("/t/a", "1").ok());
  ASSERT_TRUE(client_->Put("/t/b", "2").ok());
  ASSERT_TRUE(client_->Put("/u", "3").ok());
  const absl::StatusOr<std::vector<KeyValue>> range = client_->Range("/t/");
  ASSERT_TRUE(range.ok()) << range.status();
  ASSERT_EQ(range->size(), 2u);
  EXPECT_EQ((*range)[1].value, "2");

  absl::StatusOr<SwapOutcome> swap = client_->CompareAndSwap("/t/c", 0, "new");
  ASSERT_TRUE(swap.ok() && swap->written);
  swap = client_->CompareAndSwap("/t/c", 0, "again");  // exists now
  ASSERT_TRUE(swap.ok());
  EXPECT_FALSE(swap->written);
  ASSERT_TRUE(swap->current.has_value());
  EXPECT_EQ(swap->current->value, "new");
  swap = client_->CompareAndSwap("/t/c", swap->current->mod_revision, "changed");
  ASSERT_TRUE(swap.ok() && swap->written);
  EXPECT_EQ((*client_->Get("/t/c"))->value, "changed");

  absl::StatusOr<bool> deleted = client_->DeleteIfRevision("/t/c", swap->revision - 1);  // stale
  ASSERT_TRUE(deleted.ok()) << deleted.status();
  EXPECT_FALSE(*deleted);
  EXPECT_TRUE(client_->Get("/t/c")->has_value());
  deleted = client_->DeleteIfRevision("/t/c", swap->revision);
  ASSERT_TRUE(deleted.ok() && *deleted);
  EXPECT_FALSE(client_->Get("/t/c")->has_value());
  deleted = client_->DeleteIfRevision("/t/c", swap->revision);  // gone already
  ASSERT_TRUE(deleted.ok());
  EXPECT_FALSE(*deleted);

  ASSERT_TRUE(client_->Delete("/t/a").ok());
  EXPECT_FALSE(client_->Get("/t/a")->has_value());
}

TEST_F(ClusterEtcdTest, ShardMapCompareAndSwapRefusesAStaleEpoch) {
  const ShardMapStore store(*client_, "stale");
  EXPECT_EQ(store.Read().status().code(), absl::StatusCode::kNotFound);
  EXPECT_THAT(std::string(store.Read().status().message()), HasSubstr("not initialised"));
  const absl::StatusOr<StoredShardMap> created = store.Create(8, {"a", "b"});
  ASSERT_TRUE(created.ok()) << created.status();
  EXPECT_EQ(created->map.epoch, 1);
  EXPECT_EQ(created->map.ShardsOf("b"), (std::vector<int>{1, 3, 5, 7}));
  EXPECT_EQ(store.Create(8, {"a"}).status().code(), absl::StatusCode::kAlreadyExists);

  ShardMap first = created->map;
  first.epoch = 2;
  first.owners[0] = "b";
  ASSERT_TRUE(store.Replace(*created, first).ok());
  ShardMap second = created->map;  // made from the same, now stale, map
  second.epoch = 2;
  second.owners[1] = "a";
  const absl::StatusOr<StoredShardMap> stale = store.Replace(*created, second);
  EXPECT_EQ(stale.status().code(), absl::StatusCode::kAborted);
  EXPECT_THAT(std::string(stale.status().message()), HasSubstr("epoch 2 now"));
  const absl::StatusOr<StoredShardMap> now = store.Read();
  ASSERT_TRUE(now.ok());
  EXPECT_EQ(now->map.owners, first.owners);  // the refused change left nothing

  ShardMap skipped = now->map;
  skipped.epoch = 5;
  EXPECT_EQ(store.Replace(*now, skipped).status().code(), absl::StatusCode::kInvalidArgument);
}

TEST_F(ClusterEtcdTest, MoveShardNeedsALiveShardNodeAndAShardInRange) {
  const ShardMapStore store(*client_, "move");
  EXPECT_EQ(store.MoveShard(0, "b").status().code(), absl::StatusCode::kNotFound);  // no map
  ASSERT_TRUE(store.Create(4, {"a"}).ok());
  auto b = NodeRegistration::Start(*client_, NodeOptions(etcd_, "move", "b"), nullptr);
  auto r = NodeRegistration::Start(*client_, NodeOptions(etcd_, "move", "r", "router"), nullptr);
  ASSERT_TRUE(b.ok() && r.ok());
  EXPECT_EQ(store.MoveShard(4, "b").status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(store.MoveShard(-1, "b").status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(store.MoveShard(0, "ghost").status().code(), absl::StatusCode::kNotFound);
  EXPECT_EQ(store.MoveShard(0, "r").status().code(), absl::StatusCode::kFailedPrecondition);
  const absl::StatusOr<StoredShardMap> moved = store.MoveShard(2, "b");
  ASSERT_TRUE(moved.ok()) << moved.status();
  EXPECT_EQ(moved->map.epoch, 2);
  EXPECT_EQ(moved->map.owners, (std::vector<std::string>{"a", "a", "b", "a"}));
  EXPECT_EQ(store.MoveShard(2, "b").status().code(), absl::StatusCode::kFailedPrecondition);
}

TEST_F(ClusterEtcdTest, RegistrationRefusesAHeldIdAndEndsWithItsNode) {
  std::vector<bool> changes;
  auto first =
      NodeRegistration::Start(*client_, NodeOptions(etcd_, "reg", "n1"),
                              [&changes](bool registered) { changes.push_back(registered); });
  ASSERT_TRUE(first.ok()) << first.status();
  EXPECT_TRUE((*first)->registered());
  EXPECT_EQ(changes, std::vector<bool>{true});
  EXPECT_TRUE(Listed(*client_, "reg", "n1"));

  const auto second = NodeRegistration::Start(*client_, NodeOptions(etcd_, "reg", "n1"), nullptr);
  EXPECT_EQ(second.status().code(), absl::StatusCode::kAlreadyExists);
  EXPECT_THAT(std::string(second.status().message()), HasSubstr("held by the shard node at"));

  (*first)->SetShards({3, 4});
  EXPECT_TRUE(PollUntil([&] {
    const absl::StatusOr<std::vector<NodeInfo>> nodes = ListNodes(*client_, "reg");
    return nodes.ok() && nodes->size() == 1 && (*nodes)[0].shards == std::vector<int>{3, 4};
  }));
  first->reset();  // revokes its lease: the key goes at once
  EXPECT_FALSE(Listed(*client_, "reg", "n1"));
  EXPECT_TRUE(NodeRegistration::Start(*client_, NodeOptions(etcd_, "reg", "n1"), nullptr).ok());
}

TEST_F(ClusterEtcdTest, WatchDeliversMapChanges) {
  std::mutex mutex;
  std::vector<int64_t> epochs;
  ShardMapWatcher watcher(*client_, NodeOptions(etcd_, "watch", "a"), [&](const ShardMap& map) {
    std::lock_guard<std::mutex> lock(mutex);
    epochs.push_back(map.epoch);
  });
  EXPECT_EQ(watcher.map(), nullptr);
  const ShardMapStore store(*client_, "watch");
  absl::StatusOr<StoredShardMap> stored = store.Create(4, {"a", "b"});
  ASSERT_TRUE(stored.ok());
  ASSERT_TRUE(PollUntil([&] { return watcher.map() != nullptr; }));
  for (int epoch = 2; epoch <= 4; ++epoch) {
    ShardMap next = stored->map;
    next.epoch = epoch;
    next.owners[epoch - 1] = "a";
    stored = store.Replace(*stored, next);
    ASSERT_TRUE(stored.ok()) << stored.status();
  }
  ASSERT_TRUE(PollUntil([&] { return watcher.map()->epoch == 4; }));
  EXPECT_EQ(watcher.map()->ShardsOf("a"), (std::vector<int>{0, 1, 2, 3}));
  std::lock_guard<std::mutex> lock(mutex);
  EXPECT_TRUE(std::is_sorted(epochs.begin(), epochs.end()));
  EXPECT_EQ(epochs.back(), 4);
}

// A write reads the map from etcd: with etcd gone CurrentMap tries again until its deadline,
// then fails UNAVAILABLE naming the last epoch, while map() still serves reads; etcd back, it
// answers. Without a cluster it says so at once.
TEST_F(ClusterEtcdTest, CurrentMapWaitsForEtcdUntilItsDeadline) {
  ShardMapWatcher watcher(*client_, NodeOptions(etcd_, "current", "a"), {});
  const absl::StatusOr<ShardMap> none = watcher.CurrentMap(absl::Now() + absl::Seconds(60));
  EXPECT_EQ(none.status().code(), absl::StatusCode::kNotFound);
  EXPECT_THAT(std::string(none.status().message()), HasSubstr("motiondb cluster init"));
  ASSERT_TRUE(ShardMapStore(*client_, "current").Create(4, {"a"}).ok());
  absl::StatusOr<ShardMap> current = watcher.CurrentMap(absl::Now() + absl::Seconds(60));
  ASSERT_TRUE(current.ok()) << current.status();
  EXPECT_EQ(current->epoch, 1);
  ASSERT_TRUE(PollUntil([&] { return watcher.map() != nullptr; }));

  etcd_.Stop(0, /*graceful=*/false);
  const absl::StatusOr<ShardMap> unread = watcher.CurrentMap(absl::Now() + absl::Seconds(1));
  EXPECT_EQ(unread.status().code(), absl::StatusCode::kUnavailable);
  EXPECT_THAT(std::string(unread.status().message()),
              HasSubstr("cluster 'current': the shard map cannot be read (the last map seen is "
                        "epoch 1): "));
  ASSERT_NE(watcher.map(), nullptr);  // reads go on from the last map
  EXPECT_EQ(watcher.map()->epoch, 1);

  // Waiting: etcd returns before the deadline, and the write gets its map.
  std::thread restart([&] {
    std::this_thread::sleep_for(std::chrono::seconds(1));
    std::string error;
    EXPECT_TRUE(etcd_.Restart(0, &error)) << error;
  });
  current = watcher.CurrentMap(absl::Now() + absl::Seconds(60));
  restart.join();
  ASSERT_TRUE(current.ok()) << current.status();
  EXPECT_EQ(current->epoch, 1);
}

TEST_F(ClusterEtcdTest, ClipIdBlocksHandOutUniqueIdsInWholeBlocks) {
  constexpr int64_t kBlock = 100;
  constexpr int kThreads = 4;
  constexpr int kIdsAThread = 625;  // with the four taken in turns, 5004 ids
  const std::unique_ptr<EtcdClient> other_client = ClientOf(etcd_);
  ClipIdBlocks routers[2] = {ClipIdBlocks(*client_, "ids", kBlock),
                             ClipIdBlocks(*other_client, "ids", kBlock)};
  // ids[r][0]: router r's taken in turns; ids[r][1 + t]: its thread t's; each in the order given.
  std::vector<std::vector<int64_t>> ids[2];
  // In turns: each router reserves a block of its own at its first id, then hands out of it.
  ids[0].push_back({*routers[0].Next()});
  ids[1].push_back({*routers[1].Next()});
  ids[0][0].push_back(*routers[0].Next());
  ids[1][0].push_back(*routers[1].Next());
  EXPECT_EQ(ids[0][0], (std::vector<int64_t>{1, 2}));
  EXPECT_EQ(ids[1][0], (std::vector<int64_t>{kBlock + 1, kBlock + 2}));

  // Then from four threads each, the routers racing for the counter.
  absl::Status failures[2][kThreads];
  std::vector<std::thread> threads;
  for (int r = 0; r < 2; ++r) {
    ids[r].resize(1 + kThreads);
    for (int t = 0; t < kThreads; ++t) {
      threads.emplace_back([&routers, &ids, &failures, r, t] {
        for (int i = 0; i < kIdsAThread; ++i) {
          const absl::StatusOr<int64_t> id = routers[r].Next();
          if (!id.ok()) {
            failures[r][t] = id.status();
            return;
          }
          ids[r][1 + t].push_back(*id);
        }
      });
    }
  }
  for (std::thread& thread : threads) thread.join();

  std::set<int64_t> all;
  size_t count = 0;
  std::map<int64_t, int> owner;    // block (from 0) -> its router
  std::map<int64_t, int> used[2];  // router -> block -> ids handed out of it
  for (int r = 0; r < 2; ++r) {
    for (int t = 0; t < kThreads; ++t) ASSERT_TRUE(failures[r][t].ok()) << failures[r][t];
    for (const std::vector<int64_t>& taken : ids[r]) {
      EXPECT_TRUE(std::is_sorted(taken.begin(), taken.end()));
      for (const int64_t id : taken) {
        all.insert(id);
        ++count;
        const int64_t block = (id - 1) / kBlock;
        EXPECT_EQ(owner.emplace(block, r).first->second, r) << "block " << block;
        ++used[r][block];
      }
    }
  }
  EXPECT_EQ(count, 4u + 2 * kThreads * kIdsAThread);
  EXPECT_EQ(all.size(), count);  // no id twice
  for (int r = 0; r < 2; ++r) {
    int partial = 0;  // only the block a router holds now is partly handed out
    for (const auto& [block, ids_used] : used[r]) partial += ids_used < kBlock ? 1 : 0;
    EXPECT_LE(partial, 1) << "router " << r;
  }
  // Every block reserved was handed out from, and the counter is past the last one.
  EXPECT_EQ((*client_->Get(NextClipIdKey("ids")))->value,
            std::to_string(1 + kBlock * static_cast<int64_t>(owner.size())));
  EXPECT_EQ(owner.rbegin()->first + 1, static_cast<int64_t>(owner.size()));
}

TEST_F(ClusterEtcdTest, ClipIdBlocksRefuseACorruptCounter) {
  const std::string key = NextClipIdKey("bad");
  for (const char* bad : {"abc", "0", "-5", "12x", " 12", "+12", ""}) {
    ASSERT_TRUE(client_->Put(key, bad).ok());
    ClipIdBlocks blocks(*client_, "bad", 10);
    const absl::StatusOr<int64_t> id = blocks.Next();
    EXPECT_EQ(id.status().code(), absl::StatusCode::kFailedPrecondition) << bad;
    EXPECT_THAT(std::string(id.status().message()), HasSubstr("etcd key '/bad/next_clip_id' holds"))
        << bad;
  }
  // The counter holds the first id not reserved yet.
  ASSERT_TRUE(client_->Put(key, "41").ok());
  ClipIdBlocks blocks(*client_, "bad", 10);
  EXPECT_EQ(*blocks.Next(), 41);
  EXPECT_EQ((*client_->Get(key))->value, "51");
}

TEST_F(ClusterEtcdTest, ClipNamesHaveOneHolderAtATime) {
  const ClipNames names(*client_, "names", 16);
  ASSERT_TRUE(names.Reserve("walk", 7).ok());
  EXPECT_TRUE(names.Reserve("walk", 7).ok());  // a retried request
  const absl::Status taken = names.Reserve("walk", 8);
  EXPECT_EQ(taken.code(), absl::StatusCode::kAlreadyExists);
  EXPECT_EQ(taken.message(), "clip name 'walk' is taken by clip 7");
  EXPECT_EQ(*names.Lookup("walk"), 7);

  EXPECT_FALSE(*names.Release("walk", 8));  // not its holder: left as it is
  EXPECT_EQ(*names.Lookup("walk"), 7);
  EXPECT_TRUE(*names.Release("walk", 7));
  EXPECT_EQ(*names.Lookup("walk"), std::nullopt);
  EXPECT_FALSE(*names.Release("walk", 7));  // released already
  ASSERT_TRUE(names.Reserve("walk", 8).ok());
  EXPECT_EQ(*names.Lookup("walk"), 8);

  // A replacement's new id takes the name over from its holder only.
  EXPECT_FALSE(*names.Reassign("walk", 7, 9));  // not its holder
  EXPECT_TRUE(*names.Reassign("walk", 8, 9));
  EXPECT_EQ(*names.Lookup("walk"), 9);
  EXPECT_FALSE(*names.Reassign("run", 8, 9));  // free: left free
  EXPECT_EQ(*names.Lookup("run"), std::nullopt);
  EXPECT_EQ(names.Reassign("walk", 9, 0).status().code(), absl::StatusCode::kInvalidArgument);

  EXPECT_EQ(names.Reserve("", 1).code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(names.Reserve(std::string(17, 'x'), 1).code(), absl::StatusCode::kInvalidArgument);
  EXPECT_TRUE(names.Reserve(std::string(16, 'x'), 1).ok());
  EXPECT_EQ(names.Reserve("zero", 0).code(), absl::StatusCode::kInvalidArgument);

  ASSERT_TRUE(client_->Put(ClipNameKey("names", "odd"), "seven").ok());
  const absl::StatusOr<std::optional<int64_t>> odd = names.Lookup("odd");
  EXPECT_EQ(odd.status().code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_THAT(std::string(odd.status().message()), HasSubstr("'/names/clip_names/odd'"));
}

// After a store on a held name's shard the name follows the clip stored; a name its holder gave
// up meanwhile (renamed, deleted) is reserved for the clip stored; one another clip reserved
// meanwhile is reported, not taken.
TEST_F(ClusterEtcdTest, SettleGivesTheNameToTheClipStored) {
  const ShardMapWatcher watcher(*client_, NodeOptions(etcd_, "settle", "a"), nullptr);
  ClipRouter router(*client_, watcher, "settle", 512);
  const ClipNames names(*client_, "settle", 512);
  ASSERT_TRUE(names.Reserve("walk", 7).ok());
  ClipRoute route;
  route.clip_id = 9;
  route.held_by = 7;
  ASSERT_TRUE(router.Settle("walk", route, 9).ok());
  EXPECT_EQ(*names.Lookup("walk"), 9);

  ASSERT_TRUE(*names.Release("walk", 9));
  route.clip_id = 11;
  route.held_by = 9;
  ASSERT_TRUE(router.Settle("walk", route, 11).ok());
  EXPECT_EQ(*names.Lookup("walk"), 11);

  ASSERT_TRUE(*names.Release("walk", 11));
  ASSERT_TRUE(names.Reserve("walk", 12).ok());
  route.clip_id = 13;
  route.held_by = 11;
  const absl::Status reported = router.Settle("walk", route, 13);
  EXPECT_EQ(reported.code(), absl::StatusCode::kAborted);
  EXPECT_THAT(std::string(reported.message()),
              HasSubstr("clip 13 was stored as 'walk', which another clip reserved meanwhile"));
  EXPECT_EQ(*names.Lookup("walk"), 12);
}

TEST_F(ClusterEtcdTest, ClipNamesWithSlashesAndPrefixesAreEachTheirOwn) {
  const ClipNames names(*client_, "paths", 64);
  for (const auto& [name, id] : std::vector<std::pair<std::string, int64_t>>{
           {"run", 1}, {"run/fast", 2}, {"running", 3}, {"run/fast/left", 4}, {"Läufer 🏃", 5}}) {
    ASSERT_TRUE(names.Reserve(name, id).ok()) << name;
  }
  EXPECT_TRUE(*names.Release("run", 1));
  EXPECT_EQ(*names.Lookup("run"), std::nullopt);
  EXPECT_EQ(*names.Lookup("run/fast"), 2);
  EXPECT_EQ(*names.Lookup("running"), 3);
  EXPECT_TRUE(*names.Release("run/fast", 2));
  EXPECT_EQ(*names.Lookup("run/fast/left"), 4);
  EXPECT_EQ(*names.Lookup("Läufer 🏃"), 5);
  EXPECT_EQ(*names.Lookup("run/"), std::nullopt);
}

// Whether `said` begins with `prefix` (a candidate may flap later under load; the tests judge
// what must have come first).
bool BeginsWith(const std::vector<bool>& said, const std::vector<bool>& prefix) {
  return said.size() >= prefix.size() && std::equal(prefix.begin(), prefix.end(), said.begin());
}

// The one of `candidates` that leads, once one does; nullptr if none does within the bound. Two
// leading at once fails the test: a leader counts itself one only while its lease surely lives,
// and another can take the office only once etcd has let that lease go. Each candidate is asked
// twice, so that an office passing between two questions is not taken for two leaders: one that
// says yes both times led throughout, over the others' answers between.
LeaderElection* OnlyLeader(const std::vector<LeaderElection*>& candidates) {
  LeaderElection* leader = nullptr;
  PollUntil([&] {
    std::vector<bool> first, second;
    for (LeaderElection* candidate : candidates) first.push_back(candidate->leading());
    for (LeaderElection* candidate : candidates) second.push_back(candidate->leading());
    int steady = 0;
    for (size_t i = 0; i < candidates.size(); ++i) {
      if (!first[i] || !second[i]) continue;
      ++steady;
      leader = candidates[i];
      for (size_t j = 0; j < candidates.size(); ++j) {
        // The answers asked between i's two: j's second before i, j's first after i.
        if (j == i) continue;
        EXPECT_FALSE(j < i ? second[j] : first[j]) << "two leaders at once";
      }
    }
    return steady == 1;
  });
  return leader;
}

// Whether the office is free of `node_id` now: after its resignation returned, the key is gone
// or another's, whatever the lease (long enough, in these tests, not to have run out).
void ExpectResigned(const EtcdClient& client, const std::string& node_id) {
  const absl::StatusOr<std::optional<KeyValue>> held = client.Get(ElectionKey("elect", "jobs"));
  ASSERT_TRUE(held.ok()) << held.status();
  EXPECT_TRUE(!held->has_value() || (*held)->value != node_id) << node_id << " holds it still";
}

// Resignation is judged under a lease of 10 s, so that its expiry does not pass for it.
constexpr absl::Duration kResignTtl = absl::Seconds(10);

TEST_F(ClusterEtcdTest, OneOfTwoCandidatesLeadsAndTheOtherTakesOverWhenItResigns) {
  const std::unique_ptr<EtcdClient> other_client = ClientOf(etcd_);
  std::unique_ptr<LeaderElection> a = Candidate(*client_, "a", nullptr, kResignTtl);
  std::unique_ptr<LeaderElection> b = Candidate(*other_client, "b", nullptr, kResignTtl);
  ASSERT_TRUE(a && b);
  LeaderElection* first = OnlyLeader({a.get(), b.get()});
  ASSERT_NE(first, nullptr);
  std::unique_ptr<LeaderElection>& leader = first == a.get() ? a : b;
  std::unique_ptr<LeaderElection>& other = first == a.get() ? b : a;
  const std::string first_id = first == a.get() ? "a" : "b";
  const std::string other_id = first == a.get() ? "b" : "a";
  EXPECT_EQ(LeaderOf(*other), first_id);

  leader.reset();  // resigns
  ExpectResigned(*client_, first_id);
  EXPECT_EQ(OnlyLeader({other.get()}), other.get());
  EXPECT_EQ(LeaderOf(*other), other_id);
}

TEST_F(ClusterEtcdTest, ALaterCandidateWaitsItsTurn) {
  const std::unique_ptr<EtcdClient> other_client = ClientOf(etcd_);
  std::vector<std::unique_ptr<LeaderElection>> candidates;
  const std::vector<std::string> ids = {"a", "b", "c"};
  candidates.push_back(Candidate(*client_, "a", nullptr, kResignTtl));
  candidates.push_back(Candidate(*other_client, "b", nullptr, kResignTtl));
  ASSERT_TRUE(candidates[0] && candidates[1]);
  LeaderElection* first = OnlyLeader({candidates[0].get(), candidates[1].get()});
  ASSERT_NE(first, nullptr);
  candidates.push_back(Candidate(*client_, "c", nullptr, kResignTtl));
  ASSERT_TRUE(candidates[2]);
  EXPECT_FALSE(candidates[2]->leading());  // the office is held
  EXPECT_EQ(LeaderOf(*candidates[2]), first == candidates[0].get() ? "a" : "b");

  // Each resignation passes the office to one of those still waiting, until the last.
  std::map<LeaderElection*, std::string> id_of;
  for (size_t i = 0; i < candidates.size(); ++i) id_of[candidates[i].get()] = ids[i];
  while (candidates.size() > 1) {
    std::vector<LeaderElection*> running;
    for (const std::unique_ptr<LeaderElection>& candidate : candidates) {
      running.push_back(candidate.get());
    }
    LeaderElection* leader = OnlyLeader(running);
    ASSERT_NE(leader, nullptr);
    const std::string leader_id = id_of[leader];
    std::erase_if(candidates, [&](const auto& candidate) { return candidate.get() == leader; });
    ExpectResigned(*client_, leader_id);
  }
  EXPECT_EQ(OnlyLeader({candidates[0].get()}), candidates[0].get());
}

TEST_F(ClusterEtcdTest, ALeaderWhoseLeaseIsRevokedStepsDown) {
  const std::unique_ptr<EtcdClient> other_client = ClientOf(etcd_);
  Changes changes[2];
  const std::unique_ptr<LeaderElection> a = Candidate(*client_, "a", changes[0].Recorder());
  const std::unique_ptr<LeaderElection> b = Candidate(*other_client, "b", changes[1].Recorder());
  ASSERT_TRUE(a && b);
  LeaderElection* first = OnlyLeader({a.get(), b.get()});
  ASSERT_NE(first, nullptr);
  Changes& first_changes = changes[first == a.get() ? 0 : 1];
  const absl::StatusOr<std::optional<KeyValue>> held = client_->Get(ElectionKey("elect", "jobs"));
  ASSERT_TRUE(held.ok() && held->has_value());
  ASSERT_TRUE(client_->RevokeLease((*held)->lease).ok());  // behind the leader's back

  EXPECT_TRUE(PollUntil([&] { return BeginsWith(first_changes.said(), {true, false}); }));
  // Whoever leads next (the other, let in while it stands back, or it again) leads alone.
  EXPECT_NE(OnlyLeader({a.get(), b.get()}), nullptr);
}

TEST_F(ClusterEtcdTest, ALeaderCutOffFromEtcdStepsDownAndLeadsAgainOnItsReturn) {
  Changes a_changes;
  const std::unique_ptr<LeaderElection> a = Candidate(*client_, "a", a_changes.Recorder());
  ASSERT_TRUE(a);
  ASSERT_TRUE(PollUntil([&] { return a->leading(); }));
  etcd_.Stop(0, /*graceful=*/true);
  // It cannot renew: once the lease may have expired, it says it no longer leads.
  EXPECT_TRUE(PollUntil([&] { return BeginsWith(a_changes.said(), {true, false}); }));
  EXPECT_FALSE(a->leading());
  std::string error;
  ASSERT_TRUE(etcd_.Restart(0, &error)) << error;
  EXPECT_TRUE(PollUntil([&] { return BeginsWith(a_changes.said(), {true, false, true}); }));
}

TEST_F(ClusterEtcdTest, ElectionRefusesBadNames) {
  for (const auto& [cluster, office, node_id] :
       std::vector<std::array<std::string, 3>>{{"", "jobs", "a"},
                                               {"elect", "", "a"},
                                               {"elect", "jobs/x", "a"},
                                               {"elect", "jobs", ""},
                                               {"elect", "jobs", "a b"},
                                               {"elect", std::string(65, 'o'), "a"}}) {
    const absl::StatusOr<std::unique_ptr<LeaderElection>> election =
        LeaderElection::Start(*client_, cluster, office, node_id, absl::Seconds(2), nullptr);
    EXPECT_EQ(election.status().code(), absl::StatusCode::kInvalidArgument)
        << cluster << " " << office << " " << node_id;
  }
  EXPECT_EQ(LeaderElection::Start(*client_, "elect", "jobs", "a", absl::Milliseconds(500), nullptr)
                .status()
                .code(),
            absl::StatusCode::kInvalidArgument);
}

// Three members, so that one can be killed.
class ClusterFailoverTest : public ClusterEtcdTest {
 protected:
  ClusterFailoverTest() : ClusterEtcdTest(3) {}
};

TEST_F(ClusterFailoverTest, ClientAndWatchGoOnWhenAMemberIsKilled) {
  const ShardMapStore store(*client_, "failover");
  absl::StatusOr<StoredShardMap> stored = store.Create(4, {"a"});
  ASSERT_TRUE(stored.ok()) << stored.status();
  ShardMapWatcher watcher(*client_, NodeOptions(etcd_, "failover", "a"), nullptr);
  ASSERT_TRUE(PollUntil([&] { return watcher.map() != nullptr; }));

  etcd_.Stop(0, /*graceful=*/false);  // the member every call and the watch went to first
  ASSERT_TRUE(client_->Put("/failover/probe", "after").ok());
  EXPECT_EQ((*client_->Get("/failover/probe"))->value, "after");
  ShardMap next = stored->map;
  next.epoch = 2;
  next.owners[0] = "b";
  ASSERT_TRUE(store.Replace(*stored, next).ok());
  EXPECT_TRUE(PollUntil([&] { return watcher.map()->epoch == 2; }));
}

// With one of three members killed the election goes on through the other two: never two
// leaders at once, someone leads, and a resignation passes the office on.
TEST_F(ClusterFailoverTest, TheElectionGoesOnWhenAMemberIsKilled) {
  // A lease long enough that etcd electing a new raft leader does not outlast it.
  constexpr absl::Duration kTtl = absl::Seconds(6);
  const std::unique_ptr<EtcdClient> other_client = ClientOf(etcd_);
  std::unique_ptr<LeaderElection> a = Candidate(*client_, "a", nullptr, kTtl);
  std::unique_ptr<LeaderElection> b = Candidate(*other_client, "b", nullptr, kTtl);
  ASSERT_TRUE(a && b);
  ASSERT_NE(OnlyLeader({a.get(), b.get()}), nullptr);

  etcd_.Stop(0, /*graceful=*/false);
  // Two TTLs of watching that no two lead at once (whether the leader kept its lease through
  // the failover depends on the machine's load, so it is not judged).
  const auto until = std::chrono::steady_clock::now() + absl::ToChronoMilliseconds(2 * kTtl);
  while (std::chrono::steady_clock::now() < until) {
    const bool a_before = a->leading(), b_between = b->leading(), a_after = a->leading();
    ASSERT_FALSE(a_before && b_between && a_after) << "two leaders at once";
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  LeaderElection* leader = OnlyLeader({a.get(), b.get()});
  ASSERT_NE(leader, nullptr);
  std::unique_ptr<LeaderElection>& other = leader == a.get() ? b : a;
  (leader == a.get() ? a : b).reset();
  EXPECT_EQ(OnlyLeader({other.get()}), other.get());
}

// The standard health answer for the server as a whole ("" service): readiness.
bool Serving(const std::shared_ptr<grpc::Channel>& channel) {
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(2));
  grpc::health::v1::HealthCheckResponse response;
  return grpc::health::v1::Health::NewStub(channel)
             ->Check(&context, grpc::health::v1::HealthCheckRequest(), &response)
             .ok() &&
         response.status() == grpc::health::v1::HealthCheckResponse::SERVING;
}

class ClusterServerTest : public ClusterEtcdTest {};

// Shard nodes s1 and s2 and router r1 of the cluster "motiondb" (their databases in `dir`, their
// other flags `extra_flags`, the router's HTTP face on with `router_http`), each listed in etcd,
// and the map of 4 shards over s1 and s2 that the cluster starts with.
void StartTwoShardsAndARouter(const EtcdProcesses& etcd, const EtcdClient& client,
                              const std::filesystem::path& dir,
                              std::map<std::string, testing::ServerProcess>& nodes, ShardMap& map,
                              const std::vector<std::string>& extra_flags = {},
                              bool router_http = false) {
  std::string error;
  for (const std::string id : {"s1", "s2", "r1"}) {
    std::vector<std::string> args = {"--db",
                                     (dir / (id + ".sqlite")).string(),
                                     "--quiet",
                                     "--cluster",
                                     etcd.endpoints_flag(),
                                     "--node-id",
                                     id,
                                     "--role",
                                     id == "r1" ? "router" : "shard",
                                     "--cluster-lease-s",
                                     "2"};
    if (id != "r1" || !router_http) args.insert(args.end(), {"--http", "off"});
    args.insert(args.end(), extra_flags.begin(), extra_flags.end());
    ASSERT_TRUE(nodes[id].Start(args, &error)) << error;
  }
  ASSERT_TRUE(PollUntil([&] {
    return Listed(client, "motiondb", "s1") && Listed(client, "motiondb", "s2") &&
           Listed(client, "motiondb", "r1");
  }));
  const ShardMapStore store(client, "motiondb");
  ASSERT_TRUE(store.Create(4, {"s1", "s2"}).ok());
  map = store.Read()->map;
}

TEST_F(ClusterServerTest, RegistersIsListedSurvivesEtcdAndRegistersAgain) {
  std::string error;
  const std::filesystem::path dir = testing::MakeTempDir("cluster_server");
  const std::vector<std::string> node_flags = {
      "--cluster", etcd_.endpoints_flag(), "--node-id", "s1", "--cluster-lease-s", "2", "--quiet"};
  std::vector<std::string> args = {"--db", (dir / "s1.sqlite").string()};
  args.insert(args.end(), node_flags.begin(), node_flags.end());
  testing::ServerProcess server;
  ASSERT_TRUE(server.Start(args, &error)) << error;
  const auto channel = testing::InsecureChannel(server.address());
  ASSERT_TRUE(PollUntil([&] { return Listed(*client_, "motiondb", "s1") && Serving(channel); }))
      << server.Log();

  // A second node under the same id is refused, and exits.
  testing::ServerProcess twin;
  std::vector<std::string> twin_args = {"--db", (dir / "twin.sqlite").string()};
  twin_args.insert(twin_args.end(), node_flags.begin(), node_flags.end());
  ASSERT_TRUE(twin.Start(twin_args, &error)) << error;  // it serves, then joins the cluster
  EXPECT_TRUE(PollUntil([&] {
    return twin.Log().find("node id 's1' of cluster 'motiondb' is held by") != std::string::npos;
  })) << twin.Log();
  EXPECT_EQ(twin.Stop(SIGTERM), 1);  // exited 1 already: the signal finds it gone

  const std::string ep = etcd_.endpoints_flag();
  testing::CommandResult cli = testing::RunCli({"cluster", "status", "--etcd", ep});
  EXPECT_EQ(cli.exit_code, 0) << cli.err;
  EXPECT_THAT(cli.out, HasSubstr("not initialised"));
  cli = testing::RunCli({"cluster", "init", "--etcd", ep, "--shards", "8"});
  ASSERT_EQ(cli.exit_code, 0) << cli.err;
  cli = testing::RunCli({"cluster", "status", "--etcd", ep});
  EXPECT_EQ(cli.exit_code, 0) << cli.err;
  EXPECT_THAT(cli.out, HasSubstr("shard map epoch 1, 8 shards"));
  EXPECT_THAT(cli.out, HasSubstr(absl::StrCat("etcd members: ", ep, " leader\n")));
  EXPECT_THAT(cli.out, ::testing::ContainsRegex("s1 +shard +127.0.0.1:[0-9]+ +[0-9]+ s +8"));
  cli = testing::RunCli({"cluster", "init", "--etcd", ep});
  EXPECT_EQ(cli.exit_code, 1);
  EXPECT_THAT(cli.err, HasSubstr("initialised already"));
  cli = testing::RunCli({"cluster", "move-shard", "8", "s1", "--etcd", ep});
  EXPECT_EQ(cli.exit_code, 1);
  EXPECT_THAT(cli.err, HasSubstr("shard 8 is out of range"));
  cli = testing::RunCli({"cluster", "move-shard", "0", "ghost", "--etcd", ep});
  EXPECT_EQ(cli.exit_code, 1);
  EXPECT_THAT(cli.err, HasSubstr("'ghost' is not a live node"));
  // The node writes the shards the map gives it to its key.
  EXPECT_TRUE(PollUntil([&] {
    const absl::StatusOr<std::vector<NodeInfo>> nodes = ListNodes(*client_, "motiondb");
    return nodes.ok() && nodes->size() == 1 && (*nodes)[0].shards.size() == 8;
  }));

  // etcd gone: the server keeps answering, no longer ready; etcd back: registered again.
  etcd_.Stop(0, /*graceful=*/true);
  cli = testing::RunCli({"cluster", "status", "--etcd", ep});
  EXPECT_EQ(cli.exit_code, 1);
  EXPECT_THAT(cli.err, HasSubstr("etcd is unreachable"));
  ASSERT_TRUE(PollUntil([&] { return !Serving(channel); })) << server.Log();
  {
    grpc::ClientContext context;
    v1::ServerInfo info;
    EXPECT_TRUE(v1::ServerService::NewStub(channel)->GetServerInfo(&context, {}, &info).ok());
  }
  ASSERT_TRUE(etcd_.Restart(0, &error)) << error;
  EXPECT_TRUE(PollUntil([&] { return Listed(*client_, "motiondb", "s1") && Serving(channel); }))
      << server.Log();

  // Killed, it stops renewing: its key goes within the lease.
  server.Stop(SIGKILL);
  EXPECT_TRUE(PollUntil([&] { return !Listed(*client_, "motiondb", "s1"); }));
}

// The routers elect one job coordinator, shown by `motiondb cluster status`; when it is killed
// another router takes the office once its lease is gone; a router stopped cleanly resigns.
TEST_F(ClusterServerTest, TheRoutersElectOneJobCoordinator) {
  std::string error;
  const std::filesystem::path dir = testing::MakeTempDir("cluster_routers");
  std::map<std::string, testing::ServerProcess> routers;
  for (const std::string id : {"r1", "r2"}) {
    ASSERT_TRUE(routers[id].Start(
        {"--db", (dir / (id + ".sqlite")).string(), "--http", "off", "--quiet", "--cluster",
         etcd_.endpoints_flag(), "--node-id", id, "--role", "router", "--cluster-lease-s", "2"},
        &error))
        << error;
  }
  const auto coordinator = [&]() -> std::string {
    const testing::CommandResult cli =
        testing::RunCli({"cluster", "status", "--etcd", etcd_.endpoints_flag()});
    EXPECT_EQ(cli.exit_code, 0) << cli.err;
    for (const std::string id : {"r1", "r2"}) {
      if (cli.out.find("job coordinator: " + id + "\n") != std::string::npos) return id;
    }
    return "";
  };
  std::string first;
  ASSERT_TRUE(PollUntil([&] { return !(first = coordinator()).empty(); }))
      << routers["r1"].Log() << routers["r2"].Log();
  const std::string second = first == "r1" ? "r2" : "r1";
  routers[first].Stop(SIGKILL);  // no resignation: the office goes with its lease
  EXPECT_TRUE(PollUntil([&] { return coordinator() == second; })) << routers[second].Log();
  // A clean stop resigns: the office is free as soon as the process is gone, not a lease later.
  routers[second].Stop(SIGTERM);
  const testing::CommandResult cli =
      testing::RunCli({"cluster", "status", "--etcd", etcd_.endpoints_flag()});
  EXPECT_THAT(cli.out, HasSubstr("job coordinator: none"));
}

// A shard node stores a routed take only when the map, read from etcd for the write, gives
// the clip's shard to it: a router routing by an older map stores nothing on the wrong node.
TEST_F(ClusterServerTest, AShardNodeStoresOnlyTheClipsOfItsShards) {
  std::string error;
  const std::filesystem::path dir = testing::MakeTempDir("cluster_store");
  std::map<std::string, testing::ServerProcess> shards;
  for (const std::string id : {"s1", "s2"}) {
    ASSERT_TRUE(shards[id].Start({"--db", (dir / (id + ".sqlite")).string(), "--http", "off",
                                  "--quiet", "--cluster", etcd_.endpoints_flag(), "--node-id", id},
                                 &error))
        << error;
  }
  ASSERT_TRUE(PollUntil(
      [&] { return Listed(*client_, "motiondb", "s1") && Listed(*client_, "motiondb", "s2"); }));
  const ShardMapStore store(*client_, "motiondb");
  ASSERT_TRUE(store.Create(4, {"s1", "s2"}).ok());
  // The first ids whose shards s1 and s2 hold.
  const ShardMap map = store.Read()->map;
  std::map<std::string, int64_t> id_of;
  for (int64_t id = 1; id_of.size() < 2; ++id) {
    id_of.try_emplace(map.owners[ShardOfClip(id, map.shard_count())], id);
  }

  auto s1 = shard::v1::ShardService::NewStub(testing::InsecureChannel(shards["s1"].address()));
  const auto store_take = [&](int64_t clip_id, const std::string& name, int take,
                              v1::IngestClipResponse* response) {
    shard::v1::StoreTakeRequest request;
    request.mutable_ingest()->set_file_name(name + ".bvh");
    request.mutable_ingest()->set_bvh(BvhText(ChainClip()));
    request.set_take(take);
    request.set_clip_id(clip_id);
    grpc::ClientContext context;
    context.set_deadline(std::chrono::system_clock::now() + kBound);
    return s1->StoreTake(&context, request, response);
  };
  const auto clips_on_s1 = [&] {
    auto clips = v1::ClipService::NewStub(testing::InsecureChannel(shards["s1"].address()));
    grpc::ClientContext context;
    v1::ListClipsResponse listed;
    EXPECT_TRUE(clips->ListClips(&context, {}, &listed).ok());
    std::vector<int64_t> ids;
    for (const v1::Clip& clip : listed.clips()) ids.push_back(clip.clip_id());
    return ids;
  };

  v1::IngestClipResponse stored;
  grpc::Status status = store_take(id_of["s1"], "own", 0, &stored);
  ASSERT_TRUE(status.ok()) << status.error_message() << shards["s1"].Log();
  EXPECT_EQ(stored.clip().clip_id(), id_of["s1"]);
  EXPECT_EQ(stored.clip().name(), "own");

  // Another node's shard, an id held, a take the file lacks, no id: refused, nothing stored.
  status = store_take(id_of["s2"], "theirs", 0, &stored);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::FAILED_PRECONDITION);
  EXPECT_THAT(status.error_message(),
              HasSubstr(absl::StrCat("clip ", id_of["s2"], "'s shard ", ShardOfClip(id_of["s2"], 4),
                                     " is node 's2''s in the map "
                                     "of epoch 1, not this node's ('s1')")));
  EXPECT_EQ(store_take(id_of["s1"], "again", 0, &stored).error_code(),
            grpc::StatusCode::ALREADY_EXISTS);
  status = store_take(id_of["s1"], "take", 1, &stored);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("take 1: 'take.bvh' has 1 takes"));
  EXPECT_EQ(store_take(0, "none", 0, &stored).error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  // Nor does the node store a clip sent to it directly: its id and name would be no router's.
  {
    auto clips = v1::ClipService::NewStub(testing::InsecureChannel(shards["s1"].address()));
    v1::IngestClipRequest direct;
    direct.set_file_name("direct.bvh");
    direct.set_bvh(BvhText(ChainClip()));
    grpc::ClientContext context;
    status = clips->IngestClip(&context, direct, &stored);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::FAILED_PRECONDITION);
    EXPECT_THAT(status.error_message(), HasSubstr("clips are stored through a router"));
    // Nor renames one: the name is the cluster's, reserved by a router, which then renames
    // through ShardService.UpdateClip, fenced as StoreTake is.
    v1::UpdateClipRequest rename;
    rename.set_clip_id(id_of["s1"]);
    rename.set_name("own-renamed");
    v1::Clip renamed;
    grpc::ClientContext direct_rename;
    status = clips->UpdateClip(&direct_rename, rename, &renamed);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::FAILED_PRECONDITION);
    EXPECT_THAT(status.error_message(), HasSubstr("renamed through a router"));
    grpc::ClientContext routed_rename;
    status = s1->UpdateClip(&routed_rename, rename, &renamed);
    ASSERT_TRUE(status.ok()) << status.error_message();
    EXPECT_EQ(renamed.name(), "own-renamed");
    rename.set_clip_id(id_of["s2"]);
    grpc::ClientContext fenced_rename;
    status = s1->UpdateClip(&fenced_rename, rename, &renamed);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::FAILED_PRECONDITION);
    EXPECT_THAT(status.error_message(), HasSubstr("is node 's2''s in the map"));
  }
  EXPECT_THAT(clips_on_s1(), ::testing::ElementsAre(id_of["s1"]));

  // Once the map gives the shard to s1, s1 stores its clips at once: the map is read for the
  // write, not waited for from the watch.
  const testing::CommandResult moved =
      testing::RunCli({"cluster", "move-shard", absl::StrCat(ShardOfClip(id_of["s2"], 4)), "s1",
                       "--etcd", etcd_.endpoints_flag()});
  ASSERT_EQ(moved.exit_code, 0) << moved.err;
  status = store_take(id_of["s2"], "theirs", 0, &stored);
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_EQ(stored.clip().clip_id(), id_of["s2"]);
  EXPECT_THAT(clips_on_s1(), ::testing::UnorderedElementsAre(id_of["s1"], id_of["s2"]));

  // Without etcd the map cannot be read: the write waits until shortly before its deadline (a
  // tenth of it, here a second) and fails UNAVAILABLE then.
  etcd_.Stop(0, /*graceful=*/true);
  shard::v1::StoreTakeRequest request;
  request.mutable_ingest()->set_file_name("late.bvh");
  request.mutable_ingest()->set_bvh(BvhText(ChainClip()));
  request.set_clip_id(id_of["s1"] + 4);
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(10));
  status = s1->StoreTake(&context, request, &stored);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::UNAVAILABLE) << status.error_message();
  EXPECT_THAT(status.error_message(), HasSubstr("the shard map cannot be read"));
  EXPECT_THAT(clips_on_s1(), ::testing::UnorderedElementsAre(id_of["s1"], id_of["s2"]));
}

// A router stores each take on the shard node its clip id belongs to, the ids and names unique
// cluster-wide; a name stored already goes to its clip's shard, which decides the conflict as one
// node does; a shard node that is gone makes the ingest UNAVAILABLE naming it.
TEST_F(ClusterServerTest, ARouterStoresEachClipOnItsShard) {
  std::map<std::string, testing::ServerProcess> nodes;
  ShardMap map;
  ASSERT_NO_FATAL_FAILURE(
      StartTwoShardsAndARouter(etcd_, *client_, testing::MakeTempDir("cluster_route"), nodes, map));

  auto router = v1::ClipService::NewStub(testing::InsecureChannel(nodes["r1"].address()));
  const auto ingest = [&](const std::string& name, double speed, v1::OnConflict on_conflict,
                          v1::IngestClipResponse* response) {
    v1::IngestClipRequest request;
    request.set_file_name("take.bvh");
    request.set_name(name);
    request.set_bvh(BvhText(ChainClip(speed)));
    request.set_on_conflict(on_conflict);
    grpc::ClientContext context;
    context.set_deadline(std::chrono::system_clock::now() + kBound);
    return router->IngestClip(&context, request, response);
  };
  const auto clips_on = [&](const std::string& node) {
    auto clips = v1::ClipService::NewStub(testing::InsecureChannel(nodes[node].address()));
    grpc::ClientContext context;
    v1::ListClipsResponse listed;
    EXPECT_TRUE(clips->ListClips(&context, {}, &listed).ok()) << node;
    std::map<int64_t, std::string> names;
    for (const v1::Clip& clip : listed.clips()) names[clip.clip_id()] = clip.name();
    return names;
  };

  std::map<int64_t, std::string> routed;  // id -> name
  for (int i = 0; i < 6; ++i) {
    const std::string name = absl::StrCat("take_", i);
    v1::IngestClipResponse response;
    const grpc::Status status =
        ingest(name, 0.01 * (i + 1), v1::ON_CONFLICT_UNSPECIFIED, &response);
    ASSERT_TRUE(status.ok()) << status.error_message() << nodes["r1"].Log();
    EXPECT_EQ(response.result(), v1::INGEST_RESULT_STORED);
    EXPECT_EQ(response.clip().name(), name);
    EXPECT_TRUE(routed.emplace(response.clip().clip_id(), name).second) << "a repeated id";
  }
  std::map<int64_t, std::string> stored;
  for (const std::string node : {"s1", "s2"}) {
    const std::map<int64_t, std::string> on_node = clips_on(node);
    EXPECT_FALSE(on_node.empty()) << node;  // ids 1 to 6 fall on both nodes' shards
    for (const auto& [id, name] : on_node) {
      EXPECT_EQ(map.owners[ShardOfClip(id, map.shard_count())], node) << id;
      stored.emplace(id, name);
    }
  }
  EXPECT_EQ(stored, routed);

  // A file sent in a stream is stored as one sent whole.
  {
    const std::string text = BvhText(ChainClip(0.3));
    grpc::ClientContext context;
    context.set_deadline(std::chrono::system_clock::now() + kBound);
    v1::IngestClipResponse response;
    auto writer = router->IngestClipStream(&context, &response);
    for (size_t at = 0; at < text.size(); at += text.size() / 3 + 1) {
      v1::IngestClipStreamRequest piece;
      if (at == 0) {
        piece.set_file_name("streamed.bvh");
        piece.add_tags("in-pieces");
      }
      piece.set_chunk(text.substr(at, text.size() / 3 + 1));
      ASSERT_TRUE(writer->Write(piece));
    }
    writer->WritesDone();
    const grpc::Status status = writer->Finish();
    ASSERT_TRUE(status.ok()) << status.error_message();
    const int64_t id = response.clip().clip_id();
    EXPECT_EQ(routed.count(id), 0u);
    EXPECT_THAT(response.clip().tags(), ::testing::ElementsAre("in-pieces"));
    EXPECT_EQ(clips_on(map.owners[ShardOfClip(id, map.shard_count())]).at(id), "streamed");
  }

  // The same name again: skipped when identical, refused when not, replaced when asked: on the
  // clip's own shard, under a new id there, which the name then follows.
  const int64_t first = routed.begin()->first;
  const std::string first_name = routed.begin()->second;
  const double first_speed = 0.01 * (first_name.back() - '0' + 1);
  v1::IngestClipResponse again;
  ASSERT_TRUE(ingest(first_name, first_speed, v1::ON_CONFLICT_UNSPECIFIED, &again).ok());
  EXPECT_EQ(again.result(), v1::INGEST_RESULT_SKIPPED);
  EXPECT_EQ(again.clip().clip_id(), first);
  const grpc::Status conflict = ingest(first_name, 0.5, v1::ON_CONFLICT_UNSPECIFIED, &again);
  EXPECT_EQ(conflict.error_code(), grpc::StatusCode::ALREADY_EXISTS) << conflict.error_message();
  ASSERT_TRUE(ingest(first_name, 0.5, v1::ON_CONFLICT_REPLACE, &again).ok());
  EXPECT_EQ(again.result(), v1::INGEST_RESULT_REPLACED);
  EXPECT_EQ(again.replaced_clip_id(), first);
  const int64_t replacement = again.clip().clip_id();
  EXPECT_EQ(routed.count(replacement), 0u);  // a new id, never another clip's
  EXPECT_EQ(ShardOfClip(replacement, 4), ShardOfClip(first, 4));
  const std::string first_node = map.owners[ShardOfClip(first, map.shard_count())];
  EXPECT_EQ(clips_on(first_node).count(first), 0u);
  EXPECT_EQ(clips_on(first_node).at(replacement), first_name);
  const ClipNames names(*client_, "motiondb", 512);
  EXPECT_EQ(*names.Lookup(first_name), replacement);
  ASSERT_TRUE(ingest(first_name, 0.5, v1::ON_CONFLICT_UNSPECIFIED, &again).ok());
  EXPECT_EQ(again.result(), v1::INGEST_RESULT_SKIPPED);
  EXPECT_EQ(again.clip().clip_id(), replacement);

  // A bad name is refused before anything is reserved or stored.
  v1::IngestClipResponse bad;
  EXPECT_EQ(ingest("a//b", 0.1, v1::ON_CONFLICT_UNSPECIFIED, &bad).error_code(),
            grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_EQ(*names.Lookup("a//b"), std::nullopt);
  // A name the shard refuses to store (its tag is empty) is free again.
  {
    v1::IngestClipRequest request;
    request.set_file_name("tagged.bvh");
    request.set_bvh(BvhText(ChainClip(0.2)));
    request.add_tags("");
    grpc::ClientContext context;
    context.set_deadline(std::chrono::system_clock::now() + kBound);
    const grpc::Status refused = router->IngestClip(&context, request, &bad);
    EXPECT_EQ(refused.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << refused.error_message();
    EXPECT_EQ(*names.Lookup("tagged"), std::nullopt);
  }

  // A call on one clip goes to its node: get, export (whole and streamed), poses, delete (which
  // frees the name).
  auto stub_of = [&](const std::string& node) {
    return v1::ClipService::NewStub(testing::InsecureChannel(nodes[node].address()));
  };
  const auto context = [] {
    auto made = std::make_unique<grpc::ClientContext>();
    made->set_deadline(std::chrono::system_clock::now() + kBound);
    return made;
  };
  std::map<int64_t, std::string> now;
  for (const std::string node : {"s1", "s2"}) now.merge(clips_on(node));
  for (const auto& [id, name] : now) {
    v1::GetClipRequest get;
    get.set_clip_id(id);
    v1::Clip clip;
    const grpc::Status got = router->GetClip(context().get(), get, &clip);
    ASSERT_TRUE(got.ok()) << got.error_message() << nodes["r1"].Log();
    EXPECT_EQ(clip.name(), name);
  }
  const int64_t second = std::next(routed.begin())->first;
  v1::ExportClipRequest export_request;
  export_request.mutable_clip()->set_clip_id(second);
  v1::ExportClipResponse exported;
  ASSERT_TRUE(router->ExportClip(context().get(), export_request, &exported).ok());
  {
    v1::ExportClipResponse direct;
    const std::string node = map.owners[ShardOfClip(second, map.shard_count())];
    ASSERT_TRUE(stub_of(node)->ExportClip(context().get(), export_request, &direct).ok());
    EXPECT_EQ(exported.bvh(), direct.bvh());
  }
  {
    const auto streamed_context = context();
    auto reader = router->ExportClipStream(streamed_context.get(), export_request);
    std::string streamed;
    v1::ExportClipResponse piece;
    while (reader->Read(&piece)) streamed += piece.bvh();
    ASSERT_TRUE(reader->Finish().ok());
    EXPECT_EQ(streamed, exported.bvh());
  }
  // An answer past gRPC's default 4 MiB comes through whole, as from one node.
  {
    v1::IngestClipRequest request;
    request.set_file_name("long.bvh");
    request.set_bvh(BvhText(testing::MakeClip(
        testing::ChainSkeleton(), 60000, 1.0 / 120,
        [](int f, int j) {
          return Quat(Eigen::AngleAxisd(0.001 * f * (j + 1), Eigen::Vector3d::UnitY()));
        },
        [](int f, int) { return Eigen::Vector3d(0.01 * f, 90, 0); })));
    v1::IngestClipResponse long_clip;
    ASSERT_TRUE(router->IngestClip(context().get(), request, &long_clip).ok());
    v1::ExportClipRequest whole;
    whole.mutable_clip()->set_clip_id(long_clip.clip().clip_id());
    v1::ExportClipResponse long_export;
    const grpc::Status status = router->ExportClip(context().get(), whole, &long_export);
    ASSERT_TRUE(status.ok()) << status.error_message();
    EXPECT_GT(long_export.bvh().size(), 4u << 20);
  }
  v1::GetClipPosesRequest poses_request;
  poses_request.mutable_clip()->set_clip_id(second);
  v1::ClipPoses poses;
  EXPECT_TRUE(router->GetClipPoses(context().get(), poses_request, &poses).ok());
  v1::GetClipRequest nothing;  // id 0: as one node answers it
  v1::Clip none;
  EXPECT_EQ(router->GetClip(context().get(), nothing, &none).error_code(),
            grpc::StatusCode::NOT_FOUND);
  v1::DeleteClipRequest delete_request;
  delete_request.set_clip_id(second);
  v1::DeleteClipResponse deleted;
  const grpc::Status gone = router->DeleteClip(context().get(), delete_request, &deleted);
  ASSERT_TRUE(gone.ok()) << gone.error_message();
  v1::GetClipRequest get_second;
  get_second.set_clip_id(second);
  EXPECT_EQ(router->GetClip(context().get(), get_second, &none).error_code(),
            grpc::StatusCode::NOT_FOUND);
  EXPECT_EQ(*names.Lookup(routed.at(second)), std::nullopt);
  EXPECT_EQ(router->DeleteClip(context().get(), delete_request, &deleted).error_code(),
            grpc::StatusCode::NOT_FOUND);

  // A rename reserves the new name, has the clip's node rename it, and frees the old name; a name
  // another clip holds is refused with nothing changed; re-tagging alone goes to the node.
  {
    const int64_t third = std::next(routed.begin(), 2)->first;
    const std::string old_name = routed.at(third);
    v1::UpdateClipRequest rename;
    rename.set_clip_id(third);
    rename.set_name("renamed/third");
    rename.add_add_tags("moved");
    v1::Clip updated;
    const grpc::Status status = router->UpdateClip(context().get(), rename, &updated);
    ASSERT_TRUE(status.ok()) << status.error_message() << nodes["r1"].Log();
    EXPECT_EQ(updated.name(), "renamed/third");
    EXPECT_THAT(updated.tags(), ::testing::ElementsAre("moved"));
    const std::string node = map.owners[ShardOfClip(third, map.shard_count())];
    EXPECT_EQ(clips_on(node).at(third), "renamed/third");
    EXPECT_EQ(*names.Lookup("renamed/third"), third);
    EXPECT_EQ(*names.Lookup(old_name), std::nullopt);

    const int64_t fourth = std::next(routed.begin(), 3)->first;
    rename.set_clip_id(fourth);
    const grpc::Status taken = router->UpdateClip(context().get(), rename, &updated);
    EXPECT_EQ(taken.error_code(), grpc::StatusCode::ALREADY_EXISTS) << taken.error_message();
    EXPECT_THAT(taken.error_message(), HasSubstr(absl::StrCat("taken by clip ", third)));
    EXPECT_EQ(*names.Lookup(routed.at(fourth)), fourth);
    rename.set_name("a//b");
    EXPECT_EQ(router->UpdateClip(context().get(), rename, &updated).error_code(),
              grpc::StatusCode::INVALID_ARGUMENT);
    EXPECT_EQ(*names.Lookup("a//b"), std::nullopt);
    rename.set_name("renamed/fourth");
    rename.set_clip_id(999'999);  // no such clip: nothing reserved
    EXPECT_EQ(router->UpdateClip(context().get(), rename, &updated).error_code(),
              grpc::StatusCode::NOT_FOUND);
    EXPECT_EQ(*names.Lookup("renamed/fourth"), std::nullopt);
    // A name left reserved for a clip named otherwise now (a release that failed), or for a clip
    // gone, is taken over; one its clip still has is not (above).
    for (const auto& [left, holder] : std::vector<std::pair<std::string, int64_t>>{
             {"left/by-third", third}, {"left/by-a-clip-gone", second}}) {
      ASSERT_TRUE(names.Reserve(left, holder).ok());
      rename.clear_add_tags();
      rename.set_clip_id(fourth);
      rename.set_name(left);
      const grpc::Status taken_over = router->UpdateClip(context().get(), rename, &updated);
      ASSERT_TRUE(taken_over.ok()) << left << ": " << taken_over.error_message();
      EXPECT_EQ(updated.name(), left);
      EXPECT_EQ(*names.Lookup(left), fourth);
    }
    routed[fourth] = "left/by-a-clip-gone";

    v1::UpdateClipRequest retag;
    retag.set_clip_id(fourth);
    retag.add_add_tags("kept");
    ASSERT_TRUE(router->UpdateClip(context().get(), retag, &updated).ok());
    EXPECT_EQ(updated.name(), routed.at(fourth));
    EXPECT_THAT(updated.tags(), ::testing::ElementsAre("kept"));

    // The old name is free: an ingest under it stores a new clip.
    v1::IngestClipResponse reused;
    ASSERT_TRUE(ingest(old_name, 0.9, v1::ON_CONFLICT_UNSPECIFIED, &reused).ok());
    EXPECT_EQ(reused.result(), v1::INGEST_RESULT_STORED);
    EXPECT_NE(reused.clip().clip_id(), third);
    routed[third] = "renamed/third";
    routed.emplace(reused.clip().clip_id(), old_name);
  }

  // A listing through the router, page by page in each order, is the nodes' clips merged in that
  // order: each page token holds on every node.
  {
    std::vector<v1::Clip> all;
    for (const std::string node : {"s1", "s2"}) {
      v1::ListClipsResponse listed;
      ASSERT_TRUE(stub_of(node)->ListClips(context().get(), {}, &listed).ok());
      all.insert(all.end(), listed.clips().begin(), listed.clips().end());
    }
    ASSERT_GE(all.size(), 6u);
    for (const std::string sort : {"id", "name", "created"}) {
      std::sort(all.begin(), all.end(), [&](const v1::Clip& a, const v1::Clip& b) {
        const auto key = [&](const v1::Clip& c) {
          return std::make_tuple(sort == "name" ? c.name() : std::string(),
                                 sort == "created" ? c.created_unix_ms() : 0, c.clip_id());
        };
        return key(a) < key(b);
      });
      std::vector<int64_t> paged;
      v1::ListClipsRequest request;
      request.set_sort(sort);
      request.set_page_size(2);
      for (int pages = 0; pages < 100; ++pages) {
        v1::ListClipsResponse page;
        const grpc::Status listed = router->ListClips(context().get(), request, &page);
        ASSERT_TRUE(listed.ok()) << listed.error_message();
        EXPECT_EQ(page.total_size(), static_cast<int64_t>(all.size()));
        for (const v1::Clip& clip : page.clips()) paged.push_back(clip.clip_id());
        if (page.next_page_token().empty()) break;
        request.set_page_token(page.next_page_token());
      }
      std::vector<int64_t> expected;
      for (const v1::Clip& clip : all) expected.push_back(clip.clip_id());
      EXPECT_EQ(paged, expected) << sort;
    }
    v1::ListClipsRequest bad;
    bad.set_sort("size");
    v1::ListClipsResponse page;
    EXPECT_EQ(router->ListClips(context().get(), bad, &page).error_code(),
              grpc::StatusCode::INVALID_ARGUMENT);
  }

  // s2 killed: the next ingest whose id falls on its shards fails, naming it.
  nodes["s2"].Stop(SIGKILL);
  grpc::Status failed;
  for (int i = 6; i < 40 && failed.ok(); ++i) {
    v1::IngestClipResponse response;
    failed =
        ingest(absl::StrCat("take_", i), 0.01 * (i + 1), v1::ON_CONFLICT_UNSPECIFIED, &response);
  }
  EXPECT_EQ(failed.error_code(), grpc::StatusCode::UNAVAILABLE) << failed.error_message();
  EXPECT_THAT(failed.error_message(), HasSubstr("node 's2'"));
  {
    v1::ListClipsResponse page;
    const grpc::Status listed = router->ListClips(context().get(), {}, &page);
    EXPECT_EQ(listed.error_code(), grpc::StatusCode::UNAVAILABLE);
    EXPECT_THAT(listed.error_message(), HasSubstr("node 's2'"));
  }

  // etcd gone: reads go on from the last map and the addresses known.
  etcd_.Stop(0, /*graceful=*/true);
  const std::map<int64_t, std::string> on_s1 = clips_on("s1");
  ASSERT_FALSE(on_s1.empty());
  for (const auto& [id, name] : on_s1) {
    v1::GetClipRequest get;
    get.set_clip_id(id);
    v1::Clip clip;
    const grpc::Status got = router->GetClip(context().get(), get, &clip);
    EXPECT_TRUE(got.ok()) << got.error_message();
    EXPECT_EQ(clip.name(), name);
  }
  // A write, which needs the map and the names, waits for etcd until shortly before its
  // deadline (a tenth of it, here a second) and is refused UNAVAILABLE then, storing nothing.
  {
    v1::IngestClipRequest request;
    request.set_file_name("while_etcd_is_down.bvh");
    request.set_bvh(BvhText(ChainClip(0.7)));
    grpc::ClientContext context;
    context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(10));
    v1::IngestClipResponse response;
    const grpc::Status refused = router->IngestClip(&context, request, &response);
    EXPECT_EQ(refused.error_code(), grpc::StatusCode::UNAVAILABLE) << refused.error_message();
    EXPECT_THAT(refused.error_message(), HasSubstr("etcd"));
    EXPECT_EQ(clips_on("s1"), on_s1);
  }
}

// Three etcd members under the motiondb nodes, so that etcd's leader can be killed.
class ClusterServerFailoverTest : public ClusterEtcdTest {
 protected:
  ClusterServerFailoverTest() : ClusterEtcdTest(3) {}
};

// etcd's leader killed while a router ingests: writes wait while the other two members elect a
// leader and go on; every ingest acknowledged is stored on its shard's node under its name, and
// the name is the cluster's. How long the writes stalled is printed, not judged.
TEST_F(ClusterServerFailoverTest, AnEtcdLeaderKilledMidIngestLosesNothingAcknowledged) {
  std::map<std::string, testing::ServerProcess> nodes;
  ShardMap map;
  ASSERT_NO_FATAL_FAILURE(StartTwoShardsAndARouter(
      etcd_, *client_, testing::MakeTempDir("cluster_etcd_failover"), nodes, map));
  auto router = v1::ClipService::NewStub(testing::InsecureChannel(nodes["r1"].address()));

  // One client ingesting take_0, take_1, ... until told to stop.
  struct Outcome {
    std::string name;
    grpc::Status status;
    int64_t clip_id = 0;
    std::chrono::steady_clock::time_point answered;
  };
  std::mutex mutex;
  std::vector<Outcome> outcomes;
  std::atomic<int> acknowledged{0};
  std::atomic<bool> stop{false};
  std::thread client([&] {
    for (int i = 0; !stop && i < 10'000; ++i) {
      v1::IngestClipRequest request;
      request.set_file_name("take.bvh");
      request.set_name(absl::StrCat("take_", i));
      request.set_bvh(BvhText(ChainClip(0.001 * (i + 1))));
      grpc::ClientContext context;
      context.set_deadline(std::chrono::system_clock::now() + kBound);
      v1::IngestClipResponse response;
      Outcome outcome{.name = request.name(),
                      .status = router->IngestClip(&context, request, &response),
                      .clip_id = response.clip().clip_id(),
                      .answered = std::chrono::steady_clock::now()};
      if (outcome.status.ok()) ++acknowledged;
      std::lock_guard<std::mutex> lock(mutex);
      outcomes.push_back(std::move(outcome));
    }
  });
  auto stop_client = absl::MakeCleanup([&] {
    stop = true;
    client.join();
  });

  ASSERT_TRUE(PollUntil([&] { return acknowledged >= 5; })) << nodes["r1"].Log();
  int leader = -1;
  ASSERT_TRUE(PollUntil([&] { return (leader = etcd_.Leader()) >= 0; }));
  const auto killed = std::chrono::steady_clock::now();
  etcd_.Stop(leader, /*graceful=*/false);
  const int before = acknowledged;
  EXPECT_TRUE(PollUntil([&] { return acknowledged >= before + 10; })) << nodes["r1"].Log();
  std::move(stop_client).Invoke();
  // `cluster status` shows the members: the one killed unreachable, another leading.
  const testing::CommandResult cli =
      testing::RunCli({"cluster", "status", "--etcd", etcd_.endpoints_flag()});
  EXPECT_EQ(cli.exit_code, 0) << cli.err;
  EXPECT_THAT(cli.out, HasSubstr(etcd_.endpoints()[leader] + " unreachable"));
  EXPECT_THAT(cli.out, ::testing::ContainsRegex(":[0-9]+ leader"));

  // The stall: the longest wait for an answer from the kill on (from the kill, or the answer
  // before).
  std::map<std::string, int64_t> acked;  // name -> id
  int refused = 0;
  std::chrono::steady_clock::duration stall{};
  std::chrono::steady_clock::time_point last = killed;
  for (const Outcome& outcome : outcomes) {
    if (outcome.answered > killed) {
      stall = std::max(stall, outcome.answered - last);
      last = outcome.answered;
    }
    if (!outcome.status.ok()) {
      ++refused;
      std::cout << outcome.name << ": " << outcome.status.error_message() << "\n";
      continue;
    }
    EXPECT_TRUE(acked.emplace(outcome.name, outcome.clip_id).second);
  }
  std::cout << "etcd member m" << leader << " (the leader) killed: " << acked.size()
            << " ingests acknowledged, " << refused << " refused; the longest wait for an answer "
            << "from the kill on "
            << std::chrono::duration_cast<std::chrono::milliseconds>(stall).count() << " ms\n";

  std::map<int64_t, std::string> stored;  // id -> name, from the nodes themselves
  for (const std::string node : {"s1", "s2"}) {
    auto clips = v1::ClipService::NewStub(testing::InsecureChannel(nodes[node].address()));
    v1::ListClipsRequest all;
    all.set_page_size(1000);
    grpc::ClientContext context;
    v1::ListClipsResponse listed;
    ASSERT_TRUE(clips->ListClips(&context, all, &listed).ok()) << node;
    for (const v1::Clip& clip : listed.clips()) {
      EXPECT_EQ(map.owners[ShardOfClip(clip.clip_id(), map.shard_count())], node);
      EXPECT_TRUE(stored.emplace(clip.clip_id(), clip.name()).second);
    }
  }
  const ClipNames names(*client_, "motiondb", 512);
  for (const auto& [name, id] : acked) {
    ASSERT_EQ(stored.count(id), 1u) << name << " (clip " << id << ") acknowledged, not stored";
    EXPECT_EQ(stored.at(id), name);
    EXPECT_EQ(*names.Lookup(name), id) << name;
  }
}

// With tokens the nodes trust each other by the cluster's own token (--cluster-token-file): a
// router checks its caller as one node does and presents the cluster's token to the shard nodes,
// so that its HTTP face, whose in-process calls carry no token on, stores clips too; no client's
// token, not even an admin's, may call a shard node's ShardService, whose writes bypass the
// reservation of names.
TEST_F(ClusterServerTest, NodesTrustEachOtherByTheClusterToken) {
  const std::filesystem::path dir = testing::MakeTempDir("cluster_tokens");
  const std::string tokens = (dir / "tokens").string();
  const std::string cluster_token = (dir / "cluster-token").string();
  std::ofstream(tokens) << "read r-token\nwrite w-token\nadmin a-token\n";
  std::ofstream(cluster_token) << "c-token\n";
  // Client tokens and the cluster's go together, and are not the same.
  std::ofstream(dir / "bare-token") << "a-token\n";
  for (const auto& [flags, refusal] : std::vector<std::pair<std::vector<std::string>, std::string>>{
           {{"--auth-token-file", tokens},
            "--auth-token-file and --cluster-token-file go together"},
           {{"--cluster-token-file", cluster_token},
            "--auth-token-file and --cluster-token-file go together"},
           {{"--auth-token-file", tokens, "--cluster-token-file", (dir / "bare-token").string()},
            "the cluster's token is also one of --auth-token-file's"}}) {
    std::vector<std::string> args = {"--db",      (dir / "x.sqlite").string(), "--http",    "off",
                                     "--cluster", etcd_.endpoints_flag(),      "--node-id", "x"};
    args.insert(args.end(), flags.begin(), flags.end());
    std::string error;
    testing::ServerProcess refused;
    EXPECT_FALSE(refused.Start(args, &error));
    EXPECT_THAT(error, HasSubstr(refusal));
  }
  std::map<std::string, testing::ServerProcess> nodes;
  ShardMap map;
  ASSERT_NO_FATAL_FAILURE(StartTwoShardsAndARouter(
      etcd_, *client_, dir, nodes, map,
      {"--auth-token-file", tokens, "--cluster-token-file", cluster_token}, /*router_http=*/true));
  const auto with_token = [](const std::string& token) {
    auto context = std::make_unique<grpc::ClientContext>();
    context->set_deadline(std::chrono::system_clock::now() + kBound);
    if (!token.empty()) context->AddMetadata("authorization", "Bearer " + token);
    return context;
  };

  // The router checks its caller as one node does; the nodes see the cluster's token.
  auto router = v1::ClipService::NewStub(testing::InsecureChannel(nodes["r1"].address()));
  v1::IngestClipRequest request;
  request.set_file_name("take.bvh");
  request.set_bvh(BvhText(ChainClip(0.2)));
  v1::IngestClipResponse response;
  EXPECT_EQ(router->IngestClip(with_token("r-token").get(), request, &response).error_code(),
            grpc::StatusCode::PERMISSION_DENIED);
  grpc::Status status = router->IngestClip(with_token("w-token").get(), request, &response);
  ASSERT_TRUE(status.ok()) << status.error_message() << nodes["r1"].Log();
  v1::GetClipRequest get;
  get.set_clip_id(response.clip().clip_id());
  v1::Clip clip;
  status = router->GetClip(with_token("r-token").get(), get, &clip);
  EXPECT_TRUE(status.ok()) << status.error_message();
  v1::DeleteClipRequest remove;
  remove.set_clip_id(response.clip().clip_id());
  v1::DeleteClipResponse removed;
  EXPECT_EQ(router->DeleteClip(with_token("w-token").get(), remove, &removed).error_code(),
            grpc::StatusCode::PERMISSION_DENIED);
  status = router->DeleteClip(with_token("a-token").get(), remove, &removed);
  EXPECT_TRUE(status.ok()) << status.error_message();

  // Through the router's HTTP face, whose calls carry no token on to the nodes.
  httplib::Client http("127.0.0.1", nodes["r1"].http_port());
  http.set_read_timeout(60);
  http.set_bearer_token_auth("w-token");
  const httplib::Result posted =
      http.Post("/v1/clips",
                absl::StrCat(R"({"file_name":"over_http.bvh","bvh":")",
                             absl::Base64Escape(BvhText(ChainClip(0.4))), R"("})"),
                "application/json");
  ASSERT_TRUE(posted);
  EXPECT_EQ(posted->status, 200) << posted->body;
  EXPECT_THAT(posted->body, HasSubstr("over_http"));

  // A shard node's ShardService takes the cluster's token only.
  int64_t on_s1 = 1'000'000;
  while (map.owners[ShardOfClip(on_s1, map.shard_count())] != "s1") ++on_s1;
  auto s1 = shard::v1::ShardService::NewStub(testing::InsecureChannel(nodes["s1"].address()));
  shard::v1::StoreTakeRequest store;
  *store.mutable_ingest() = request;
  store.mutable_ingest()->set_name("around-the-router");
  store.set_clip_id(on_s1);
  for (const std::string token : {"a-token", "w-token"}) {
    status = s1->StoreTake(with_token(token).get(), store, &response);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::PERMISSION_DENIED) << token;
    EXPECT_THAT(status.error_message(), HasSubstr("needs 'cluster'"));
  }
  EXPECT_EQ(s1->StoreTake(with_token("").get(), store, &response).error_code(),
            grpc::StatusCode::UNAUTHENTICATED);
  v1::UpdateClipRequest rename;
  rename.set_clip_id(on_s1);
  rename.set_name("renamed-around-the-router");
  v1::Clip renamed;
  EXPECT_EQ(s1->UpdateClip(with_token("a-token").get(), rename, &renamed).error_code(),
            grpc::StatusCode::PERMISSION_DENIED);
  status = s1->StoreTake(with_token("c-token").get(), store, &response);
  EXPECT_TRUE(status.ok()) << status.error_message();
  // Its ClipService answers clients' tokens as one node does.
  auto s1_clips = v1::ClipService::NewStub(testing::InsecureChannel(nodes["s1"].address()));
  v1::ListClipsResponse listed;
  status = s1_clips->ListClips(with_token("r-token").get(), {}, &listed);
  EXPECT_TRUE(status.ok()) << status.error_message();

  // A router given another cluster token is refused by the nodes: its caller is told so, not
  // that its own token is wrong.
  std::ofstream(dir / "other-cluster-token") << "not-c-token\n";
  testing::ServerProcess stray;
  std::string error;
  ASSERT_TRUE(stray.Start(
      {"--db", (dir / "r2.sqlite").string(), "--http", "off", "--quiet", "--cluster",
       etcd_.endpoints_flag(), "--node-id", "r2", "--role", "router", "--auth-token-file", tokens,
       "--cluster-token-file", (dir / "other-cluster-token").string()},
      &error))
      << error;
  ASSERT_TRUE(PollUntil([&] { return Listed(*client_, "motiondb", "r2"); }));
  status = v1::ClipService::NewStub(testing::InsecureChannel(stray.address()))
               ->ListClips(with_token("r-token").get(), {}, &listed);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INTERNAL);
  EXPECT_THAT(status.error_message(), HasSubstr("give every node of the cluster the same "
                                                "--cluster-token-file"));
}

// A node registers where others reach it (--advertise), and refuses an address nobody reaches.
TEST_F(ClusterServerTest, RegistersTheAdvertisedAddress) {
  std::string error;
  const std::filesystem::path dir = testing::MakeTempDir("cluster_advertise");
  testing::ServerProcess server;
  ASSERT_TRUE(server.Start(
      {"--db", (dir / "a.sqlite").string(), "--http", "off", "--quiet", "--cluster",
       etcd_.endpoints_flag(), "--node-id", "a", "--advertise", "shard-0.motiondb-shard:7000"},
      &error))
      << error;
  EXPECT_TRUE(PollUntil([&] {
    const absl::StatusOr<std::vector<NodeInfo>> nodes = ListNodes(*client_, "motiondb");
    return nodes.ok() && nodes->size() == 1 && (*nodes)[0].address == "shard-0.motiondb-shard:7000";
  })) << server.Log();

  // TLS between the nodes is not built: refused rather than left to fail on the first call.
  std::ofstream(dir / "cert.pem") << "";
  std::ofstream(dir / "key.pem") << "";
  testing::ServerProcess tls;
  EXPECT_FALSE(tls.Start({"--db", (dir / "c.sqlite").string(), "--http", "off", "--cluster",
                          etcd_.endpoints_flag(), "--node-id", "c", "--tls-cert",
                          (dir / "cert.pem").string(), "--tls-key", (dir / "key.pem").string()},
                         &error));
  EXPECT_THAT(error, HasSubstr("--cluster with --tls-cert"));

  testing::ServerProcess wildcard;
  EXPECT_FALSE(wildcard.Start({"--db", (dir / "b.sqlite").string(), "--http", "off", "--cluster",
                               etcd_.endpoints_flag(), "--node-id", "b", "--advertise", "0.0.0.0"},
                              &error));
  EXPECT_THAT(error, HasSubstr("--advertise '0.0.0.0': a wildcard host reaches no node"));
}

}  // namespace
}  // namespace motiondb::cluster
