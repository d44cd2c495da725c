// Admission at --threads N: calls beyond N wait in line, first come first served, and only a
// full line refuses. No timing: the tests wait on the gate's own state.
#include "server/grpc/call_gate.h"

#include <gtest/gtest.h>

#include <atomic>
#include <future>
#include <mutex>
#include <thread>
#include <vector>

namespace motiondb::server {
namespace {

// A call that runs until released.
class HeldCall {
 public:
  grpc::Status operator()() {
    started_.set_value();
    release_.get_future().wait();
    return grpc::Status::OK;
  }
  void WaitStarted() { started_.get_future().wait(); }
  void Release() { release_.set_value(); }

 private:
  std::promise<void> started_;
  std::promise<void> release_;
};

// A thread running `held` through the gate, returned once the call holds the gate's slot.
std::thread RunHeld(CallGate& gate, grpc::ServerContext& context, HeldCall& held) {
  std::thread thread([&] { EXPECT_TRUE(gate.Run(&context, std::ref(held)).ok()); });
  held.WaitStarted();
  return thread;
}

void WaitForWaiting(const CallGate& gate, int waiting) {
  while (gate.waiting() != waiting) std::this_thread::yield();
}

TEST(CallGateTest, NoLimitRunsAtOnce) {
  CallGate gate(0, 0);
  grpc::ServerContext context;
  int runs = 0;
  EXPECT_TRUE(gate.Run(&context,
                       [&] {
                         ++runs;
                         return grpc::Status::OK;
                       })
                  .ok());
  EXPECT_EQ(runs, 1);
}

TEST(CallGateTest, CallsBeyondTheLimitWaitTheirTurnInOrder) {
  CallGate gate(1, 2);
  grpc::ServerContext first_context, second_context, third_context;
  HeldCall held;
  std::thread first = RunHeld(gate, first_context, held);

  std::mutex mutex;
  std::vector<int> order;
  auto recording = [&](int id) {
    return [&, id] {
      std::lock_guard<std::mutex> lock(mutex);
      order.push_back(id);
      return grpc::Status::OK;
    };
  };
  std::thread second([&] { EXPECT_TRUE(gate.Run(&second_context, recording(2)).ok()); });
  WaitForWaiting(gate, 1);
  std::thread third([&] { EXPECT_TRUE(gate.Run(&third_context, recording(3)).ok()); });
  WaitForWaiting(gate, 2);
  {
    std::lock_guard<std::mutex> lock(mutex);
    EXPECT_TRUE(order.empty());  // both wait while the first runs
  }
  held.Release();
  first.join();
  second.join();
  third.join();
  EXPECT_EQ(order, (std::vector<int>{2, 3}));
  EXPECT_EQ(gate.waiting(), 0);
}

TEST(CallGateTest, AFullLineRefusesWithTheLimit) {
  CallGate gate(1, 1);
  grpc::ServerContext first_context, second_context, third_context;
  HeldCall held;
  std::thread first = RunHeld(gate, first_context, held);
  std::thread second(
      [&] { EXPECT_TRUE(gate.Run(&second_context, [] { return grpc::Status::OK; }).ok()); });
  WaitForWaiting(gate, 1);
  std::atomic<bool> ran{false};
  const grpc::Status refused = gate.Run(&third_context, [&] {
    ran = true;
    return grpc::Status::OK;
  });
  EXPECT_EQ(refused.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_NE(refused.error_message().find("--threads 1"), std::string::npos)
      << refused.error_message();
  EXPECT_FALSE(ran);
  held.Release();
  first.join();
  second.join();
}

}  // namespace
}  // namespace motiondb::server
