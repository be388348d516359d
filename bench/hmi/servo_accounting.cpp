// SPDX-License-Identifier: GPL-3.0-or-later
// Where a real-time servo thread's lost periods went (see servo_accounting.hpp).
#include "servo_accounting.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <fstream>
#include <sstream>

namespace opencnc::bench {
namespace {

std::int64_t now_ns() {
  timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// The 8th value of /proc/stat's "cpuN" line (or "cpu " for the whole machine) is stolen time.
bool read_steal(int cpu, std::uint64_t& steal) {
  const std::string stat = slurp("/proc/stat");
  const std::string key = cpu < 0 ? "cpu " : "cpu" + std::to_string(cpu) + " ";
  const auto at = stat.find(key);
  if (at == std::string::npos) return false;
  std::istringstream line(stat.substr(at + key.size(), stat.find('\n', at) - at - key.size()));
  std::uint64_t v[8] = {};
  for (auto& x : v)
    if (!(line >> x)) return false;
  steal = v[7];
  return true;
}

std::uint64_t status_value(const std::string& status, const char* key) {
  const auto at = status.find(key);
  return at == std::string::npos ? 0 : std::strtoull(status.c_str() + at + std::strlen(key), nullptr, 10);
}

}  // namespace

ServoAccounting::ServoAccounting(int servo_tid, int cpu, std::int64_t interval_ns)
    : tid_(servo_tid), cpu_(cpu), interval_ns_(interval_ns) {
  AccountingSample first;
  if (tid_ <= 0 || !sample(first)) {
    error_ = "cannot read /proc/stat or the servo thread's /proc/self/task/<tid>/schedstat";
    return;
  }
  samples_.reserve(1 << 16);
  samples_.push_back(first);
  thread_ = std::thread([this] {
    while (!stop_.load(std::memory_order_acquire)) {
      std::this_thread::sleep_for(std::chrono::nanoseconds(interval_ns_));
      AccountingSample s;
      if (sample(s)) samples_.push_back(s);
    }
  });
}

ServoAccounting::~ServoAccounting() { stop(); }

void ServoAccounting::stop() {
  stop_.store(true, std::memory_order_release);
  if (thread_.joinable()) thread_.join();
}

bool ServoAccounting::sample(AccountingSample& s) const {
  const std::string task = "/proc/self/task/" + std::to_string(tid_);
  if (!read_steal(cpu_, s.steal_ticks)) return false;
  unsigned long long on_cpu = 0, delay = 0;
  if (std::sscanf(slurp(task + "/schedstat").c_str(), "%llu %llu", &on_cpu, &delay) != 2) return false;
  s.run_delay_ns = delay;
  const std::string status = slurp(task + "/status");
  s.voluntary = status_value(status, "\nvoluntary_ctxt_switches:");
  s.involuntary = status_value(status, "nonvoluntary_ctxt_switches:");
  s.t_ns = now_ns();
  return true;
}

std::vector<OverrunCause> ServoAccounting::attribute(const std::vector<control::OverrunRecord>& log,
                                                     std::int64_t before_ns, std::int64_t after_ns) const {
  std::vector<OverrunCause> out;
  if (samples_.empty()) return out;
  // The last sample at or before t, and the first at or after t (clamped to the run).
  const auto at_or_before = [&](std::int64_t t) {
    auto it = std::upper_bound(samples_.begin(), samples_.end(), t,
                               [](std::int64_t v, const AccountingSample& s) { return v < s.t_ns; });
    return it == samples_.begin() ? *it : *(it - 1);
  };
  const auto at_or_after = [&](std::int64_t t) {
    auto it = std::lower_bound(samples_.begin(), samples_.end(), t,
                               [](const AccountingSample& s, std::int64_t v) { return s.t_ns < v; });
    return it == samples_.end() ? samples_.back() : *it;
  };
  for (const auto& r : log) {
    const AccountingSample a = at_or_before(r.deadline_ns - before_ns);
    const AccountingSample b = at_or_after(r.done_ns + after_ns);
    out.push_back({r, b.steal_ticks - a.steal_ticks, b.run_delay_ns - a.run_delay_ns, b.involuntary - a.involuntary});
  }
  return out;
}

}  // namespace opencnc::bench
