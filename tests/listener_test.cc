// The ports motiondb accepts on itself (server/net/): connections counted in all and per client
// address, accept errors survived when the process runs out of descriptors, places of
// connections handed to another library given back once those close. No timing: every wait is
// on the listener's own counts.
#include "server/net/listener.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <atomic>
#include <mutex>
#include <thread>
#include <vector>

#include "server/net/connection_counter.h"
#include "server/net/handed_off_sockets.h"

namespace motiondb::server {
namespace {

// A client connection to 127.0.0.1:`port`; invalid when the connect fails.
SocketFd Connect(int port) {
  SocketFd socket(::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0));
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<uint16_t>(port));
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (!socket.valid() ||
      ::connect(socket.get(), reinterpret_cast<sockaddr*>(&address), sizeof(address)) != 0) {
    return SocketFd();
  }
  return socket;
}

// True once the server side closed `socket` (a read sees the end, or a reset).
bool ClosedByServer(const SocketFd& socket) {
  char byte = 0;
  return ::recv(socket.get(), &byte, 1, 0) <= 0;
}

// Waits for `condition`; false if it has not held after a minute, far more than any of these
// take on a loaded machine, so that a listener that never gets there fails the test rather than
// hanging it.
template <typename Condition>
[[nodiscard]] bool WaitUntil(Condition condition) {
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::minutes(1);
  while (!condition()) {
    if (std::chrono::steady_clock::now() > give_up) return false;
    std::this_thread::yield();
  }
  return true;
}

// Accepted connections, kept open (with their places) until the test clears them.
struct Kept {
  std::mutex mutex;
  std::vector<AcceptedConnection> connections;
  std::atomic<int> count{0};

  Listener::Handler Handler() {
    return [this](AcceptedConnection connection) {
      std::lock_guard<std::mutex> lock(mutex);
      connections.push_back(std::move(connection));
      ++count;
    };
  }
  void Clear() {
    std::lock_guard<std::mutex> lock(mutex);
    connections.clear();
  }
};

std::unique_ptr<Listener> Bind(int max_connections, int max_per_peer) {
  absl::StatusOr<std::unique_ptr<Listener>> listener = Listener::Bind(
      ListenerOptions{.listen = "127.0.0.1:0",
                      .face = "test",
                      .limits = {.max_connections = max_connections, .max_per_peer = max_per_peer},
                      .log = nullptr});
  EXPECT_TRUE(listener.ok()) << listener.status();
  return *std::move(listener);
}

TEST(ConnectionCounterTest, CountsInAllAndPerPeerAndGivesPlacesBack) {
  ConnectionCounter counter({.max_connections = 3, .max_per_peer = 2});
  std::string refusal;
  auto a1 = counter.TryAdmit("10.0.0.1", &refusal);
  auto a2 = counter.TryAdmit("10.0.0.1", &refusal);
  ASSERT_TRUE(a1 && a2);
  EXPECT_FALSE(counter.TryAdmit("10.0.0.1", &refusal));
  EXPECT_NE(refusal.find("10.0.0.1 holds 2 connections"), std::string::npos) << refusal;
  auto b1 = counter.TryAdmit("10.0.0.2", &refusal);
  ASSERT_TRUE(b1);
  EXPECT_FALSE(counter.TryAdmit("10.0.0.3", &refusal));
  EXPECT_NE(refusal.find("holds 3 connections, its most"), std::string::npos) << refusal;
  EXPECT_TRUE(counter.full());
  a1.reset();
  EXPECT_EQ(counter.open_from("10.0.0.1"), 1);
  EXPECT_TRUE(counter.TryAdmit("10.0.0.3", &refusal));  // destroyed at once: its place back
  EXPECT_EQ(counter.open(), 2);
}

TEST(ConnectionCounterTest, ASlotOutlivingItsCounterGoesNowhere) {
  std::optional<ConnectionCounter::Slot> slot;
  {
    ConnectionCounter counter({.max_connections = 1, .max_per_peer = 1});
    std::string refusal;
    slot = counter.TryAdmit("10.0.0.1", &refusal);
    ASSERT_TRUE(slot);
  }
  slot.reset();  // no use of the counter, gone (ASan would tell)
}

TEST(ListenerTest, RefusesBeyondThePerPeerLimitAndTakesAgainOncePlacesFree) {
  std::unique_ptr<Listener> listener = Bind(/*max_connections=*/100, /*max_per_peer=*/2);
  Kept kept;
  listener->Start(kept.Handler(), nullptr, nullptr);
  std::vector<SocketFd> clients;
  for (int i = 0; i < 3; ++i) clients.push_back(Connect(listener->port()));
  ASSERT_TRUE(WaitUntil([&] { return kept.count + listener->refused() == 3; }));
  EXPECT_EQ(kept.count, 2);
  EXPECT_EQ(listener->refused(), 1);
  EXPECT_TRUE(ClosedByServer(clients[2]));
  EXPECT_TRUE(listener->accepting());  // only this address is at its limit
  kept.Clear();                        // the two accepted close: their places come back
  SocketFd again = Connect(listener->port());
  ASSERT_TRUE(WaitUntil([&] { return kept.count + listener->refused() == 4; }));
  EXPECT_EQ(kept.count, 3);
}

