#include "server/http/worker_pool.h"

namespace motiondb::server {

WorkerPool::WorkerPool(int threads, int max_waiting) : max_waiting_(max_waiting) {
  for (int i = 0; i < threads; ++i) threads_.emplace_back([this] { Work(); });
}

WorkerPool::~WorkerPool() { Join(); }

bool WorkerPool::TryPost(std::function<void()> task) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    // A task an idle worker takes at once does not wait.
    const int idle = static_cast<int>(threads_.size()) - busy_;
    if (joining_ || static_cast<int>(tasks_.size()) >= max_waiting_ + idle) return false;
    tasks_.push_back(std::move(task));
  }
  posted_.notify_one();
  return true;
}

void WorkerPool::Join() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    joining_ = true;
  }
  posted_.notify_all();
  for (std::thread& thread : threads_) {
    if (thread.joinable()) thread.join();
  }
}

int WorkerPool::busy() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return busy_;
}

int WorkerPool::waiting() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return static_cast<int>(tasks_.size());
}

void WorkerPool::Work() {
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    posted_.wait(lock, [this] { return joining_ || !tasks_.empty(); });
    if (tasks_.empty()) return;  // joining, and nothing left
    std::function<void()> task = std::move(tasks_.front());
    tasks_.pop_front();
    ++busy_;
    lock.unlock();
    task();
    lock.lock();
    --busy_;
  }
}

}  // namespace motiondb::server
