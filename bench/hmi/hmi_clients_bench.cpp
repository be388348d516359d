// SPDX-License-Identifier: GPL-3.0-or-later
// hmi_clients_bench: the simulated mill with a real-time servo thread runs the bracket program
// over and over while N WebSocket clients read the status stream (and S more connect and never
// read), and M MTConnect `/sample?interval=` streams (and T more that never read); prints the
// servo's overruns and wake-up latency, what the clients received, and who was dropped; and where
// the servo's lost periods went (stolen by the hypervisor, waiting for its CPU, preempted). Run it
// with --clients 0 --mtconnect 0 for the baseline of the same machine.
#include <sys/resource.h>
#include <unistd.h>

#include <array>
#include <boost/asio/connect.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/websocket.hpp>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

#include "opencnc/config/profile_loader.hpp"
#include "opencnc/connect/agent.hpp"
#include "opencnc/connect/status_sampler.hpp"
#include "opencnc/controller/gcode_source.hpp"
#include "opencnc/features/features.hpp"
#include "opencnc/hmi/machine_host.hpp"
#include "opencnc/hmi/server.hpp"
#include "servo_accounting.hpp"

namespace {

namespace beast = boost::beast;
namespace websocket = beast::websocket;
namespace http = beast::http;
namespace net = boost::asio;
using tcp = net::ip::tcp;
using namespace opencnc;

const std::string kToken = "bench-operator-token-0123456789";

/// One MTConnect stream: `GET /sample?interval=…`, then reads the multipart answer as it comes
/// (or, stalled, never reads a byte of it).
struct MtcStream : std::enable_shared_from_this<MtcStream> {
  MtcStream(net::io_context& ioc, bool stalled) : socket(ioc), stalled(stalled) {}
  void start(std::uint16_t port, int interval_ms) {
    socket.open(tcp::v4());
    if (stalled) socket.set_option(net::socket_base::receive_buffer_size(4096));
    request = "GET /sample?interval=" + std::to_string(interval_ms) +
              "&heartbeat=1000 HTTP/1.1\r\nHost: 127.0.0.1\r\nAuthorization: Bearer " + kToken + "\r\n\r\n";
    socket.async_connect(tcp::endpoint(net::ip::make_address("127.0.0.1"), port), [self = shared_from_this()](
                                                                                      beast::error_code ec) {
      if (ec) return;
      net::async_write(self->socket, net::buffer(self->request), [self](beast::error_code e, std::size_t) {
        self->connected = !e;
        if (!e && !self->stalled) self->read();
      });
    });
  }
  void read() {
    socket.async_read_some(net::buffer(chunk),
                           [self = shared_from_this()](beast::error_code ec, std::size_t n) {
                             if (ec) {
                               self->closed = true;
                               return;
                             }
                             self->bytes += n;
                             self->read();
                           });
  }
  tcp::socket socket;
  bool stalled;
  std::string request;
  std::array<char, 65536> chunk{};
  bool connected = false, closed = false;
  std::uint64_t bytes = 0;
};

/// One client: connects, then reads every message (or, stalled, never reads one).
struct Client : std::enable_shared_from_this<Client> {
  Client(net::io_context& ioc, bool stalled) : ws(ioc), stalled(stalled) {}
  void start(std::uint16_t port, int receive_buffer) {
    auto& s = beast::get_lowest_layer(ws).socket();
    s.open(tcp::v4());
    if (receive_buffer > 0) s.set_option(net::socket_base::receive_buffer_size(receive_buffer));
    beast::get_lowest_layer(ws).async_connect(tcp::endpoint(net::ip::make_address("127.0.0.1"), port),
                                              [self = shared_from_this()](beast::error_code ec) {
                                                if (ec) return;
                                                self->ws.set_option(websocket::stream_base::decorator(
                                                    [](websocket::request_type& req) {
                                                      req.set(http::field::authorization, "Bearer " + kToken);
                                                    }));
                                                self->ws.async_handshake("127.0.0.1", "/api/v1/stream",
                                                                         [self](beast::error_code e) {
                                                                           self->connected = !e;
                                                                           if (!e && !self->stalled)
                                                                             self->read();
                                                                         });
                                              });
  }
  void read() {
    ws.async_read(buffer, [self = shared_from_this()](beast::error_code ec, std::size_t n) {
      if (ec) {
        self->closed = true;
        return;
      }
      ++self->messages;
      self->bytes += n;
      self->buffer.consume(self->buffer.size());
      self->read();
    });
  }
  websocket::stream<beast::tcp_stream> ws;
  beast::flat_buffer buffer;
  bool stalled;
  bool connected = false, closed = false;
  std::uint64_t messages = 0, bytes = 0;
};

double cpu_s() {
  rusage u{};
  ::getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
         (u.ru_utime.tv_usec + u.ru_stime.tv_usec) * 1e-6;
}

// Where the lost periods went: the servo thread's own accounting over the run, then each overrun
// with the stolen time and run-queue wait in the 20 ms before its deadline and after its end.
void print_accounting(const bench::ServoAccounting& a, const std::vector<control::OverrunRecord>& log,
                      std::uint64_t ticks, bool list) {
  if (!a.error().empty() || a.samples().size() < 2) {
    std::printf("servo accounting: %s\n", a.error().empty() ? "too few samples" : a.error().c_str());
    return;
  }
  const auto& first = a.samples().front();
  const auto& last = a.samples().back();
  std::printf(
      "servo thread: waited %.3f ms for its CPU, preempted %llu times, slept %llu times in %llu periods; "
      "%.0f ms stolen from its CPU by the hypervisor\n",
      static_cast<double>(last.run_delay_ns - first.run_delay_ns) / 1e6,
      static_cast<unsigned long long>(last.involuntary - first.involuntary),
      static_cast<unsigned long long>(last.voluntary - first.voluntary), static_cast<unsigned long long>(ticks),
      static_cast<double>(last.steal_ticks - first.steal_ticks) * 1000.0 / static_cast<double>(sysconf(_SC_CLK_TCK)));
  constexpr std::int64_t kAround = 20'000'000;
  int late = 0, long_tick = 0, stolen = 0, waited = 0, neither = 0;
  double worst_ms = 0;
  for (const auto& c : a.attribute(log, kAround, kAround)) {
    const double woke_ms = static_cast<double>(c.record.woke_ns - c.record.deadline_ns) / 1e6;
    const double tick_ms = static_cast<double>(c.record.done_ns - c.record.woke_ns) / 1e6;
    (woke_ms >= tick_ms ? late : long_tick) += 1;
    worst_ms = std::max(worst_ms, woke_ms + tick_ms);
    if (c.steal_ticks > 0)
      ++stolen;
    else if (c.run_delay_ns > 100'000 || c.involuntary > 0)
      ++waited;
    else
      ++neither;
    if (list)
      std::printf("  overrun at %.3f s: woke %.3f ms late, tick %.3f ms; around it: %llu stolen ticks, "
                  "%.3f ms run-queue wait, %llu preemptions\n",
                  static_cast<double>(c.record.deadline_ns - a.samples().front().t_ns) / 1e9, woke_ms, tick_ms,
                  static_cast<unsigned long long>(c.steal_ticks), static_cast<double>(c.run_delay_ns) / 1e6,
                  static_cast<unsigned long long>(c.involuntary));
  }
  std::printf(
      "overruns logged: %zu (woke late %d, tick ran long %d; worst %.3f ms); within 20 ms of stolen time %d, "
      "of the thread waiting for its CPU %d, of neither %d\n",
      log.size(), late, long_tick, worst_ms, stolen, waited, neither);
}

int usage() {
  std::fprintf(
      stderr,
      "usage: hmi_clients_bench [--clients N (100)] [--stalled S (5)] [--seconds T (30)] [--hz R (30)] "
      "[--servo-cpu N]\n"
      "                         [--mtconnect M (0)] [--mtconnect-stalled T (0)] [--interval MS (100)]\n"
      "                         [--overruns] (list each overrun with what was seen around it)\n");
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  int clients = 100, stalled = 5, mtconnect = 0, mtconnect_stalled = 0, interval_ms = 100;
  double seconds = 30, hz = 30;
  int servo_cpu = -1;
  bool list_overruns = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "-h" || a == "--help") return usage(), 0;
    if (a == "--overruns") {
      list_overruns = true;
      continue;
    }
    if (i + 1 >= argc) return usage();
    if (a == "--clients")
      clients = std::atoi(argv[++i]);
    else if (a == "--stalled")
      stalled = std::atoi(argv[++i]);
    else if (a == "--seconds")
      seconds = std::atof(argv[++i]);
    else if (a == "--hz")
      hz = std::atof(argv[++i]);
    else if (a == "--mtconnect")
      mtconnect = std::atoi(argv[++i]);
    else if (a == "--mtconnect-stalled")
      mtconnect_stalled = std::atoi(argv[++i]);
    else if (a == "--interval")
      interval_ms = std::atoi(argv[++i]);
    else if (a == "--servo-cpu")
      servo_cpu = std::atoi(argv[++i]);
    else
      return usage();
  }
  const auto load = config::load_profile(OPENCNC_SOURCE_DIR "/configs/mill-3axis.toml");
  if (!load.ok()) return 1;
  Diagnostics d;
  auto source = features::machine_setup(*load.profile, d)->source();
  hmi::HostOptions ho;
  ho.servo_cpu = servo_cpu;  // the clients' threads start after host.start(): they keep off it too
  hmi::MachineHost host(*load.profile, source, ho);
  std::vector<std::string> warnings;
  host.start(&warnings);
  for (const auto& w : warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
  // The MTConnect agent, sampled at 10 Hz as `opencnc serve` does.
  const auto agent = connect::Agent::for_profile(*load.profile, connect::AgentOptions{});
  connect::StatusSampler sampler(
      *agent, [&host] { return host.controller().status(); },
      [] { return std::vector<connect::ToolAsset>{}; },
      connect::SamplerOptions{std::chrono::milliseconds(100), std::chrono::seconds(2)});
  sampler.start();
  hmi::ServerConfig sc;
  sc.mtconnect = agent.get();
  sc.port = 0;
  sc.stream_hz = hz;
  sc.programs_dir = OPENCNC_SOURCE_DIR "/examples";
  hmi::Server server(host.controller(), *load.profile, hmi::Tokens::of(kToken, kToken + "-admin"), nullptr,
                     source.get(), sc);
  std::string error;
  if (!server.start(&error)) return std::fprintf(stderr, "error: %s\n", error.c_str()), 1;

  controller::Controller& c = host.controller();
  for (auto r : {controller::Request::simple(control::CommandKind::MachineOn),
                 controller::Request::set_mode(control::Mode::Auto),
                 controller::Request::open(OPENCNC_SOURCE_DIR "/examples/bracket.ngc")}) {
    const auto id = c.submit(std::move(r));
    while (!c.outcome(id)) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  net::io_context ioc;
  std::vector<std::shared_ptr<Client>> all;
  for (int k = 0; k < clients + stalled; ++k) {
    all.push_back(std::make_shared<Client>(ioc, k >= clients));
    all.back()->start(server.port(), k >= clients ? 4096 : 0);
  }
  std::vector<std::shared_ptr<MtcStream>> streams;
  for (int k = 0; k < mtconnect + mtconnect_stalled; ++k) {
    streams.push_back(std::make_shared<MtcStream>(ioc, k >= mtconnect));
    streams.back()->start(server.port(), interval_ms);
  }
  std::thread io([&ioc] {
    auto guard = net::make_work_guard(ioc);
    ioc.run();
  });

  // Sampled every 2 ms from a thread that, started after the servo's, keeps off the servo's CPU.
  const control::RealtimeClock* clock = host.realtime_clock();
  bench::ServoAccounting accounting(clock ? clock->thread_id() : 0, servo_cpu, 2'000'000);
  const std::uint64_t logged0 = clock ? clock->overrun_log().size() : 0;

  // The operator: starts the program, confirms tool changes, starts it again when it ends.
  const std::uint64_t ticks0 = host.ticks(), overruns0 = host.overruns();
  const double cpu0 = cpu_s();
  const auto t0 = std::chrono::steady_clock::now();
  while (std::chrono::steady_clock::now() - t0 < std::chrono::duration<double>(seconds)) {
    const auto s = c.status();
    if (s.servo.state == control::State::Idle && !s.run_active)
      c.submit(controller::Request::simple(control::CommandKind::CycleStart));
    if (s.servo.wait == control::Wait::ManualToolChange)
      c.submit(controller::Request::simple(control::CommandKind::ToolChanged));
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const double cpu = cpu_s() - cpu0;
  const std::uint64_t ticks = host.ticks() - ticks0, overruns = host.overruns() - overruns0;
  const auto stats = server.stats();
  const auto* lat = host.latency();
  const auto last = c.status();
  const auto finished = last.runs_finished;
  accounting.stop();
  std::vector<control::OverrunRecord> log = clock ? clock->overrun_log() : std::vector<control::OverrunRecord>{};
  log.erase(log.begin(), log.begin() + static_cast<std::ptrdiff_t>(std::min<std::uint64_t>(logged0, log.size())));
  ioc.stop();
  io.join();
  server.stop();
  sampler.stop();
  host.stop();

  std::uint64_t min_msgs = UINT64_MAX, max_msgs = 0, sum = 0, bytes = 0;
  int connected = 0, stalled_closed = 0;
  for (int k = 0; k < clients + stalled; ++k) {
    const Client& cl = *all[static_cast<std::size_t>(k)];
    if (k >= clients) {
      stalled_closed += cl.connected ? 1 : 0;
      continue;
    }
    connected += cl.connected ? 1 : 0;
    min_msgs = std::min(min_msgs, cl.messages);
    max_msgs = std::max(max_msgs, cl.messages);
    sum += cl.messages;
    bytes += cl.bytes;
  }
  std::printf(
      "servo: %llu periods in %.1f s, %llu overruns; wake-up latency p99 %.1f us, p99.9 %.1f us, max %.1f us "
      "(SCHED_FIFO: %s)\n",
      static_cast<unsigned long long>(ticks), wall, static_cast<unsigned long long>(overruns),
      lat->percentile_ns(0.99) / 1e3, lat->percentile_ns(0.999) / 1e3, lat->max_ns() / 1e3,
      warnings.empty() ? "yes" : "no");
  std::printf("clients: %d of %d connected, messages per client %llu..%llu (mean %.1f/s), %.1f MB in all\n",
              connected, clients, static_cast<unsigned long long>(clients ? min_msgs : 0),
              static_cast<unsigned long long>(max_msgs),
              clients ? static_cast<double>(sum) / clients / wall : 0.0, static_cast<double>(bytes) / 1e6);
  std::printf("stalled clients: %d connected, %llu dropped by the server\n", stalled_closed,
              static_cast<unsigned long long>(stats.dropped));
  std::printf("programs finished: %llu, the last at %.0f %% (line %u)%s%s; process CPU %.2f s (%.0f %% of one core)\n",
              static_cast<unsigned long long>(finished), 100 * last.progress, last.location.line,
              last.fault_text.empty() ? "" : ", fault: ", last.fault_text.c_str(), cpu, 100 * cpu / wall);
  if (mtconnect + mtconnect_stalled > 0) {
    std::uint64_t low = UINT64_MAX, high = 0;
    int open = 0;
    for (int k = 0; k < mtconnect; ++k) {
      const MtcStream& s = *streams[static_cast<std::size_t>(k)];
      low = std::min(low, s.bytes);
      high = std::max(high, s.bytes);
      open += s.connected && !s.closed;
    }
    std::printf(
        "mtconnect streams: %d of %d reading to the end, %.1f..%.1f kB each, %llu parts sent; "
        "%d stalled, %llu dropped by the server\n",
        open, mtconnect, mtconnect ? static_cast<double>(low) / 1e3 : 0.0, static_cast<double>(high) / 1e3,
        static_cast<unsigned long long>(stats.mtconnect_parts), mtconnect_stalled,
        static_cast<unsigned long long>(stats.mtconnect_dropped));
  }
  print_accounting(accounting, log, ticks, list_overruns);
  return 0;
}
