#include "cluster/etcd_client.h"

#include "absl/strings/str_cat.h"
#include "cluster/internal/etcd_channels.h"
#include "etcd/etcdserver/etcdserverpb/rpc.grpc.pb.h"

namespace motiondb::cluster {
namespace {

using etcdserverpb::Compare;

KeyValue FromProto(const mvccpb::KeyValue& kv) {
  return KeyValue{.key = kv.key(),
                  .value = kv.value(),
                  .create_revision = kv.create_revision(),
                  .mod_revision = kv.mod_revision(),
                  .lease = kv.lease()};
}

// One unary call of a service's `Stub` through the members (EtcdChannels::Call).
template <typename Stub, typename Request, typename Response>
absl::Status Unary(const EtcdChannels& channels,
                   grpc::Status (Stub::*method)(grpc::ClientContext*, const Request&, Response*),
                   const Request& request, Response* response,
                   absl::Time deadline = absl::InfiniteFuture()) {
  return channels.Call(
      [&](const std::shared_ptr<grpc::Channel>& channel, grpc::ClientContext& context) {
        response->Clear();
        Stub stub(channel);
        return (stub.*method)(&context, request, response);
      },
      deadline);
}

// The transaction's condition: `key`'s mod_revision is `expected_revision`, or the key is absent
// for 0 (an absent key has no mod_revision to compare: its create_revision is 0).
void CompareRevision(const std::string& key, int64_t expected_revision,
                     etcdserverpb::TxnRequest* request) {
  Compare* compare = request->add_compare();
  compare->set_key(key);
  compare->set_result(Compare::EQUAL);
  if (expected_revision == 0) {
    compare->set_target(Compare::CREATE);
    compare->set_create_revision(0);
  } else {
    compare->set_target(Compare::MOD);
    compare->set_mod_revision(expected_revision);
  }
}

// etcd answers an unknown lease with NOT_FOUND ("requested lease not found"), and a keep-alive
// of one with a TTL of 0.
absl::Status LeaseGone(int64_t lease) {
  return absl::NotFoundError(absl::StrCat("etcd lease ", lease, " has expired"));
}

}  // namespace

std::string PrefixRangeEnd(const std::string& prefix) {
  // etcd's own rule (clientv3.GetPrefixRangeEnd): the prefix with its last byte below 0xff
  // incremented, the bytes after it dropped.
  std::string end = prefix;
  while (!end.empty()) {
    if (static_cast<unsigned char>(end.back()) < 0xff) {
      end.back() = static_cast<char>(static_cast<unsigned char>(end.back()) + 1);
      return end;
    }
    end.pop_back();
  }
  return std::string(1, '\0');  // every key
}

absl::StatusOr<std::unique_ptr<EtcdClient>> EtcdClient::Create(EtcdOptions options) {
  if (options.endpoints.empty()) return absl::InvalidArgumentError("no etcd endpoint given");
  return std::unique_ptr<EtcdClient>(
      new EtcdClient(std::make_shared<const EtcdChannels>(std::move(options))));
}

EtcdClient::EtcdClient(std::shared_ptr<const EtcdChannels> channels)
    : channels_(std::move(channels)) {}

EtcdClient::~EtcdClient() = default;

const EtcdOptions& EtcdClient::options() const { return channels_->options(); }

absl::StatusOr<std::optional<KeyValue>> EtcdClient::Get(const std::string& key,
                                                        absl::Time deadline) const {
  etcdserverpb::RangeRequest request;
  request.set_key(key);
  etcdserverpb::RangeResponse response;
  const absl::Status status =
      Unary(*channels_, &etcdserverpb::KV::Stub::Range, request, &response, deadline);
  if (!status.ok()) return status;
  if (response.kvs_size() == 0) return std::nullopt;
  return FromProto(response.kvs(0));
}

absl::StatusOr<std::vector<KeyValue>> EtcdClient::Range(const std::string& prefix) const {
  etcdserverpb::RangeRequest request;
  request.set_key(prefix);
  request.set_range_end(PrefixRangeEnd(prefix));
  etcdserverpb::RangeResponse response;  // in key order, etcd's default
  const absl::Status status = Unary(*channels_, &etcdserverpb::KV::Stub::Range, request, &response);
  if (!status.ok()) return status;
  std::vector<KeyValue> kvs;
  for (const mvccpb::KeyValue& kv : response.kvs()) kvs.push_back(FromProto(kv));
  return kvs;
}

absl::Status EtcdClient::Put(const std::string& key, const std::string& value,
                             int64_t lease) const {
  etcdserverpb::PutRequest request;
  request.set_key(key);
  request.set_value(value);
  request.set_lease(lease);
  etcdserverpb::PutResponse response;
  return Unary(*channels_, &etcdserverpb::KV::Stub::Put, request, &response);
}

absl::Status EtcdClient::Delete(const std::string& key) const {
  etcdserverpb::DeleteRangeRequest request;
  request.set_key(key);
  etcdserverpb::DeleteRangeResponse response;
  return Unary(*channels_, &etcdserverpb::KV::Stub::DeleteRange, request, &response);
}

absl::StatusOr<SwapOutcome> EtcdClient::CompareAndSwap(const std::string& key,
                                                       int64_t expected_revision,
                                                       const std::string& value,
                                                       int64_t lease) const {
  etcdserverpb::TxnRequest request;
  CompareRevision(key, expected_revision, &request);
  etcdserverpb::PutRequest* put = request.add_success()->mutable_request_put();
  put->set_key(key);
  put->set_value(value);
  put->set_lease(lease);
  request.add_failure()->mutable_request_range()->set_key(key);
  etcdserverpb::TxnResponse response;
  const absl::Status status = Unary(*channels_, &etcdserverpb::KV::Stub::Txn, request, &response);
  if (!status.ok()) return status;
  SwapOutcome outcome{
      .written = response.succeeded(), .revision = response.header().revision(), .current = {}};
  if (!outcome.written && response.responses_size() == 1 &&
      response.responses(0).response_range().kvs_size() == 1) {
    outcome.current = FromProto(response.responses(0).response_range().kvs(0));
  }
  return outcome;
}

absl::StatusOr<bool> EtcdClient::DeleteIfRevision(const std::string& key,
                                                  int64_t expected_revision) const {
  if (expected_revision < 1) {
    return absl::InvalidArgumentError(absl::StrCat(
        "a delete of '", key, "' by revision needs a revision, not ", expected_revision));
  }
  etcdserverpb::TxnRequest request;
  CompareRevision(key, expected_revision, &request);
  request.add_success()->mutable_request_delete_range()->set_key(key);
  etcdserverpb::TxnResponse response;
  const absl::Status status = Unary(*channels_, &etcdserverpb::KV::Stub::Txn, request, &response);
  if (!status.ok()) return status;
  return response.succeeded();
}

absl::StatusOr<int64_t> EtcdClient::GrantLease(absl::Duration ttl) const {
  etcdserverpb::LeaseGrantRequest request;
  request.set_ttl(absl::ToInt64Seconds(absl::Ceil(ttl, absl::Seconds(1))));
  etcdserverpb::LeaseGrantResponse response;
  const absl::Status status =
      Unary(*channels_, &etcdserverpb::Lease::Stub::LeaseGrant, request, &response);
  if (!status.ok()) return status;
  if (!response.error().empty()) return absl::UnavailableError(response.error());
  return response.id();
}

absl::StatusOr<absl::Duration> EtcdClient::KeepAlive(int64_t lease) const {
  // LeaseKeepAlive is a stream meant to stay open; one request and its answer on a stream of its
  // own fails over like any unary call, and a renewal every few seconds costs nothing.
  etcdserverpb::LeaseKeepAliveRequest request;
  request.set_id(lease);
  etcdserverpb::LeaseKeepAliveResponse response;
  const absl::Status status = channels_->Call([&](const std::shared_ptr<grpc::Channel>& channel,
                                                  grpc::ClientContext& context) {
    etcdserverpb::Lease::Stub stub(channel);
    const auto stream = stub.LeaseKeepAlive(&context);
    const bool answered = stream->Write(request) && stream->WritesDone() && stream->Read(&response);
    const grpc::Status finished = stream->Finish();
    if (!finished.ok()) return finished;
    return answered ? grpc::Status::OK
                    : grpc::Status(grpc::StatusCode::UNAVAILABLE, "no keep-alive answer");
  });
  if (!status.ok()) return status;
  if (response.ttl() <= 0) return LeaseGone(lease);
  return absl::Seconds(response.ttl());
}

absl::StatusOr<absl::Duration> EtcdClient::TimeToLive(int64_t lease) const {
  etcdserverpb::LeaseTimeToLiveRequest request;
  request.set_id(lease);
  etcdserverpb::LeaseTimeToLiveResponse response;
  const absl::Status status =
      Unary(*channels_, &etcdserverpb::Lease::Stub::LeaseTimeToLive, request, &response);
  if (!status.ok()) return status;
  if (response.ttl() < 0) return LeaseGone(lease);
  return absl::Seconds(response.ttl());
}

absl::Status EtcdClient::RevokeLease(int64_t lease) const {
  etcdserverpb::LeaseRevokeRequest request;
  request.set_id(lease);
  etcdserverpb::LeaseRevokeResponse response;
  const absl::Status status =
      Unary(*channels_, &etcdserverpb::Lease::Stub::LeaseRevoke, request, &response);
  return absl::IsNotFound(status) ? absl::OkStatus() : status;  // gone already
}

absl::StatusOr<MemberStatus> EtcdClient::Status() const {
  etcdserverpb::StatusResponse response;
  const absl::Status status = Unary(*channels_, &etcdserverpb::Maintenance::Stub::Status,
                                    etcdserverpb::StatusRequest(), &response);
  if (!status.ok()) return status;
  return MemberStatus{.member_id = response.header().member_id(), .leader_id = response.leader()};
}

std::unique_ptr<EtcdWatch> EtcdClient::Watch(const std::string& prefix, int64_t start_revision,
                                             EtcdWatch::Callbacks callbacks) const {
  return std::make_unique<EtcdWatch>(channels_, prefix, start_revision, std::move(callbacks));
}

}  // namespace motiondb::cluster
