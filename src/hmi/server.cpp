// SPDX-License-Identifier: GPL-3.0-or-later
// The HMI server on Boost.Beast: HTTP sessions (the JSON API, the front end's files) and
// WebSocket sessions (status at a steady rate, each client's own cursor on the event log).
#include "opencnc/hmi/server.hpp"
#include "opencnc/connect/listener.hpp"
#include "opencnc/connect/status_sampler.hpp"

#include <atomic>
#include <chrono>
#include <fstream>
#include <mutex>
#include <thread>
#include <vector>

#include <fmt/format.h>
#include <boost/asio/dispatch.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/asio/strand.hpp>
#include <boost/asio/thread_pool.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>

#include "opencnc/controller/gcode_source.hpp"
#include "opencnc/hmi/api.hpp"
#include "opencnc/hmi/api_admin.hpp"
#include "opencnc/hmi/api_cutchart.hpp"
#include "opencnc/hmi/history.hpp"
#include "opencnc/hmi/machine_features.hpp"
#include "opencnc/hmi/preview.hpp"
#include "opencnc/hmi/static_files.hpp"
#include "opencnc/hmi/stream_tickets.hpp"
#include "opencnc/tools/tool_table_service.hpp"

namespace opencnc::hmi {

namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
namespace net = boost::asio;
using tcp = net::ip::tcp;
using nlohmann::json;
using HttpRequest = http::request<http::string_body>;
using HttpResponse = http::response<http::string_body>;

namespace {

constexpr std::size_t kBodyLimit = 1 << 20;
constexpr std::size_t kEventsPerMessage = 256;
constexpr int kSendBufferBytes = 64 * 1024;  ///< small, so a client that stops reading shows soon

/// The path and the decoded query parameters of a request target.
struct Target {
  std::string path;
  std::map<std::string, std::string> query;
};

std::string_view sv(beast::string_view s) {
  return {s.data(), s.size()};
}

std::string url_decode(std::string_view s) {
  std::string out;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s[i] == '+') {
      out += ' ';
    } else if (s[i] == '%' && i + 2 < s.size() && std::isxdigit(static_cast<unsigned char>(s[i + 1])) &&
               std::isxdigit(static_cast<unsigned char>(s[i + 2]))) {
      out += static_cast<char>(std::stoi(std::string(s.substr(i + 1, 2)), nullptr, 16));
      i += 2;
    } else {
      out += s[i];
    }
  }
  return out;
}

Target parse_target(std::string_view t) {
  Target r;
  const std::size_t q = t.find('?');
  r.path = url_decode(t.substr(0, q));
  if (q == std::string_view::npos) return r;
  std::string_view rest = t.substr(q + 1);
  while (!rest.empty()) {
    const std::size_t amp = rest.find('&');
    const std::string_view kv = rest.substr(0, amp);
    const std::size_t eq = kv.find('=');
    r.query[url_decode(kv.substr(0, eq))] = eq == std::string_view::npos ? "" : url_decode(kv.substr(eq + 1));
    rest = amp == std::string_view::npos ? std::string_view{} : rest.substr(amp + 1);
  }
  return r;
}

// Tokens travel in the Authorization header only: a URL ends up in logs and browser history
// (the stream takes a ticket instead, StreamTickets).
std::string token_of(const HttpRequest& req) {
  const auto auth = req[http::field::authorization];
  if (sv(auth).starts_with("Bearer ")) return std::string(sv(auth).substr(7));
  return "";
}

HttpResponse respond(const HttpRequest& req, http::status status, std::string body,
                     std::string_view type = "application/json") {
  HttpResponse res{status, req.version()};
  res.set(http::field::server, "opencnc");
  res.set(http::field::content_type, beast::string_view(type.data(), type.size()));
  res.set(http::field::cache_control, "no-store");
  res.keep_alive(req.keep_alive());
  res.body() = std::move(body);
  res.prepare_payload();
  return res;
}

HttpResponse json_response(const HttpRequest& req, int status, const json& j) {
  return respond(req, static_cast<http::status>(status), j.dump());
}

HttpResponse error_response(const HttpRequest& req, int status, std::string message) {
  HttpResponse res = json_response(req, status, {{"error", std::move(message)}});
  if (status == 401) res.set(http::field::www_authenticate, "Bearer");
  return res;
}

int query_int(const Target& t, const char* name, int fallback, int lo, int hi) {
  const auto it = t.query.find(name);
  if (it == t.query.end()) return fallback;
  try {
    return std::clamp(std::stoi(it->second), lo, hi);
  } catch (const std::exception&) {
    return fallback;
  }
}

}  // namespace

class HttpSession;
class WsSession;

struct Server::Impl : std::enable_shared_from_this<Server::Impl> {
  Impl(controller::Controller& c, const config::MachineProfile& p, Tokens t, History* h,
       const controller::GcodeProgramSource* s, ServerConfig cfg)
      : controller(c),
        profile(std::make_shared<const config::MachineProfile>(p)),
        tokens(std::move(t)),
        history(h),
        source(s),
        config(std::move(cfg)),
        ioc_owner(std::make_unique<net::io_context>()),
        ioc(*ioc_owner) {
    acceptor.emplace(net::make_strand(ioc));
    stream_timer.emplace(ioc);
  }

  controller::Controller& controller;
  /// The profile in force (replaced after an accepted set-parameters): any io thread.
  std::shared_ptr<const config::MachineProfile> machine() const {
    std::lock_guard lock(profile_mutex);
    return profile;
  }
  mutable std::mutex profile_mutex;
  std::shared_ptr<const config::MachineProfile> profile;
  Tokens tokens;
  StreamTickets tickets;
  History* history;
  const controller::GcodeProgramSource* source;
  ServerConfig config;

  /// Destroyed by Server::stop() after its threads ended: that destroys the handlers still
  /// queued, and with them the sessions they hold (they hold this Impl too, so it cannot own it).
  std::unique_ptr<net::io_context> ioc_owner;
  net::io_context& ioc;
  std::optional<tcp::acceptor> acceptor;              ///< reset before the io_context goes
  std::optional<net::steady_timer> stream_timer;      ///< reset before the io_context goes
  std::chrono::steady_clock::time_point next_tick{};  ///< of the stream (the io thread)
  net::thread_pool workers{1};                        ///< previews: the interpreter may take a while
  /// Work that may wait for a disk, the database or the simulated machine (files, the history, a
  /// tool-table write, a simulation event): never on an io thread, which stays free for the stops
  /// (docs/controller.md, "Stops never wait").
  net::thread_pool blocking{2};
  /// `make_response()` on the blocking pool, its answer sent on the session's executor.
  template <class Session, class F>
  void off_io(const std::shared_ptr<Session>& s, F make_response) {
    net::post(blocking, [s, make_response = std::move(make_response)]() mutable {
      auto res = std::make_shared<HttpResponse>(make_response());
      net::post(s->executor(), [s, res] { s->send(std::move(*res)); });
    });
  }
  std::vector<std::thread> threads;
  bool loopback = true;
  std::uint16_t port = 0;
  std::atomic<bool> stopping{false};

