// motiondb cluster init|status|move-shard --etcd ENDPOINTS [--cluster-name NAME]: a cluster's
// shard map and nodes, read and changed in its etcd (cluster/). They need etcd only, no server.
#include <algorithm>
#include <iostream>
#include <map>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "client/commands.h"
#include "cluster/cluster_keys.h"
#include "cluster/etcd_client.h"
#include "cluster/node_info.h"
#include "cluster/shard_map_store.h"
#include "util/cli_conventions.h"
#include "util/status_macros.h"

namespace motiondb::cli {
namespace {

constexpr char kClusterGroup[] = "Cluster commands (etcd, no server needed)";

struct ClusterCommandFlags {
  std::string etcd;
  std::string cluster = "motiondb";
  int shards = cluster::kDefaultShardCount;
  int shard = -1;
  std::string node_id;
};

void AddEtcdFlags(CLI::App* command, ClusterCommandFlags* flags) {
  command->add_option("--etcd", flags->etcd, "the cluster's etcd members, comma-separated")
      ->type_name("HOST:PORT,...")
      ->required();
  command->add_option("--cluster-name", flags->cluster, "the cluster's name")
      ->type_name("NAME")
      ->capture_default_str();
}

// A client of the flags' etcd, after checking the cluster's name; UNAVAILABLE, said plainly,
// when no member answers.
absl::StatusOr<std::unique_ptr<cluster::EtcdClient>> ConnectEtcd(const ClusterCommandFlags& flags) {
  MOTIONDB_RETURN_IF_ERROR(cluster::CheckClusterName(flags.cluster, "--cluster-name"));
  MOTIONDB_ASSIGN_OR_RETURN(std::vector<std::string> endpoints,
                            cluster::ParseEtcdEndpoints(flags.etcd));
  return cluster::EtcdClient::Create(cluster::EtcdOptions{.endpoints = std::move(endpoints),
                                                          .call_timeout = absl::Seconds(5),
                                                          .attempt_timeout = absl::Seconds(2)});
}

absl::Status ClusterInit(const ClusterCommandFlags& flags) {
  MOTIONDB_ASSIGN_OR_RETURN(const std::unique_ptr<cluster::EtcdClient> etcd, ConnectEtcd(flags));
  MOTIONDB_ASSIGN_OR_RETURN(const std::vector<cluster::NodeInfo> nodes,
                            cluster::ListNodes(*etcd, flags.cluster));
  std::vector<std::string> shard_nodes;
  for (const cluster::NodeInfo& node : nodes) {
    if (node.role == "shard") shard_nodes.push_back(node.node_id);
  }
  if (shard_nodes.empty()) {
    return absl::FailedPreconditionError(
        absl::StrCat("cluster '", flags.cluster,
                     "' has no live shard node to give the shards to: start them "
                     "first (motiondb-server --cluster ",
                     flags.etcd, " --node-id ID --role shard)"));
  }
  MOTIONDB_ASSIGN_OR_RETURN(
      const cluster::StoredShardMap stored,
      cluster::ShardMapStore(*etcd, flags.cluster).Create(flags.shards, shard_nodes));
  absl::PrintF("cluster '%s' created: %d shards over %d shard nodes (%s), map epoch %d\n",
               flags.cluster, stored.map.shard_count(), shard_nodes.size(),
               absl::StrJoin(shard_nodes, ", "), stored.map.epoch);
  return absl::OkStatus();
}

absl::Status ClusterStatus(const ClusterCommandFlags& flags) {
  MOTIONDB_ASSIGN_OR_RETURN(const std::unique_ptr<cluster::EtcdClient> etcd, ConnectEtcd(flags));
  MOTIONDB_ASSIGN_OR_RETURN(const std::vector<cluster::NodeInfo> nodes,
                            cluster::ListNodes(*etcd, flags.cluster));
  const absl::StatusOr<cluster::StoredShardMap> stored =
      cluster::ShardMapStore(*etcd, flags.cluster).Read();
  if (!stored.ok() && !absl::IsNotFound(stored.status())) return stored.status();
  std::map<std::string, int> per_node;
  if (stored.ok()) {
    absl::PrintF("cluster '%s': shard map epoch %d, %d shards\n", flags.cluster, stored->map.epoch,
                 stored->map.shard_count());
    per_node = stored->map.ShardsPerNode();
  } else {
    absl::PrintF("%s\n", stored.status().message());
  }
  const absl::StatusOr<std::optional<cluster::KeyValue>> coordinator =
      etcd->Get(cluster::ElectionKey(flags.cluster, cluster::kJobsOffice));
  absl::PrintF("job coordinator: %s\n",
               !coordinator.ok() ? std::string(coordinator.status().message())
               : *coordinator    ? (*coordinator)->value
                                 : std::string("none (no live router holds the office)"));
  // Each member asked alone: which answer and which leads (during a failover, none).
  std::vector<std::string> members;
  for (const std::string& endpoint : etcd->options().endpoints) {
    const absl::StatusOr<std::unique_ptr<cluster::EtcdClient>> member =
        cluster::EtcdClient::Create(cluster::EtcdOptions{.endpoints = {endpoint},
                                                         .call_timeout = absl::Seconds(2),
                                                         .attempt_timeout = absl::Seconds(2)});
    const absl::StatusOr<cluster::MemberStatus> status =
        member.ok() ? (*member)->Status() : member.status();
    members.push_back(absl::StrCat(endpoint, " ",
                                   !status.ok()             ? "unreachable"
                                   : status->leads()        ? "leader"
                                   : status->leader_id != 0 ? "follower"
                                                            : "without a leader"));
  }
  absl::PrintF("etcd members: %s\n", absl::StrJoin(members, ", "));
  absl::PrintF("%d live nodes\n", nodes.size());
  absl::PrintF("  %-16s %-7s %-22s %-10s %s\n", "NODE", "ROLE", "ADDRESS", "LEASE LEFT",
               "SHARDS IN THE MAP");
  for (const cluster::NodeInfo& node : nodes) {
    const absl::StatusOr<absl::Duration> left = etcd->TimeToLive(node.lease);
    absl::PrintF("  %-16s %-7s %-22s %-10s %d\n", node.node_id, node.role, node.address,
                 left.ok() ? absl::StrCat(absl::ToInt64Seconds(*left), " s") : "expired",
                 per_node[node.node_id]);
    per_node.erase(node.node_id);
  }
  for (const auto& [node_id, count] : per_node) {
    if (count > 0) absl::PrintF("  %-16s not live: %d shards unserved\n", node_id, count);
  }
  return absl::OkStatus();
}

absl::Status ClusterMoveShard(const ClusterCommandFlags& flags) {
  MOTIONDB_ASSIGN_OR_RETURN(const std::unique_ptr<cluster::EtcdClient> etcd, ConnectEtcd(flags));
  const cluster::ShardMapStore store(*etcd, flags.cluster);
  MOTIONDB_ASSIGN_OR_RETURN(const cluster::StoredShardMap before, store.Read());
  MOTIONDB_ASSIGN_OR_RETURN(const cluster::StoredShardMap after,
                            store.MoveShard(flags.shard, flags.node_id));
  absl::PrintF(
      "shard %d: %s -> %s, map epoch %d\n"
      "Only the map changed: copying a shard's data to its new node is not implemented yet.\n",
      flags.shard, before.map.owners[flags.shard], flags.node_id, after.map.epoch);
  return absl::OkStatus();
}

}  // namespace

void AddClusterCommands(Commands& commands) {
  auto flags = std::make_shared<ClusterCommandFlags>();
  CLI::App* group =
      commands.AddGroup(commands.root(), "cluster", "a cluster in etcd: init, status, move-shard");
  CLI::App* init =
      commands.AddOffline(group, "init", "create the cluster's shard map over its live shard nodes",
                          false, [flags] { return ClusterInit(*flags); });
  AddEtcdFlags(init, flags.get());
  init->add_option("--shards", flags->shards, "logical shards, fixed for the cluster's life")
      ->type_name("N")
      ->capture_default_str()
      ->check(CLI::Range(1, cluster::kMaxShardCount).description(""));
  CLI::App* status = commands.AddOffline(
      group, "status", "the live nodes, their roles and leases, and the shard map", false,
      [flags] { return ClusterStatus(*flags); });
  AddEtcdFlags(status, flags.get());
  CLI::App* move = commands.AddOffline(
      group, "move-shard", "give a shard to another live shard node (the map only, for now)", false,
      [flags] { return ClusterMoveShard(*flags); });
  move->add_option("SHARD", flags->shard, "the logical shard")->required();
  move->add_option("NODE", flags->node_id, "the live shard node to hold it")->required();
  AddEtcdFlags(move, flags.get());
  for (CLI::App* command : {init, status, move}) command->group(kClusterGroup);
}

}  // namespace motiondb::cli
