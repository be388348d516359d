// SPDX-License-Identifier: GPL-3.0-or-later
// A real mosquitto broker started by a test on a free loopback port, a subscriber that collects what
// it receives, and a status that changes every call (synthetic machines for the publishers).
#pragma once

#include <fcntl.h>
#include <mosquitto.h>
#include <netinet/in.h>
#include <signal.h>
#include <spawn.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "opencnc/controller/controller_status.hpp"

extern char** environ;

namespace opencnc::connect::test {

/// Waits up to `limit` for `done`, asking every 10 ms; its last answer.
template <typename F>
bool eventually(F done, std::chrono::milliseconds limit = std::chrono::seconds(10)) {
  const auto until = std::chrono::steady_clock::now() + limit;
  while (std::chrono::steady_clock::now() < until) {
    if (done()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return done();
}

inline int free_port() {
  const int s = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ::bind(s, reinterpret_cast<sockaddr*>(&a), sizeof a);
  socklen_t n = sizeof a;
  ::getsockname(s, reinterpret_cast<sockaddr*>(&a), &n);
  ::close(s);
  return ntohs(a.sin_port);
}

inline bool port_open(int port) {
  const int s = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(static_cast<std::uint16_t>(port));
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  const bool ok = ::connect(s, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0;
  ::close(s);
  return ok;
}

/// `mosquitto` on 127.0.0.1:port, without persistence (a kill loses what it held).
class Broker {
 public:
  /// `start`: false leaves the broker down until start() (a machine that starts before its broker).
  explicit Broker(bool start_now = true) : port_(free_port()) {
    conf_ = std::filesystem::temp_directory_path() /
            ("opencnc-mosquitto-" + std::to_string(::getpid()) + "-" + std::to_string(port_) + ".conf");
    std::ofstream(conf_) << "listener " << port_ << " 127.0.0.1\nallow_anonymous true\npersistence false\n"
                         << (::getuid() == 0 ? "user root\n" : "");
    if (start_now) start();
  }
  ~Broker() {
    kill();
    std::filesystem::remove(conf_);
  }
  bool start() {
    std::string conf = conf_.string();
    std::vector<char*> argv{const_cast<char*>("mosquitto"), const_cast<char*>("-c"), conf.data(), nullptr};
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_addopen(&fa, 2, "/dev/null", O_WRONLY, 0);  // its log lines
    const int rc = ::posix_spawnp(&pid_, "mosquitto", &fa, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&fa);
    if (rc != 0) return false;
    for (int i = 0; i < 500; ++i) {
      if (port_open(port_)) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return false;
  }
  void kill() {
    if (pid_ <= 0) return;
    ::kill(pid_, SIGKILL);
    ::waitpid(pid_, nullptr, 0);
    pid_ = -1;
  }
  int port() const { return port_; }

 private:
  int port_;
  pid_t pid_ = -1;
  std::filesystem::path conf_;
};

/// Subscribes to `MTConnect/#` and keeps what arrives: the sample sequences per device, the
/// availability and the retained messages.
class Subscriber {
 public:
  explicit Subscriber(int port) {
    mosquitto_lib_init();
    client_ = mosquitto_new(nullptr, true, this);
    mosquitto_connect_callback_set(client_, [](mosquitto* m, void*, int rc) {
      if (rc == 0) mosquitto_subscribe(m, nullptr, "MTConnect/#", 1);
    });
    mosquitto_subscribe_callback_set(client_, [](mosquitto*, void* self, int, int, const int*) {
      static_cast<Subscriber*>(self)->subscribed_ = true;
    });
    mosquitto_message_callback_set(client_, [](mosquitto*, void* self, const mosquitto_message* msg) {
      static_cast<Subscriber*>(self)->take(msg);
    });
    mosquitto_reconnect_delay_set(client_, 1, 1, false);
    mosquitto_connect_async(client_, "127.0.0.1", port, 5);
    mosquitto_loop_start(client_);
  }
  ~Subscriber() {
    mosquitto_disconnect(client_);
    mosquitto_loop_stop(client_, true);
    mosquitto_destroy(client_);
  }
  struct Device {
    std::multiset<std::uint64_t> sequences;
    std::vector<nlohmann::json> gaps;
    std::vector<std::string> availability;
    std::chrono::steady_clock::time_point unavailable_at{};
    bool probe = false, current = false;
  };
  /// The broker has confirmed the subscription.
  bool subscribed() const { return subscribed_; }
  std::map<std::string, Device> devices() const {
    std::lock_guard lock(mutex_);
    return devices_;
  }

 private:
  void take(const mosquitto_message* msg) {
    const std::string topic = msg->topic;
    const std::string payload(static_cast<const char*>(msg->payload),
                              static_cast<std::size_t>(msg->payloadlen));
    const auto a = topic.find('/'), b = topic.find('/', a + 1);
    if (a == std::string::npos || b == std::string::npos) return;
    const std::string kind = topic.substr(a + 1, b - a - 1), uuid = topic.substr(b + 1);
    std::lock_guard lock(mutex_);
    Device& d = devices_[uuid];
    if (kind == "Availability") {
      d.availability.push_back(payload);
      if (payload == "UNAVAILABLE") d.unavailable_at = std::chrono::steady_clock::now();
    } else if (kind == "Probe") {
      d.probe = true;
    } else if (kind == "Current") {
      d.current = true;
    } else if (kind == "Sample") {
      const auto j = nlohmann::json::parse(payload);
      for (const auto& o : j["observations"]) d.sequences.insert(o["sequence"].get<std::uint64_t>());
      if (j.contains("gap")) d.gaps.push_back(j["gap"]);
    }
  }
  mosquitto* client_ = nullptr;
  std::atomic<bool> subscribed_{false};
  mutable std::mutex mutex_;
  std::map<std::string, Device> devices_;
};

#ifdef MQTT_MACHINE
/// A machine publishing in a process of its own (tests/connect/mqtt_machine.cpp), killed with
/// SIGKILL by kill() or at the latest when this goes: a killed machine closes no connection.
class MachineProcess {
 public:
  /// `profile` below the source folder ("configs/mill-3axis.toml").
  MachineProcess(const std::string& profile, const std::string& name, int port, int keepalive_s) {
    const std::string exe = MQTT_MACHINE;
    const std::string file = (std::filesystem::path(OPENCNC_SOURCE_DIR) / profile).string();
    const std::string p = std::to_string(port), k = std::to_string(keepalive_s);
    std::vector<char*> argv{const_cast<char*>(exe.c_str()),  const_cast<char*>(file.c_str()),
                            const_cast<char*>(name.c_str()), const_cast<char*>(p.c_str()),
                            const_cast<char*>(k.c_str()),    nullptr};
    if (::posix_spawn(&pid_, exe.c_str(), nullptr, nullptr, argv.data(), environ) != 0) pid_ = -1;
  }
  ~MachineProcess() { kill(); }
  MachineProcess(const MachineProcess&) = delete;
  MachineProcess& operator=(const MachineProcess&) = delete;
  bool running() const { return pid_ > 0; }
  void kill() {
    if (pid_ <= 0) return;
    ::kill(pid_, SIGKILL);
    ::waitpid(pid_, nullptr, 0);
    pid_ = -1;
  }

 private:
  pid_t pid_ = -1;
};
#endif

/// A status that moves a little at each call: X, Y and the feed change, every 50th call the mode.
inline controller::ControllerStatus moving_status(std::uint64_t i) {
  controller::ControllerStatus s;
  s.servo.state = control::State::Running;
  s.servo.estop_input_ok = true;
  s.servo.mode = i / 50 % 2 ? control::Mode::Auto : control::Mode::Mdi;
  s.servo.actual[0] = s.servo.commanded[0] = 0.001 * static_cast<double>(i);
  s.servo.actual[1] = s.servo.commanded[1] = -0.002 * static_cast<double>(i);
  s.servo.path_velocity = static_cast<double>(i % 100);
  return s;
}

}  // namespace opencnc::connect::test