  std::mutex sessions_mutex;
  std::vector<std::weak_ptr<WsSession>> sessions;
  std::atomic<std::uint64_t> dropped{0}, stream_ticks{0}, status_messages{0}, http_requests{0};
  std::atomic<std::uint64_t> mtc_streams{0}, mtc_dropped{0}, mtc_parts{0};

  std::mutex preview_mutex;
  std::string preview_key;
  std::shared_ptr<const std::string> preview_body;

  void accept();
  void stream_tick();
  /// The status with the features' state (`features`), as GET /status and the stream send it.
  json status_object() const {
    json j = status_json(controller.status(), *machine());
    if (config.features != nullptr) j["features"] = config.features->status();
    return j;
  }
  void handle(const std::shared_ptr<HttpSession>& s, HttpRequest req);
  void upgrade(tcp::socket socket, HttpRequest req, std::string remote);
  void audit(const std::string& remote, std::optional<Role> role, const HttpRequest& req, int status,
             std::string result);

  // --- routes (docs/api.md) ---
  /// Who may call a route.
  enum class Access : std::uint8_t {
    Anyone,           ///< no token asked: the front end's files, the answer naming the API's version
    Token,            ///< a valid token, either role
    TokenOrLoopback,  ///< a token, or a GET to a server that listens on loopback only
    Admin,            ///< the admin's token (another role: 403, audited)
  };
  /// Where a route's answer is made.
  enum class Runs : std::uint8_t {
    Io,        ///< on the io thread: it reads memory only
    Blocking,  ///< on the blocking pool: it reads a file or the database
  };
  /// A route's answer, made at once (where `Runs` says): the role is the caller's (Operator for an
  /// unauthenticated loopback GET).
  using Answer = HttpResponse (Impl::*)(const HttpRequest&, const Target&, Role);
  /// A route that sends its answer itself, later (a command waits for the controller's answer).
  using Start = void (Impl::*)(const std::shared_ptr<HttpSession>&, const HttpRequest&, Role);
  /// One row of the route table: a request whose path matches is answered by this row alone.
  struct Route {
    std::uint8_t methods;   ///< bits of Method: what it answers; others get 405
    std::string_view path;  ///< the path, or its beginning when `prefix`
    bool prefix = false;
    Access access = Access::Token;
    Runs runs = Runs::Io;
    std::string_view wrong_method = "only GET here";  ///< the 405's words
    std::string_view admin_only = {};                 ///< Admin: what the 403 names ("the audit trail")
    Answer answer = nullptr;                          ///< or:
    Start start = nullptr;
  };
  enum Method : std::uint8_t { kGet = 1, kHead = 2, kPost = 4, kAnyMethod = 0xff };
  /// The route for `path`: the first row of the table that matches (the last one matches all).
  static const Route& route_for(std::string_view path) noexcept;

  void command(const std::shared_ptr<HttpSession>& s, const HttpRequest& req, Role role);
  void stream_ticket(const std::shared_ptr<HttpSession>& s, const HttpRequest& req, Role role);
  void preview(const std::shared_ptr<HttpSession>& s, const HttpRequest& req, Role role);
  void wait_outcome(const std::shared_ptr<HttpSession>& s, HttpRequest req, std::uint64_t id,
                    std::chrono::steady_clock::time_point deadline, bool profile_edit = false);
  HttpResponse tool_change(const HttpRequest& req, const ToolChange& c);
  HttpResponse status(const HttpRequest& req, const Target& t, Role role);
  HttpResponse machine_info(const HttpRequest& req, const Target& t, Role role);
  HttpResponse parameters(const HttpRequest& req, const Target& t, Role role);
  HttpResponse compensation(const HttpRequest& req, const Target& t, Role role);
  HttpResponse conditions(const HttpRequest& req, const Target& t, Role role);
  HttpResponse edm_sequence(const HttpRequest& req, const Target& t, Role role);
  HttpResponse program_info(const HttpRequest& req, const Target& t, Role role);
  HttpResponse program_text(const HttpRequest& req, const Target& t, Role role);
  HttpResponse programs(const HttpRequest& req, const Target& t, Role role);
  HttpResponse tools_table(const HttpRequest& req, const Target& t, Role role);
  HttpResponse cut_chart(const HttpRequest& req, const Target& t, Role role);
  HttpResponse events(const HttpRequest& req, const Target& t, Role role);
  HttpResponse command_outcome(const HttpRequest& req, const Target& t, Role role);
  HttpResponse history_jobs(const HttpRequest& req, const Target& t, Role role);
  HttpResponse audit_trail(const HttpRequest& req, const Target& t, Role role);
  HttpResponse server_info(const HttpRequest& req, const Target& t, Role role);
  HttpResponse no_such_call(const HttpRequest& req, const Target& t, Role role);
  HttpResponse other_version(const HttpRequest& req, const Target& t, Role role);
  HttpResponse static_file(const HttpRequest& req, const Target& t, Role role);
  HttpResponse mtconnect(const HttpRequest& req, const Target& t, Role role);
  void mtconnect_sample(const std::shared_ptr<HttpSession>& s, const HttpRequest& req, Role role);
  std::string relative_program(const std::string& path) const;
};

/// One HTTP connection: reads requests one after the other, answers each (some answers come
/// later: a command waits for the controller's answer on a timer, never blocking the thread).
class HttpSession : public std::enable_shared_from_this<HttpSession> {
 public:
  HttpSession(tcp::socket socket, std::shared_ptr<Server::Impl> server)
      : stream_(std::move(socket)), server_(std::move(server)) {
    beast::error_code ec;
    const auto ep = stream_.socket().remote_endpoint(ec);
    remote_ = ec ? "?" : fmt::format("{}:{}", ep.address().to_string(), ep.port());
  }
  void run() {
    net::dispatch(stream_.get_executor(), [self = shared_from_this()] { self->read(); });
  }
  /// Sends `res`, then reads the next request (or closes). The session's executor.
  void send(HttpResponse res) {
    auto sp = std::make_shared<HttpResponse>(std::move(res));
    http::async_write(stream_, *sp, [self = shared_from_this(), sp](beast::error_code ec, std::size_t) {
      if (ec) return;
      if (sp->need_eof()) {
        self->stream_.socket().shutdown(tcp::socket::shutdown_send, ec);
        return;
      }
      self->read();
    });
  }
  net::any_io_executor executor() { return stream_.get_executor(); }
  const std::string& remote() const { return remote_; }
  /// The connection, for an answer that streams (the session ends here).
  tcp::socket take_socket() { return stream_.release_socket(); }

