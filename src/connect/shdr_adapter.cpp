// SPDX-License-Identifier: GPL-3.0-or-later
// The SHDR adapter: Boost.Asio on one thread of its own. Each connection gets the device's commands,
// a snapshot of every item, then every observation after it; nothing a client does (reading slowly,
// not at all, sending rubbish) holds up the others or the agent: each client reads the agent's
// buffer at its own pace, a little ahead of what its socket has taken, and is dropped when a write
// waits too long or the buffer forgets what it has not yet read.
#include "opencnc/connect/shdr_adapter.hpp"

#include <fmt/format.h>

#include <boost/asio.hpp>
#include <chrono>
#include <deque>
#include <list>
#include <mutex>
#include <thread>

#include "opencnc/connect/json_messages.hpp"
#include "opencnc/connect/listener.hpp"

namespace opencnc::connect {

namespace asio = boost::asio;
using asio::ip::tcp;
using Clock = std::chrono::steady_clock;

std::string shdr_field(std::string_view value) {
  if (value.find_first_of("|\"\r\n") == std::string_view::npos) return std::string(value);
  std::string out = "\"";
  for (char c : value) {
    if (c == '|' || c == '"') out += '\\';
    out += (c == '\r' || c == '\n') ? ' ' : c;
  }
  out += '"';
  return out;
}

namespace {

const char* shdr_level(Level l) {
  switch (l) {
    case Level::Unavailable:
      return "UNAVAILABLE";
    case Level::Normal:
      return "NORMAL";
    case Level::Warning:
      return "WARNING";
    case Level::Fault:
      return "FAULT";
  }
  return "UNAVAILABLE";
}

}  // namespace

std::string shdr_lines(const DeviceModel& model, std::span<const Observation> observations) {
  std::string out;
  std::int64_t line_time = 0;
  bool open = false;  // a line of samples and events is being written
  auto close_line = [&] {
    if (open) out += '\n';
    open = false;
  };
  for (const Observation& o : observations) {
    const DataItem& item = model.items()[o.item];
    if (item.category == Category::Condition) {
      close_line();
      // time|id|level|native_code|native_severity|qualifier|message: no severity or qualifier here.
      out += fmt::format("{}|{}|{}|{}|||{}\n", iso_time(o.time_us), item.id, shdr_level(o.level),
                         shdr_field(o.native_code), shdr_field(o.value));
      continue;
    }
    if (!open || o.time_us != line_time) {
      close_line();
      out += iso_time(o.time_us);
      line_time = o.time_us;
      open = true;
    }
    out += '|';
    out += item.id;
    out += '|';
    out += shdr_field(o.value);
  }
  close_line();
  return out;
}

// --- The server --------------------------------------------------------------------------------

struct ShdrAdapter::Impl {
  struct Client {
    explicit Client(tcp::socket s) : socket(std::move(s)) {}
    tcp::socket socket;
    asio::streambuf input{4096};  // a longer line is not SHDR: the client is dropped
    std::deque<std::string> output;
    std::size_t backlog = 0;  // bytes queued, not yet written
    bool writing = false, closed = false;
    Clock::time_point write_started{};  // of the write in progress
    std::uint64_t next = 0;             // the next observation this client gets
    Clock::time_point last_ping{};      // {} until its first PING: then it must keep pinging
  };

  Impl(const Agent& a, ShdrOptions o) : agent(a), options(std::move(o)) {}

  void accept() {
    acceptor.async_accept([this](boost::system::error_code ec, tcp::socket socket) {
      if (stopping) return;
      if (ec) {  // out of descriptors, or a connection gone before it was accepted: try again soon
        retry.expires_after(std::chrono::milliseconds(100));
        retry.async_wait([this](boost::system::error_code e) {
          if (!e && !stopping) accept();
        });
        return;
      }
      std::shared_ptr<Client> c;
      {
        std::lock_guard lock(stats_mutex);
        if (clients.size() >= options.max_clients) {
          ++stats.refused;
        } else {
          ++stats.connections;
          c = clients.emplace_back(std::make_shared<Client>(std::move(socket)));
        }
      }
      if (c) {
        greet(c);
        read(c);
      } else {
        boost::system::error_code ignored;
        socket.close(ignored);
      }
      accept();
    });
  }

  /// The commands, then every item's current state; the stream goes on from that instant.
  void greet(const std::shared_ptr<Client>& c) {
    std::string text = fmt::format("* adapterVersion: opencnc {}\n* mtconnectVersion: 2.7\n* device: {}\n",
                                   OPENCNC_VERSION, agent.model().uuid());
    const std::vector<Observation> now = agent.snapshot(&c->next);
    text += shdr_lines(agent.model(), now);
    {
      std::lock_guard lock(stats_mutex);
      stats.lines += now.size();
    }
    send(c, std::move(text));
  }

  void read(const std::shared_ptr<Client>& c) {
    asio::async_read_until(c->socket, c->input, '\n', [this, c](boost::system::error_code ec, std::size_t n) {
      if (ec) {
        if (ec == asio::error::not_found) {  // a line longer than the buffer: not an agent
          std::lock_guard lock(stats_mutex);
          ++stats.dropped_garbage;
        }
        close(c);
        return;
      }
      std::string line(asio::buffers_begin(c->input.data()), asio::buffers_begin(c->input.data()) + n);
      c->input.consume(n);
      while (!line.empty() && (line.back() == '\n' || line.back() == '\r')) line.pop_back();
      if (line == "* PING") {
        c->last_ping = Clock::now();
        {
          std::lock_guard lock(stats_mutex);
          ++stats.pongs;
        }
        send(c, fmt::format("* PONG {}\n", options.heartbeat_ms));
      }
      // Anything else from the agent is not ours to act on: read on.
      read(c);
    });
  }

