// SPDX-License-Identifier: GPL-3.0-or-later
// TaskRunner — the controller's long work (a preflight, the replay before a resume) on a thread
// of its own, so that the controller's loop goes on reading the servo, publishing the status and
// passing stops while it runs; or, in virtual time, at once on the caller's thread, so that a run
// repeats bit for bit.
#pragma once

#include <atomic>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <thread>

namespace opencnc::controller::detail {

/// One task at a time. start(), idle(), finished() and collect() from the controller's thread.
class TaskRunner {
 public:
  /// `threaded`: tasks run on a thread of their own (started with the first task); otherwise
  /// start() runs the task before it returns.
  explicit TaskRunner(bool threaded) noexcept : threaded_(threaded) {}
  ~TaskRunner();
  TaskRunner(const TaskRunner&) = delete;
  TaskRunner& operator=(const TaskRunner&) = delete;

  /// Starts `work`; only while idle(). Not threaded: `work` has run when this returns.
  void start(std::function<void()> work);
  /// No task started, or the last one collected.
  bool idle() const noexcept { return !started_; }
  /// The task started has run: collect() it.
  bool finished() const noexcept { return started_ && done_.load(std::memory_order_acquire); }
  /// After finished(): idle again (what the task wrote is visible to the caller).
  void collect() noexcept { started_ = false; }

 private:
  void loop();

  bool threaded_;
  bool started_ = false;
  std::atomic<bool> done_{false};
  std::mutex mutex_;
  std::condition_variable wake_;
  std::function<void()> work_;  ///< under mutex_: the task the thread is to run
  bool quit_ = false;           ///< under mutex_
  std::thread thread_;
};

}  // namespace opencnc::controller::detail