 private:
  void read() {
    parser_.emplace();
    parser_->body_limit(kBodyLimit);
    stream_.expires_after(std::chrono::seconds(60));
    http::async_read(stream_, buffer_, *parser_,
                     [self = shared_from_this()](beast::error_code ec, std::size_t) { self->on_read(ec); });
  }
  void on_read(beast::error_code ec) {
    if (ec == http::error::body_limit) {
      HttpRequest req;
      req.version(11);
      req.keep_alive(false);
      return send(error_response(req, 413, "the body is larger than 1 MiB"));
    }
    if (ec) return;  // closed, timed out, or garbage: nothing to answer
    stream_.expires_never();
    HttpRequest req = parser_->release();
    if (websocket::is_upgrade(req)) {
      return server_->upgrade(stream_.release_socket(), std::move(req), remote_);
    }
    server_->handle(shared_from_this(), std::move(req));
  }

  beast::tcp_stream stream_;
  beast::flat_buffer buffer_;
  std::optional<http::request_parser<http::string_body>> parser_;
  std::shared_ptr<Server::Impl> server_;
  std::string remote_;
};

/// One MTConnect /sample?interval= stream (docs/connectivity.md): a multipart/x-mixed-replace
/// answer, chunked, a document at most every `interval` with what is new, an empty one after
/// `heartbeat` without news. One write at a time: a reader that takes longer than the server's
/// write timeout over one part is dropped, and nobody else waits for it.
class MtcStream : public std::enable_shared_from_this<MtcStream> {
 public:
  MtcStream(tcp::socket socket, std::shared_ptr<Server::Impl> server, connect::AgentRequest request,
            std::chrono::milliseconds interval, std::chrono::milliseconds heartbeat)
      : stream_(std::move(socket)),
        timer_(stream_.get_executor()),
        server_(std::move(server)),
        request_(std::move(request)),
        interval_(interval),
        heartbeat_(heartbeat) {}

  /// Sends the header, then the first document at once.
  void run(std::uint64_t from, unsigned http_version) {
    from_ = from;
    ++server_->mtc_streams;
    tick_due_ = true;
    write(
        std::make_shared<std::string>(fmt::format(
            "HTTP/{}.{} 200 OK\r\nServer: opencnc\r\nContent-Type: multipart/x-mixed-replace;boundary={}\r\n"
            "Transfer-Encoding: chunked\r\nCache-Control: no-cache, private\r\nConnection: close\r\n\r\n",
            http_version / 10, http_version % 10, kBoundary)),
        false);
  }

 private:
  static constexpr std::string_view kBoundary = "opencnc-mtconnect-part";

  void write(std::shared_ptr<std::string> bytes, bool last) {
    writing_ = true;
    stream_.expires_after(std::chrono::milliseconds(
        static_cast<std::int64_t>(server_->config.mtconnect_write_timeout_s * 1000.0)));
    net::async_write(stream_, net::buffer(*bytes),
                     [self = shared_from_this(), bytes, last](beast::error_code ec, std::size_t) {
                       self->writing_ = false;
                       if (ec) return self->end(ec == beast::error::timeout);
                       self->last_sent_ = std::chrono::steady_clock::now();
                       if (last) return self->end(false);
                       if (self->tick_due_) {
                         self->tick_due_ = false;
                         self->tick();
                       }
                     });
  }
  /// One part as a chunk of the chunked body.
  static std::shared_ptr<std::string> part(const std::string& document) {
    const std::string body = fmt::format("--{}\r\nContent-type: text/xml\r\nContent-length: {}\r\n\r\n{}\r\n",
                                         kBoundary, document.size(), document);
    return std::make_shared<std::string>(fmt::format("{:x}\r\n{}\r\n", body.size(), body));
  }
  /// What is new since the last part (or a heartbeat), then the next look after `interval`.
  void tick() {
    if (ended_) return;
    if (server_->stopping) return end(false);
    connect::AgentRequest r = request_;
    r.query["from"] = std::to_string(from_);
    const connect::SampleAnswer a = server_->config.mtconnect->sample(r, connect::StatusSampler::wall_us());
    if (a.response.status != 200) {  // the reader fell behind the buffer: the error is the last part
      ++server_->mtc_parts;
      auto last = part(a.response.body);
      last->append("0\r\n\r\n");
      return write(last, true);
    }
    if (!a.empty || std::chrono::steady_clock::now() - last_sent_ >= heartbeat_) {
      from_ = a.next_from;
      ++server_->mtc_parts;
      write(part(a.response.body), false);
    }
    timer_.expires_after(interval_);
    timer_.async_wait([self = shared_from_this()](beast::error_code ec) {
      if (ec || self->ended_) return;
      if (self->writing_)
        self->tick_due_ = true;  // after the part being written
      else
        self->tick();
    });
  }
  void end(bool stalled) {
    if (ended_) return;
    ended_ = true;
    if (stalled) ++server_->mtc_dropped;
    --server_->mtc_streams;
    beast::error_code ec;
    stream_.socket().close(ec);
    timer_.cancel();
  }

  beast::tcp_stream stream_;
  net::steady_timer timer_;
  std::shared_ptr<Server::Impl> server_;
  connect::AgentRequest request_;
  std::chrono::milliseconds interval_, heartbeat_;
  std::uint64_t from_ = 0;
  std::chrono::steady_clock::time_point last_sent_{};
  bool ended_ = false, writing_ = false, tick_due_ = false;
};

/// One WebSocket client of the stream: status at the server's rate and the event log from its
/// own cursor. Messages wait in a queue of its own; a client that lets it fill is dropped.
class WsSession : public std::enable_shared_from_this<WsSession> {
 public:
  WsSession(tcp::socket socket, std::shared_ptr<Server::Impl> server)
      : ws_(std::move(socket)), server_(std::move(server)), cursor_(server_->controller.events()) {}