  void send(const std::shared_ptr<Client>& c, std::string text) {
    if (c->closed || text.empty()) return;
    c->backlog += text.size();
    c->output.push_back(std::move(text));
    if (!c->writing) write(c);
  }

  void write(const std::shared_ptr<Client>& c) {
    c->writing = true;
    c->write_started = Clock::now();
    asio::async_write(c->socket, asio::buffer(c->output.front()),
                      [this, c](boost::system::error_code ec, std::size_t n) {
                        c->writing = false;
                        if (ec) {
                          close(c);
                          return;
                        }
                        c->backlog -= n;
                        c->output.pop_front();
                        if (!c->output.empty() && !c->closed) write(c);
                      });
  }

  void close(const std::shared_ptr<Client>& c) {
    std::lock_guard lock(stats_mutex);
    close_locked(c);
  }
  void close_locked(const std::shared_ptr<Client>& c) {
    if (c->closed) return;
    c->closed = true;
    boost::system::error_code ignored;
    c->socket.shutdown(tcp::socket::shutdown_both, ignored);
    c->socket.close(ignored);
    clients.remove(c);
  }

  /// Every poll: each client's new observations, and the silent ones closed.
  void poll() {
    timer.expires_after(std::chrono::milliseconds(options.poll_ms));
    timer.async_wait([this](boost::system::error_code ec) {
      if (ec || stopping) return;
      const Clock::time_point now = Clock::now();
      const auto silence = std::chrono::milliseconds(2 * options.heartbeat_ms);
      const auto stalled = std::chrono::milliseconds(options.write_timeout_ms);
      const std::vector<std::shared_ptr<Client>> each(clients.begin(), clients.end());
      for (const auto& c : each) {
        if (c->last_ping != Clock::time_point{} && now - c->last_ping > silence) {
          std::lock_guard lock(stats_mutex);
          ++stats.dropped_silent;
          close_locked(c);
          continue;
        }
        if (c->writing && now - c->write_started > stalled) {
          std::lock_guard lock(stats_mutex);
          ++stats.dropped_slow;
          close_locked(c);
          continue;
        }
        forward(c);
      }
      poll();
    });
  }

  void forward(const std::shared_ptr<Client>& c) {
    while (!c->closed && c->backlog < options.max_backlog_bytes) {
      std::uint64_t first = 0;
      const std::vector<Observation> batch = agent.observations(c->next, 1000, &first);
      if (first > c->next) {  // the agent's buffer turned over under this client: it starts again
        std::lock_guard lock(stats_mutex);
        ++stats.dropped_slow;
        close_locked(c);
        return;
      }
      if (batch.empty()) return;
      c->next = batch.back().sequence + 1;
      {
        std::lock_guard lock(stats_mutex);
        stats.lines += batch.size();
      }
      send(c, shdr_lines(agent.model(), batch));
    }
  }

  const Agent& agent;
  ShdrOptions options;
  asio::io_context io;
  tcp::acceptor acceptor{io};
  asio::steady_timer timer{io};
  asio::steady_timer retry{io};                // the next accept after a failed one
  std::list<std::shared_ptr<Client>> clients;  // the io thread's; stats_mutex guards its size for stats()
  std::thread thread;
  int bound_port = 0;
  bool stopping = false;  // the io thread's: nothing is started again once set
  mutable std::mutex stats_mutex;
  ShdrStats stats;
};

ShdrAdapter::ShdrAdapter(const Agent& agent, ShdrOptions options)
    : impl_(std::make_unique<Impl>(agent, std::move(options))) {
  const ShdrOptions& o = impl_->options;
  if (o.heartbeat_ms < 100 || o.poll_ms < 1 || o.max_clients == 0 || o.max_backlog_bytes == 0 ||
      o.write_timeout_ms < 1)
    throw std::invalid_argument(
        "shdr: the heartbeat must be ≥ 100 ms, the poll and the write timeout ≥ 1 ms, the clients and the "
        "backlog ≥ 1");
}

ShdrAdapter::~ShdrAdapter() {
  stop();
}

void ShdrAdapter::start() {
  Impl& m = *impl_;
  if (m.thread.joinable()) return;
  if (std::string why = open_listener(m.acceptor, m.options.host, static_cast<std::uint16_t>(m.options.port));
      !why.empty())
    throw std::runtime_error("shdr: " + why);
  m.bound_port = m.acceptor.local_endpoint().port();
  m.accept();
  m.poll();
  m.thread = std::thread([&m] { m.io.run(); });
}

void ShdrAdapter::stop() {
  Impl& m = *impl_;
  if (!m.thread.joinable()) return;
  // A handler already due (the poll's timer, an accept that completed) still runs after this:
  // `stopping` keeps it from starting anything again, and io.stop() ends the thread regardless.
  asio::post(m.io, [&m] {
    m.stopping = true;
    boost::system::error_code ignored;
    m.acceptor.close(ignored);
    m.timer.cancel();
    m.retry.cancel();
    const std::vector<std::shared_ptr<Impl::Client>> each(m.clients.begin(), m.clients.end());
    for (const auto& c : each) m.close(c);
    m.io.stop();
  });
  m.thread.join();
}

int ShdrAdapter::port() const noexcept {
  return impl_->bound_port;
}

ShdrStats ShdrAdapter::stats() const {
  std::lock_guard lock(impl_->stats_mutex);
  ShdrStats s = impl_->stats;
  s.clients = impl_->clients.size();
  return s;
}

}  // namespace opencnc::connect