TEST(ListenerTest, ATotalLimitStopsAcceptingAndReadinessSaysSo) {
  std::unique_ptr<Listener> listener = Bind(/*max_connections=*/2, /*max_per_peer=*/100);
  Kept kept;
  std::atomic<int> refusals_told{0};
  listener->Start(
      kept.Handler(), [&](int, absl::string_view) { ++refusals_told; }, nullptr);
  SocketFd a = Connect(listener->port()), b = Connect(listener->port());
  ASSERT_TRUE(WaitUntil([&] { return kept.count == 2; }));
  EXPECT_FALSE(listener->accepting());
  SocketFd c = Connect(listener->port());
  ASSERT_TRUE(WaitUntil([&] { return listener->refused() == 1; }));
  EXPECT_EQ(refusals_told, 1);  // the refuser had its word before the close
  kept.Clear();
  EXPECT_TRUE(listener->accepting());
}

TEST(ListenerTest, ReclaimGivesBackThePlacesOfHandedOffConnectionsThatClosed) {
  std::unique_ptr<Listener> listener = Bind(/*max_connections=*/1, /*max_per_peer=*/1);
  HandedOffSockets handed_off;
  std::atomic<int> handed{0};
  std::mutex mutex;
  std::vector<int> sockets;  // "the library's": closed by the test as a library would
  listener->Start(
      [&](AcceptedConnection connection) {
        std::lock_guard<std::mutex> lock(mutex);
        handed_off.Add(connection.socket.get(), std::move(connection.slot));
        sockets.push_back(connection.socket.Release());
        ++handed;
      },
      nullptr, [&] { handed_off.Sweep(); });
  SocketFd first = Connect(listener->port());
  ASSERT_TRUE(WaitUntil([&] { return handed == 1; }));
  EXPECT_EQ(handed_off.held(), 1);
  {
    std::lock_guard<std::mutex> lock(mutex);
    ::close(sockets[0]);  // the library closes it and tells nobody
  }
  SocketFd second = Connect(listener->port());
  ASSERT_TRUE(WaitUntil([&] { return handed + listener->refused() == 2; }));
  EXPECT_EQ(handed, 2) << "the closed connection's place was not reclaimed";
  std::lock_guard<std::mutex> lock(mutex);
  for (size_t i = 1; i < sockets.size(); ++i) ::close(sockets[i]);
}

TEST(HandedOffSocketsTest, ADescriptorReusedForAnotherFileIsNoLongerHeld) {
  HandedOffSockets handed_off;
  ConnectionCounter counter({.max_connections = 10, .max_per_peer = 10});
  int pair[2];
  ASSERT_EQ(::socketpair(AF_UNIX, SOCK_STREAM, 0, pair), 0);
  std::string refusal;
  handed_off.Add(pair[0], *counter.TryAdmit("a", &refusal));
  handed_off.Sweep();
  EXPECT_EQ(handed_off.held(), 1);
  EXPECT_EQ(counter.open(), 1);
  // The number comes back for another socket: not the one handed off.
  ::close(pair[0]);
  int other[2];
  ASSERT_EQ(::socketpair(AF_UNIX, SOCK_STREAM, 0, other), 0);
  handed_off.Sweep();
  EXPECT_EQ(handed_off.held(), 0);
  EXPECT_EQ(counter.open(), 0);
  for (int fd : {pair[1], other[0], other[1]}) ::close(fd);
}

// Out of descriptors, the port refuses (accepting() false, the waiting connection closed rather
// than left to wake the loop for ever) and takes connections again once descriptors free up:
// gRPC 1.51's own listener stopped for good. In a child process, whose descriptor limit the test
// lowers without touching the test's own.
TEST(ListenerTest, SurvivesRunningOutOfDescriptors) {
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    int step = 0;
    const auto fail = [&step] { _exit(10 + step); };
    std::unique_ptr<Listener> listener = Bind(100, 100);
    Kept kept;
    listener->Start(kept.Handler(), nullptr, nullptr);
    // One connection accepted, so the test's client has its own descriptor before the rest go.
    SocketFd client = Connect(listener->port());
    if (!WaitUntil([&] { return kept.count == 1; })) fail();
    const rlimit low{64, 64};
    ++step;
    if (setrlimit(RLIMIT_NOFILE, &low) != 0) fail();
    std::vector<int> filler;
    for (int fd; (fd = ::open("/dev/null", O_RDONLY | O_CLOEXEC)) >= 0;) filler.push_back(fd);
    // The client side of a connection needs a descriptor too: give one back for it.
    ::close(filler.back());
    filler.pop_back();
    SocketFd starved = Connect(listener->port());
    ++step;
    if (!starved.valid()) fail();
    if (!WaitUntil([&] { return listener->descriptor_shortages() > 0; })) fail();
    ++step;
    if (listener->accepting()) fail();
    if (!ClosedByServer(starved)) fail();  // taken off the backlog and closed
    for (int fd : filler) ::close(fd);
    SocketFd after = Connect(listener->port());
    ++step;
    if (!after.valid()) fail();
    if (!WaitUntil([&] { return kept.count == 2; })) fail();
    if (!WaitUntil([&] { return listener->accepting(); })) fail();
    _exit(0);
  }
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0) << "the child failed at step " << WEXITSTATUS(status) - 10;
}

}  // namespace
}  // namespace motiondb::server