  void run(HttpRequest req) {
    beast::error_code ec;
    beast::get_lowest_layer(ws_).socket().set_option(net::socket_base::send_buffer_size(kSendBufferBytes),
                                                     ec);
    ws_.set_option(websocket::stream_base::timeout::suggested(beast::role_type::server));
    ws_.async_accept(req, [self = shared_from_this()](beast::error_code e) {
      if (e) return;
      {
        std::lock_guard lock(self->server_->sessions_mutex);
        self->server_->sessions.push_back(self);
      }
      self->read();
    });
  }
  /// Queues the status (and this client's new events). The session's executor.
  void deliver(const std::shared_ptr<const std::string>& status) {
    if (closed_) return;
    queue_.push_back(status);
    ++server_->status_messages;
    std::vector<controller::ControllerEvent> events = cursor_.next(kEventsPerMessage);
    if (!events.empty() || cursor_.lost() != reported_lost_) {
      json list = json::array();
      for (const auto& e : events) list.push_back(event_json(e));
      reported_lost_ = cursor_.lost();
      queue_.push_back(std::make_shared<const std::string>(
          json{{"type", "events"}, {"events", list}, {"lost", cursor_.lost()}}.dump()));
    }
    if (queue_.size() > server_->config.max_queued) return drop();
    if (!writing_) write();
  }
  void close() {
    beast::error_code ec;
    closed_ = true;
    beast::get_lowest_layer(ws_).socket().close(ec);
  }
  bool closed() const { return closed_; }
  net::any_io_executor executor() { return ws_.get_executor(); }

 private:
  void drop() {
    ++server_->dropped;
    queue_.clear();
    close();
  }
  void write() {
    writing_ = true;
    ws_.text(true);
    ws_.async_write(net::buffer(*queue_.front()),
                    [self = shared_from_this()](beast::error_code ec, std::size_t) {
                      self->writing_ = false;
                      if (ec) {
                        self->closed_ = true;
                        return;
                      }
                      if (!self->queue_.empty()) self->queue_.pop_front();
                      if (!self->queue_.empty() && !self->closed_) self->write();
                    });
  }
  /// Reads (and ignores) what the client sends, to see it close.
  void read() {
    ws_.async_read(in_, [self = shared_from_this()](beast::error_code ec, std::size_t) {
      if (ec) {
        self->closed_ = true;
        return;
      }
      self->in_.consume(self->in_.size());
      self->read();
    });
  }

  websocket::stream<beast::tcp_stream> ws_;
  std::shared_ptr<Server::Impl> server_;
  controller::EventCursor cursor_;
  std::uint64_t reported_lost_ = 0;
  std::deque<std::shared_ptr<const std::string>> queue_;
  beast::flat_buffer in_;
  bool writing_ = false;
  std::atomic<bool> closed_{false};  ///< read by the stream tick and stats() on other threads
};

// --- the server -----------------------------------------------------------------------------

void Server::Impl::accept() {
  acceptor->async_accept(net::make_strand(ioc),
                         [self = shared_from_this()](beast::error_code ec, tcp::socket socket) {
                           if (self->stopping) return;
                           if (!ec) std::make_shared<HttpSession>(std::move(socket), self)->run();
                           self->accept();
                         });
}

// Every 1/stream_hz: the status once as JSON, handed to each client on its own executor.
void Server::Impl::stream_tick() {
  if (stopping) return;
  ++stream_ticks;
  auto status =
      std::make_shared<const std::string>(json{{"type", "status"}, {"status", status_object()}}.dump());
  {
    std::lock_guard lock(sessions_mutex);
    std::erase_if(sessions, [](const std::weak_ptr<WsSession>& w) {
      const auto s = w.lock();
      return !s || s->closed();
    });
    for (const auto& w : sessions) {
      if (auto s = w.lock()) net::post(s->executor(), [s, status] { s->deliver(status); });
    }
  }
  // A fixed schedule (not "a period after this one's work"), so the rate holds; a tick that
  // came too late is not made up with a burst.
  const auto period = std::chrono::duration_cast<std::chrono::steady_clock::duration>(
      std::chrono::duration<double>(1.0 / config.stream_hz));
  const auto now = std::chrono::steady_clock::now();
  next_tick = next_tick.time_since_epoch().count() == 0 || next_tick + period < now ? now + period
                                                                                    : next_tick + period;
  stream_timer->expires_at(next_tick);
  stream_timer->async_wait([self = shared_from_this()](beast::error_code ec) {
    if (!ec) self->stream_tick();
  });
}

void Server::Impl::upgrade(tcp::socket socket, HttpRequest req, std::string remote) {
  const Target t = parse_target(sv(req.target()));
  std::optional<Role> role = tokens.role_of(token_of(req));
  if (const auto it = t.query.find("ticket"); !role && it != t.query.end()) {
    role = tickets.redeem(it->second, StreamTickets::Clock::now());
  }
  if (t.path != "/api/v1/stream" || !role) {
    const int status = t.path != "/api/v1/stream" ? 404 : 401;
    if (status == 401) audit(remote, role, req, 401, "no valid token");
    auto s = std::make_shared<HttpSession>(std::move(socket), shared_from_this());
    HttpResponse res =
        error_response(req, status, status == 404 ? "no such stream" : "a valid token or stream ticket is needed");
    res.keep_alive(false);
    return s->send(std::move(res));
  }
  std::make_shared<WsSession>(std::move(socket), shared_from_this())->run(std::move(req));
}

void Server::Impl::audit(const std::string& remote, std::optional<Role> role, const HttpRequest& req,
                         int status, std::string result) {
  if (!history) return;
  history->add(
      AuditRecord{0, utc_now(), role ? to_string(*role) : "", remote,
                  fmt::format("{} {}", std::string(req.method_string()), parse_target(sv(req.target())).path),
                  req.body(), status, std::move(result)});
}

