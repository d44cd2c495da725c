#include "server/net/connection_counter.h"

#include "absl/strings/str_cat.h"

namespace motiondb::server {

struct ConnectionCounter::Slot::Shared {
  std::mutex mutex;
  int open = 0;                                   // guarded by mutex
  absl::flat_hash_map<std::string, int> by_peer;  // guarded by mutex; no zero counts
};

ConnectionCounter::ConnectionCounter(const ConnectionLimits& limits)
    : limits_(limits), shared_(std::make_shared<Slot::Shared>()) {}

ConnectionCounter::Slot& ConnectionCounter::Slot::operator=(Slot&& other) noexcept {
  if (this != &other) {
    Release();
    shared_ = std::move(other.shared_);
    peer_ = std::move(other.peer_);
  }
  return *this;
}

ConnectionCounter::Slot::~Slot() { Release(); }

void ConnectionCounter::Slot::Release() {
  if (shared_ == nullptr) return;
  std::lock_guard<std::mutex> lock(shared_->mutex);
  --shared_->open;
  const auto found = shared_->by_peer.find(peer_);
  if (found != shared_->by_peer.end() && --found->second == 0) shared_->by_peer.erase(found);
  shared_.reset();
}

std::optional<ConnectionCounter::Slot> ConnectionCounter::TryAdmit(const std::string& peer,
                                                                   std::string* refusal) {
  std::lock_guard<std::mutex> lock(shared_->mutex);
  if (shared_->open >= limits_.max_connections) {
    *refusal = absl::StrCat("the port holds ", shared_->open, " connections, its most");
    return std::nullopt;
  }
  int& from_peer = shared_->by_peer[peer];
  if (from_peer >= limits_.max_per_peer) {
    *refusal = absl::StrCat(peer, " holds ", from_peer, " connections, the most one client may");
    return std::nullopt;
  }
  ++from_peer;
  ++shared_->open;
  return Slot(shared_, peer);
}

int ConnectionCounter::open() const {
  std::lock_guard<std::mutex> lock(shared_->mutex);
  return shared_->open;
}

int ConnectionCounter::open_from(const std::string& peer) const {
  std::lock_guard<std::mutex> lock(shared_->mutex);
  const auto found = shared_->by_peer.find(peer);
  return found == shared_->by_peer.end() ? 0 : found->second;
}

bool ConnectionCounter::full() const { return open() >= limits_.max_connections; }

}  // namespace motiondb::server
