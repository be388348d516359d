// SPDX-License-Identifier: GPL-3.0-or-later
// TaskRunner: one worker thread, one task at a time, handed over under a mutex.
#include "task_runner.hpp"

#include <utility>

namespace opencnc::controller::detail {

TaskRunner::~TaskRunner() {
  if (!thread_.joinable()) return;
  {
    std::lock_guard lock(mutex_);
    quit_ = true;
  }
  wake_.notify_one();
  thread_.join();
}

void TaskRunner::start(std::function<void()> work) {
  started_ = true;
  done_.store(false, std::memory_order_relaxed);
  if (!threaded_) {
    work();
    done_.store(true, std::memory_order_release);
    return;
  }
  {
    std::lock_guard lock(mutex_);
    work_ = std::move(work);
  }
  if (!thread_.joinable()) thread_ = std::thread([this] { loop(); });
  wake_.notify_one();
}

void TaskRunner::loop() {
  std::unique_lock lock(mutex_);
  for (;;) {
    wake_.wait(lock, [this] { return quit_ || work_; });
    if (quit_) return;
    std::function<void()> work = std::move(work_);
    work_ = nullptr;
    lock.unlock();
    work();  // the controller's own code: it reports its failures in what it writes, never throws
    lock.lock();
    done_.store(true, std::memory_order_release);
  }
}

}  // namespace opencnc::controller::detail