// The route table: what each path answers, who may call it, where its answer is made. The first
// row that matches a request's path is its route; the WebSocket stream is upgraded before this
// (upgrade()).
const Server::Impl::Route& Server::Impl::route_for(std::string_view path) noexcept {
  using I = Impl;
  static constexpr Route kRoutes[] = {
      {.methods = kGet, .path = "/api/v1/status", .access = Access::TokenOrLoopback, .answer = &I::status},
      {.methods = kGet, .path = "/api/v1/machine", .answer = &I::machine_info},
      {.methods = kGet, .path = "/api/v1/parameters", .answer = &I::parameters},
      {.methods = kGet, .path = "/api/v1/compensation", .answer = &I::compensation},
      {.methods = kGet, .path = "/api/v1/conditions", .answer = &I::conditions},
      {.methods = kGet, .path = "/api/v1/edm-sequence", .answer = &I::edm_sequence},
      {.methods = kGet, .path = "/api/v1/program", .answer = &I::program_info},
      {.methods = kGet, .path = "/api/v1/program/text", .runs = Runs::Blocking, .answer = &I::program_text},
      {.methods = kGet, .path = "/api/v1/program/preview", .start = &I::preview},
      {.methods = kGet, .path = "/api/v1/programs", .runs = Runs::Blocking, .answer = &I::programs},
      {.methods = kGet, .path = "/api/v1/tools", .answer = &I::tools_table},
      {.methods = kGet | kPost,
       .path = "/api/v1/cutchart",
       .runs = Runs::Blocking,
       .wrong_method = "GET the cut chart, POST a change",
       .answer = &I::cut_chart},
      {.methods = kGet, .path = "/api/v1/events", .answer = &I::events},
      {.methods = kPost,
       .path = "/api/v1/commands",
       .wrong_method = "commands are POSTed",
       .start = &I::command},
      {.methods = kGet, .path = "/api/v1/commands/", .prefix = true, .answer = &I::command_outcome},
      {.methods = kPost,
       .path = "/api/v1/stream-ticket",
       .wrong_method = "stream tickets are POSTed",
       .start = &I::stream_ticket},
      {.methods = kGet, .path = "/api/v1/history", .runs = Runs::Blocking, .answer = &I::history_jobs},
      {.methods = kGet,
       .path = "/api/v1/audit",
       .access = Access::Admin,
       .runs = Runs::Blocking,
       .admin_only = "the audit trail",
       .answer = &I::audit_trail},
      {.methods = kGet, .path = "/api/v1/server", .answer = &I::server_info},
      // Any other call of this version: a token first, then GET, then "no such call".
      {.methods = kGet, .path = "/api/v1/", .prefix = true, .answer = &I::no_such_call},
      {.methods = kAnyMethod,
       .path = "/api/",
       .prefix = true,
       .access = Access::Anyone,
       .answer = &I::other_version},
      // MTConnect (docs/connectivity.md): read-only, open on loopback like the status.
      {.methods = kGet,
       .path = "/probe",
       .access = Access::TokenOrLoopback,
       .runs = Runs::Blocking,
       .answer = &I::mtconnect},
      {.methods = kGet,
       .path = "/current",
       .access = Access::TokenOrLoopback,
       .runs = Runs::Blocking,
       .answer = &I::mtconnect},
      {.methods = kGet, .path = "/sample", .access = Access::TokenOrLoopback, .start = &I::mtconnect_sample},
      {.methods = kGet,
       .path = "/assets",
       .access = Access::TokenOrLoopback,
       .runs = Runs::Blocking,
       .answer = &I::mtconnect},
      {.methods = kGet,
       .path = "/mtconnect/",
       .prefix = true,
       .access = Access::TokenOrLoopback,
       .start = &I::mtconnect_sample},
      // Everything else is the front end's files.
      {.methods = kGet | kHead,
       .path = "/",
       .prefix = true,
       .access = Access::Anyone,
       .runs = Runs::Blocking,
       .answer = &I::static_file},
  };
  for (const Route& r : kRoutes) {
    if (r.prefix ? path.starts_with(r.path) : path == r.path) return r;
  }
  return kRoutes[std::size(kRoutes) - 1];  // a path that does not start with '/': a file not found
}

void Server::Impl::handle(const std::shared_ptr<HttpSession>& s, HttpRequest req) {
  ++http_requests;
  const Target t = parse_target(sv(req.target()));
  const Route& r = route_for(t.path);
  std::optional<Role> role;
  if (r.access != Access::Anyone) {
    role = tokens.role_of(token_of(req));
    const bool open = r.access == Access::TokenOrLoopback && req.method() == http::verb::get && loopback;
    if (!role && !open) {
      audit(s->remote(), role, req, 401, token_of(req).empty() ? "no token" : "no valid token");
      return s->send(error_response(req, 401, "a valid token is needed (Authorization: Bearer TOKEN)"));
    }
  }
  const std::uint8_t method = req.method() == http::verb::get    ? kGet
                              : req.method() == http::verb::head ? kHead
                              : req.method() == http::verb::post ? kPost
                                                                 : 0x80;  // only kAnyMethod has it
  if ((r.methods & method) == 0) return s->send(error_response(req, 405, std::string(r.wrong_method)));
  if (r.access == Access::Admin && role != Role::Admin) {
    audit(s->remote(), role, req, 403, "needs the admin role");
    return s->send(error_response(req, 403, fmt::format("{} is for the admin", r.admin_only)));
  }
  const Role as = role.value_or(Role::Operator);
  if (r.start != nullptr) return (this->*r.start)(s, req, as);
  auto answer = [self = shared_from_this(), req, t, as, a = r.answer] { return ((*self).*a)(req, t, as); };
  if (r.runs == Runs::Blocking) return off_io(s, std::move(answer));
  s->send(answer());
}

void Server::Impl::stream_ticket(const std::shared_ptr<HttpSession>& s, const HttpRequest& req, Role role) {
  std::string error;
  const auto ticket = tickets.issue(role, StreamTickets::Clock::now(), &error);
  if (!ticket) return s->send(error_response(req, 503, error));
  s->send(json_response(req, 200, {{"ticket", *ticket}, {"expires_in_s", StreamTickets::kLifetime.count()}}));
}

HttpResponse Server::Impl::status(const HttpRequest& req, const Target&, Role) {
  return json_response(req, 200, status_object());
}

HttpResponse Server::Impl::machine_info(const HttpRequest& req, const Target&, Role) {
  return json_response(req, 200, machine_json(*machine()));
}

HttpResponse Server::Impl::parameters(const HttpRequest& req, const Target&, Role) {
  return json_response(req, 200, parameters_json(*machine()));
}

HttpResponse Server::Impl::compensation(const HttpRequest& req, const Target&, Role) {
  return json_response(req, 200, compensation_json(*machine()));
}

HttpResponse Server::Impl::conditions(const HttpRequest& req, const Target&, Role) {
  return json_response(req, 200, conditions_json(*machine()));
}

HttpResponse Server::Impl::edm_sequence(const HttpRequest& req, const Target& t, Role) {
  const auto [status, body] = edm_sequence_json(*machine(), t.query);
  return json_response(req, status, body);
}

