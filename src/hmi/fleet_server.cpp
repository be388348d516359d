// SPDX-License-Identifier: GPL-3.0-or-later
// The fleet view's HTTP server on Boost.Beast: one thread, one request at a time per connection,
// every answer made at once from the watcher's state (no call here waits on anything).
#include "opencnc/hmi/fleet_server.hpp"

#include <fmt/format.h>

#include <boost/asio/strand.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <optional>
#include <thread>

#include "opencnc/connect/listener.hpp"
#include "opencnc/hmi/static_files.hpp"

namespace opencnc::hmi {

namespace beast = boost::beast;
namespace http = beast::http;
namespace net = boost::asio;
using tcp = net::ip::tcp;
using Request = http::request<http::string_body>;
using Response = http::response<http::string_body>;

namespace {

constexpr std::size_t kBodyLimit = 8 * 1024;  // a GET has no body worth reading

Response answer(const Request& req, http::status status, std::string body, std::string_view type) {
  Response res{status, req.version()};
  res.set(http::field::server, "opencnc fleet");
  res.set(http::field::content_type, beast::string_view(type.data(), type.size()));
  res.set(http::field::cache_control, "no-store");
  res.keep_alive(req.keep_alive());
  res.body() = std::move(body);
  res.prepare_payload();
  return res;
}

Response error(const Request& req, http::status status, std::string_view message) {
  return answer(req, status, fmt::format(R"({{"error":"{}"}})", message), "application/json");
}

}  // namespace

// The sessions and the pending accept point at the Impl without owning it: the io_context inside it
// destroys them (and their handlers) before the rest of it goes.
struct FleetServer::Impl {
  Impl(const connect::FleetWatcher& f, FleetServerConfig c) : fleet(f), config(std::move(c)) {}

  Response respond(const Request& req) const {
    if (req.method() != http::verb::get && req.method() != http::verb::head)
      return error(req, http::status::method_not_allowed, "the fleet view is read-only: GET");
    std::string_view target(req.target().data(), req.target().size());
    const std::string_view path = target.substr(0, target.find('?'));
    if (path == "/api/v1/fleet") return answer(req, http::status::ok, fleet.json(), "application/json");
    if (path.starts_with("/api/")) return error(req, http::status::not_found, "no such call");
    std::optional<StaticFile> file = read_static_file(config.static_dir, path, "fleet.html");
    if (!file)
      return error(req, http::status::not_found, "no such file (the page is built by scripts/hmi.sh)");
    Response res = answer(req, http::status::ok, std::move(file->body), file->type);
    if (file->immutable) res.set(http::field::cache_control, "max-age=31536000, immutable");
    return res;
  }

  /// One connection: request, answer, and again while the client keeps it alive.
  struct Session : std::enable_shared_from_this<Session> {
    Session(tcp::socket s, const Impl* server) : stream(std::move(s)), impl(server) {}
    void read() {
      parser.emplace();
      parser->body_limit(kBodyLimit);
      stream.expires_after(std::chrono::seconds(30));
      http::async_read(
          stream, buffer, *parser, [self = shared_from_this()](beast::error_code ec, std::size_t) {
            if (ec) return;  // closed, timed out, too large or not HTTP: nothing to answer
            auto res = std::make_shared<Response>(self->impl->respond(self->parser->get()));
            http::async_write(self->stream, *res, [self, res](beast::error_code wec, std::size_t) {
              if (wec || res->need_eof()) {
                self->stream.socket().shutdown(tcp::socket::shutdown_send, wec);
                return;
              }
              self->read();
            });
          });
    }
    beast::tcp_stream stream;
    beast::flat_buffer buffer;
    std::optional<http::request_parser<http::string_body>> parser;
    const Impl* impl;
  };

  void accept() {
    acceptor.async_accept(net::make_strand(ioc), [this](beast::error_code ec, tcp::socket s) {
      if (ec == net::error::operation_aborted) return;
      if (!ec) std::make_shared<Session>(std::move(s), this)->read();
      accept();
    });
  }

  const connect::FleetWatcher& fleet;
  FleetServerConfig config;
  net::io_context ioc{1};
  tcp::acceptor acceptor{ioc};
  std::thread thread;
  std::uint16_t bound = 0;
};

FleetServer::FleetServer(const connect::FleetWatcher& fleet, FleetServerConfig config)
    : impl_(std::make_unique<Impl>(fleet, std::move(config))) {}

FleetServer::~FleetServer() {
  stop();
}

bool FleetServer::start(std::string* error) {
  Impl& m = *impl_;
  if (std::string why = connect::open_listener(m.acceptor, m.config.address, m.config.port); !why.empty()) {
    if (error) *error = std::move(why);
    return false;
  }
  m.bound = m.acceptor.local_endpoint().port();
  m.accept();
  m.thread = std::thread([&m] { m.ioc.run(); });
  return true;
}

void FleetServer::stop() {
  Impl& m = *impl_;
  if (!m.thread.joinable()) return;
  m.ioc.stop();
  m.thread.join();
}

std::uint16_t FleetServer::port() const noexcept {
  return impl_->bound;
}

}  // namespace opencnc::hmi