HttpResponse Server::Impl::events(const HttpRequest& req, const Target& t, Role) {
  const auto after = static_cast<std::uint64_t>(query_int(t, "after", 0, 0, INT32_MAX));
  const auto max = static_cast<std::size_t>(query_int(t, "max", 1000, 1, 4096));
  std::uint64_t lost = 0;
  json list = json::array();
  for (const auto& e : controller.events().read_after(after, max, &lost)) list.push_back(event_json(e));
  return json_response(req, 200, {{"events", list}, {"lost", lost}, {"last", controller.events().last()}});
}

HttpResponse Server::Impl::command_outcome(const HttpRequest& req, const Target& t, Role) {
  std::uint64_t id = 0;
  try {
    id = std::stoull(t.path.substr(std::string_view("/api/v1/commands/").size()));
  } catch (const std::exception&) {
    return error_response(req, 400, "a command id is a number");
  }
  if (const auto o = controller.outcome(id)) return json_response(req, 200, outcome_json(id, *o));
  return error_response(req, 404, fmt::format("no answer to command {} (yet)", id));
}

HttpResponse Server::Impl::history_jobs(const HttpRequest& req, const Target& t, Role) {
  if (!history) return json_response(req, 200, json::array());
  json list = json::array();
  for (const JobRecord& r : history->jobs(query_int(t, "limit", 50, 1, 1000))) {
    list.push_back({{"id", r.id},
                    {"job_id", r.job_id},
                    {"kind", r.kind},
                    {"program", r.program},
                    {"started", r.started_utc},
                    {"ended", r.ended_utc},
                    {"outcome", r.outcome},
                    {"machining_s", r.machining_s},
                    {"end_line", r.end_line},
                    {"alarms", r.alarms}});
  }
  return json_response(req, 200, list);
}

HttpResponse Server::Impl::audit_trail(const HttpRequest& req, const Target& t, Role) {
  json list = json::array();
  if (history) {
    for (const AuditRecord& r : history->audit(query_int(t, "limit", 100, 1, 1000))) {
      list.push_back({{"id", r.id},
                      {"time", r.time_utc},
                      {"role", r.role},
                      {"remote", r.remote},
                      {"action", r.action},
                      {"body", r.body},
                      {"status", r.status},
                      {"result", r.result}});
    }
  }
  return json_response(req, 200, list);
}

HttpResponse Server::Impl::server_info(const HttpRequest& req, const Target&, Role role) {
  std::size_t clients = 0;
  {
    std::lock_guard lock(sessions_mutex);
    clients = sessions.size();
  }
  return json_response(req, 200,
                       {{"address", config.address},
                        {"port", port},
                        {"loopback_only", loopback},
                        {"stream_hz", config.stream_hz},
                        {"clients", clients},
                        {"dropped", dropped.load()},
                        {"tokens", tokens.origin()},
                        {"role", to_string(role)},
                        {"programs", config.programs_dir.string()}});
}

HttpResponse Server::Impl::no_such_call(const HttpRequest& req, const Target& t, Role) {
  return error_response(req, 404, fmt::format("no such call: GET {}", t.path));
}

HttpResponse Server::Impl::other_version(const HttpRequest& req, const Target&, Role) {
  return error_response(req, 404, "this server speaks /api/v1/");
}

void Server::Impl::command(const std::shared_ptr<HttpSession>& s, const HttpRequest& req, Role role) {
  json body;
  try {
    body = json::parse(req.body());
  } catch (const json::exception& e) {  // malformed, or a number no double holds (1e400)
    audit(s->remote(), role, req, 400, "malformed JSON");
    return s->send(
        error_response(req, 400, fmt::format("the body is not JSON opencnc can read: {}", e.what())));
  }
  const std::optional<Role> needed = body.is_object() && body.contains("kind") && body["kind"].is_string()
                                         ? role_for(body["kind"].get<std::string>())
                                         : std::nullopt;
  if (needed == Role::Admin && role != Role::Admin) {
    audit(s->remote(), role, req, 403, "needs the admin role");
    return s->send(error_response(req, 403, "this command needs the admin token"));
  }
  auto parsed = parse_command(body, *machine(), config.programs_dir);
  if (const auto* e = std::get_if<ApiError>(&parsed)) {
    audit(s->remote(), role, req, e->status, e->message);
    return s->send(error_response(req, e->status, e->message));
  }
  auto& c = std::get<Command>(parsed);
  if (const auto* e = std::get_if<SimulationEvent>(&c)) {  // waits for the machine to take it
    return off_io(s, [self = shared_from_this(), s, req, role, e = *e] {
      const std::string why =
          self->config.simulate ? self->config.simulate(e) : "this server has no simulation controls";
      HttpResponse res = why.empty() ? json_response(req, 200, {{"accepted", true}, {"event", e.event}})
                                     : error_response(req, 409, why);
      self->audit(s->remote(), role, req, static_cast<int>(res.result_int()), why.empty() ? "accepted" : why);
      return res;
    });
  }
  if (const auto* t = std::get_if<ToolChange>(&c)) {  // writes the tool table (a file, the database)
    return off_io(s, [self = shared_from_this(), s, req, role, t = *t] {
      HttpResponse res = self->tool_change(req, t);
      self->audit(s->remote(), role, req, static_cast<int>(res.result_int()), res.body());
      return res;
    });
  }
  auto& request = std::get<controller::Request>(c);
  auto* edit = std::get_if<controller::requests::EditProfile>(&request.body);
  if (edit) edit->who = fmt::format("{}@{}", to_string(role), s->remote());
  const std::uint64_t id = controller.submit(std::move(request));
  const auto deadline =
      std::chrono::steady_clock::now() + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                             std::chrono::duration<double>(config.command_timeout_s));
  wait_outcome(s, req, id, deadline, edit != nullptr);
}

// Polls the controller for the answer every 2 ms on a timer of the session's executor: the
// thread serves the other clients meanwhile.
void Server::Impl::wait_outcome(const std::shared_ptr<HttpSession>& s, HttpRequest req, std::uint64_t id,
                                std::chrono::steady_clock::time_point deadline, bool profile_edit) {
  const std::optional<Role> role = tokens.role_of(token_of(req));
  if (const auto o = controller.outcome(id)) {
    const int status = o->accepted ? 200 : 409;
    if (profile_edit && o->accepted) {  // the new limits for the checks of later commands
      auto next = std::make_shared<const config::MachineProfile>(controller.current_profile());
      std::lock_guard lock(profile_mutex);
      profile = std::move(next);
    }
    audit(s->remote(), role, req, status,
          o->accepted ? (profile_edit ? "accepted: " + o->message : "accepted")
                      : fmt::format("{}: {}", control::refusal_code(o->refusal), o->message));
    return s->send(json_response(req, status, outcome_json(id, *o)));
  }
  if (std::chrono::steady_clock::now() >= deadline || stopping) {
    audit(s->remote(), role, req, 202, fmt::format("queued as {}, no answer yet", id));
    return s->send(json_response(req, 202, {{"id", id}, {"pending", true}}));
  }
  auto timer = std::make_shared<net::steady_timer>(s->executor(), std::chrono::milliseconds(2));
  timer->async_wait([self = shared_from_this(), s, timer, req = std::move(req), id, deadline,
                     profile_edit](beast::error_code) mutable {
    self->wait_outcome(s, std::move(req), id, deadline, profile_edit);
  });
}

HttpResponse Server::Impl::tool_change(const HttpRequest& req, const ToolChange& c) {
  const auto service = source ? source->tools() : nullptr;
  if (!service) return error_response(req, 409, "this machine has no tool table");
  const auto table = service->snapshot();
  const auto slot = table->find(c.tool);
  if (!slot) return error_response(req, 404, fmt::format("no tool T{} in the table", c.tool));
  tools::ToolEntry e = table->at_index(*slot);
  if (c.diameter_mm) e.diameter = *c.diameter_mm;
  if (c.z_offset_mm) e.offset[index(Axis::Z)] = *c.z_offset_mm;
  if (!c.comment.empty()) e.comment = c.comment;
  Diagnostics diags;
  if (!service->update(*slot, e, tools::ChangeSource::Operator, diags)) {
    std::string why;
    for (const Diagnostic& d : diags.items()) why += (why.empty() ? "" : "; ") + d.format();
    return error_response(req, 409, why.empty() ? "the tool table refused the change" : why);
  }
  return json_response(req, 200,
                       {{"accepted", true},
                        {"tool", c.tool},
                        {"diameter", e.diameter},
                        {"z_offset", e.offset[index(Axis::Z)]}});
}

std::string Server::Impl::relative_program(const std::string& path) const {
  std::error_code ec;
  const auto rel =
      std::filesystem::relative(path, std::filesystem::weakly_canonical(config.programs_dir, ec), ec);
  return ec || rel.empty() || rel.string().starts_with("..") ? std::filesystem::path(path).filename().string()
                                                             : rel.string();
}

HttpResponse Server::Impl::program_info(const HttpRequest& req, const Target&, Role) {
  const auto open = controller.open_program();
  if (!open) return json_response(req, 200, {{"open", false}});
  const controller::PreflightSummary& s = open->preflight.summary;
  json warnings = json::array();
  for (const Diagnostic& d : open->preflight.diagnostics.items()) warnings.push_back(d.format());
  return json_response(req, 200,
                       {{"open", true},
                        {"name", open->name},
                        {"program", relative_program(open->path)},
                        {"moves", s.moves},
                        {"length_mm", s.path_length_mm},
                        {"warnings", warnings},
                        {"min", {s.min[0], s.min[1], s.min[2]}},
                        {"max", {s.max[0], s.max[1], s.max[2]}}});
}

HttpResponse Server::Impl::program_text(const HttpRequest& req, const Target& t, Role) {
  const auto open = controller.open_program();
  if (!open || open->path.empty()) return error_response(req, 404, "no program file is open");
  const int from = query_int(t, "from", 1, 1, INT32_MAX);
  const int count = query_int(t, "count", 500, 1, 5000);
  std::ifstream in(open->path);
  if (!in) return error_response(req, 404, "the open program cannot be read");
  json lines = json::array();
  std::string line;
  int n = 0;
  while (std::getline(in, line) && n < from + count - 1) {
    if (++n >= from) lines.push_back(line.size() > 400 ? line.substr(0, 400) : line);
  }
  // Whether the file goes on after the window (the listing pages on when the run gets there).
  const bool more = n == from + count - 1 && static_cast<bool>(std::getline(in, line));
  return json_response(req, 200, {{"from", from}, {"lines", lines}, {"more", more}});
}

void Server::Impl::preview(const std::shared_ptr<HttpSession>& s, const HttpRequest& req, Role) {
  const auto open = controller.open_program();
  if (!open || open->path.empty() || !source)
    return s->send(error_response(req, 404, "no program file is open"));
  std::error_code ec;
  const std::string key =
      fmt::format("{}|{}|{}", open->path, std::filesystem::file_size(open->path, ec),
                  std::filesystem::last_write_time(open->path, ec).time_since_epoch().count());
  {
    std::lock_guard lock(preview_mutex);
    if (key == preview_key && preview_body) return s->send(respond(req, http::status::ok, *preview_body));
  }
  const Pose start = controller.status().servo.commanded;
  net::post(workers, [self = shared_from_this(), s, req, key, path = open->path, start] {
    auto body = std::make_shared<const std::string>(program_preview(*self->source, path, start).dump());
    {
      std::lock_guard lock(self->preview_mutex);
      self->preview_key = key;
      self->preview_body = body;
    }
    net::post(s->executor(), [s, req, body] { s->send(respond(req, http::status::ok, *body)); });
  });
}

HttpResponse Server::Impl::programs(const HttpRequest& req, const Target&, Role) {
  json list = json::array();
  std::error_code ec;
  std::vector<std::string> names;
  for (const auto& e : std::filesystem::directory_iterator(config.programs_dir, ec)) {
    const std::string ext = e.path().extension().string();
    if (e.is_regular_file(ec) && (ext == ".ngc" || ext == ".nc" || ext == ".tap" || ext == ".gcode")) {
      names.push_back(e.path().filename().string());
    }
  }
  std::sort(names.begin(), names.end());
  for (const std::string& n : names) {
    list.push_back({{"name", n}, {"bytes", std::filesystem::file_size(config.programs_dir / n, ec)}});
  }
  return json_response(req, 200, list);
}

HttpResponse Server::Impl::tools_table(const HttpRequest& req, const Target&, Role) {
  json list = json::array();
  if (const auto service = source ? source->tools() : nullptr) {
    for (const tools::ToolEntry& e : service->snapshot()->entries()) {
      list.push_back({{"tool", e.tool},
                      {"pocket", e.pocket},
                      {"diameter", e.diameter},
                      {"z_offset", e.offset[index(Axis::Z)]},
                      {"comment", e.comment}});
    }
  }
  return json_response(req, 200, list);
}

// A plasma table's cut chart: its store read or changed on the blocking pool (api_cutchart.hpp).
HttpResponse Server::Impl::cut_chart(const HttpRequest& req, const Target&, Role role) {
  CutChartAnswer a;
  if (req.method() == http::verb::post) {
    const json body = json::parse(req.body(), nullptr, false);
    if (body.is_discarded()) return error_response(req, 400, "the body is not JSON");
    a = cut_chart_post(*machine(), body, role);
  } else {
    a = cut_chart_get(*machine());
  }
  return json_response(req, a.status, a.body);
}

// --- MTConnect (docs/connectivity.md) -------------------------------------------------------

namespace {

/// The agent's request for `target`: the path below /mtconnect when it is there.
connect::AgentRequest mtconnect_request(std::string_view target) {
  connect::AgentRequest r = connect::parse_agent_request(target);
  constexpr std::string_view base = "/mtconnect";
  if (r.path.starts_with(base)) r.path.erase(0, base.size());
  return r;
}

HttpResponse agent_response(const HttpRequest& req, const connect::AgentResponse& a) {
  HttpResponse res{static_cast<http::status>(a.status), req.version()};
  res.set(http::field::content_type, a.content_type);
  res.set(http::field::cache_control, "no-cache, private");
  res.keep_alive(req.keep_alive());
  res.body() = a.body;
  res.prepare_payload();
  return res;
}

}  // namespace

HttpResponse Server::Impl::mtconnect(const HttpRequest& req, const Target&, Role) {
  if (config.mtconnect == nullptr) return error_response(req, 404, "this server has no MTConnect agent");
  return agent_response(
      req, config.mtconnect->respond(mtconnect_request(sv(req.target())), connect::StatusSampler::wall_us()));
}

void Server::Impl::mtconnect_sample(const std::shared_ptr<HttpSession>& s, const HttpRequest& req,
                                    Role role) {
  const connect::AgentRequest r = mtconnect_request(sv(req.target()));
  const bool sample = r.path == "/sample" || r.path.ends_with("/sample");
  const auto interval = r.query.find("interval");
  if (config.mtconnect == nullptr || !sample || interval == r.query.end()) {
    auto answer = [self = shared_from_this(), req, role] { return self->mtconnect(req, Target{}, role); };
    return off_io(s, std::move(answer));
  }
  // A stream: its parameters checked by a first answer, which must succeed.
  auto number = [&](std::string_view name, long fallback, long max) -> std::optional<long> {
    auto it = r.query.find(name);
    if (it == r.query.end()) return fallback;
    char* end = nullptr;
    const long v = std::strtol(it->second.c_str(), &end, 10);
    if (it->second.empty() || *end != 0 || v < 0 || v > max) return std::nullopt;
    return v;
  };
  const auto every = number("interval", 0, 3600000), beat = number("heartbeat", 10000, 3600000);
  if (!every || !beat || *beat < 10)
    return s->send(error_response(req, 400, "interval and heartbeat are milliseconds (heartbeat ≥ 10)"));
  connect::AgentRequest first = r;
  first.query.erase("interval");
  first.query.erase("heartbeat");
  const connect::SampleAnswer check = config.mtconnect->sample(first, connect::StatusSampler::wall_us());
  if (check.response.status != 200) return s->send(agent_response(req, check.response));
  const auto from =
      first.query.count("from") ? std::stoull(first.query.at("from")) : config.mtconnect->first_sequence();
  auto stream = std::make_shared<MtcStream>(s->take_socket(), shared_from_this(), first,
                                            std::chrono::milliseconds(std::max(*every, 10L)),
                                            std::chrono::milliseconds(*beat));
  stream->run(from, req.version());
}

HttpResponse Server::Impl::static_file(const HttpRequest& req, const Target& t, Role) {
  if (config.static_dir.empty())
    return error_response(req, 404, "no front end is served (build it: scripts/hmi.sh)");
  std::optional<StaticFile> file = read_static_file(config.static_dir, t.path);
  if (!file) return error_response(req, 404, fmt::format("no such file: {}", t.path));
  HttpResponse res = respond(req, http::status::ok, std::move(file->body), file->type);
  if (file->immutable) res.set(http::field::cache_control, "max-age=31536000, immutable");
  return res;
}

// --- public ---------------------------------------------------------------------------------

Server::Server(controller::Controller& controller, const config::MachineProfile& profile, Tokens tokens,
               History* history, const controller::GcodeProgramSource* source, ServerConfig config)
    : impl_(std::make_shared<Impl>(controller, profile, std::move(tokens), history, source,
                                   std::move(config))) {}

Server::~Server() {
  stop();
}

bool Server::start(std::string* error) {
  Impl& s = *impl_;
  if (std::string why = connect::open_listener(*s.acceptor, s.config.address, s.config.port); !why.empty()) {
    if (error) *error = "--listen: " + why;
    return false;
  }
  s.port = s.acceptor->local_endpoint().port();
  s.loopback = s.acceptor->local_endpoint().address().is_loopback();
  s.accept();
  net::post(s.ioc, [self = impl_] { self->stream_tick(); });
  for (int k = 0; k < std::max(1, s.config.io_threads); ++k)
    s.threads.emplace_back([self = impl_] { self->ioc.run(); });
  return true;
}

void Server::stop() {
  Impl& s = *impl_;
  if (s.stopping.exchange(true) || !s.ioc_owner) return;
  s.ioc.stop();
  for (std::thread& t : s.threads) {
    if (t.joinable()) t.join();
  }
  s.workers.join();  // a preview being made finishes; its answer is dropped below
  s.blocking.join();
  // No thread runs the io_context now: close the I/O objects, then destroy the io_context,
  // which destroys every handler still queued and the sessions only they kept alive.
  beast::error_code ec;
  s.acceptor->close(ec);
  s.acceptor.reset();
  s.stream_timer.reset();
  {
    std::lock_guard lock(s.sessions_mutex);
    s.sessions.clear();
  }
  s.ioc_owner.reset();
}

std::uint16_t Server::port() const {
  return impl_->port;
}

bool Server::loopback_only() const {
  return impl_->loopback;
}

ServerStats Server::stats() const {
  ServerStats st;
  {
    std::lock_guard lock(impl_->sessions_mutex);
    for (const auto& w : impl_->sessions) {
      if (const auto s = w.lock(); s && !s->closed()) ++st.clients;
    }
  }
  st.dropped = impl_->dropped;
  st.stream_ticks = impl_->stream_ticks;
  st.status_messages = impl_->status_messages;
  st.http_requests = impl_->http_requests;
  st.mtconnect_streams = impl_->mtc_streams;
  st.mtconnect_dropped = impl_->mtc_dropped;
  st.mtconnect_parts = impl_->mtc_parts;
  return st;
}

}  // namespace opencnc::hmi
