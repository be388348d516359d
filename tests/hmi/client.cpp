// SPDX-License-Identifier: GPL-3.0-or-later
// The HMI server tests' blocking HTTP and WebSocket client on Boost.Beast (client.hpp): compiled
// once here, so that the test files do not each instantiate Beast (about 20 CPU s a file under
// the sanitizers).
#include "client.hpp"

#include <boost/asio/connect.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>

namespace opencnc::hmi::test {

namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
namespace net = boost::asio;
using tcp = net::ip::tcp;

namespace {

http::verb verb_of(Method m) {
  return m == Method::Get ? http::verb::get : http::verb::post;
}

}  // namespace

/// One request on a connection of its own.
Reply call(std::uint16_t port, Method method, const std::string& target, const std::string& token,
           const std::string& body) {
  net::io_context ioc;
  beast::tcp_stream stream(ioc);
  stream.connect(tcp::endpoint(net::ip::make_address("127.0.0.1"), port));
  http::request<http::string_body> req{verb_of(method), target, 11};
  req.set(http::field::host, "127.0.0.1");
  if (!token.empty()) req.set(http::field::authorization, "Bearer " + token);
  if (!body.empty()) {
    req.set(http::field::content_type, "application/json");
    req.body() = body;
  }
  req.prepare_payload();
  http::write(stream, req);
  beast::flat_buffer buffer;
  http::response_parser<http::string_body> parser;
  parser.body_limit(64 << 20);
  http::read(stream, buffer, parser);
  Reply r;
  r.status = static_cast<int>(parser.get().result_int());
  r.text = parser.get().body();
  r.body = nlohmann::json::parse(r.text, nullptr, false);
  beast::error_code ec;
  stream.socket().shutdown(tcp::socket::shutdown_both, ec);
  return r;
}

/// A request that declares a body of `declared_bytes` and sends only its header: what the server
/// answers from the header alone. (Sending a body the server refuses races its close: once it
/// answers and closes, the rest of the body gets a reset and the answer may be lost on the way.)
Reply call_declaring(std::uint16_t port, const std::string& target, const std::string& token,
                     std::size_t declared_bytes) {
  net::io_context ioc;
  beast::tcp_stream stream(ioc);
  stream.connect(tcp::endpoint(net::ip::make_address("127.0.0.1"), port));
  http::request<http::empty_body> req{http::verb::post, target, 11};
  req.set(http::field::host, "127.0.0.1");
  if (!token.empty()) req.set(http::field::authorization, "Bearer " + token);
  req.set(http::field::content_type, "application/json");
  req.content_length(declared_bytes);
  http::request_serializer<http::empty_body> sr{req};
  http::write_header(stream, sr);
  beast::flat_buffer buffer;
  http::response_parser<http::string_body> parser;
  http::read(stream, buffer, parser);
  Reply r;
  r.status = static_cast<int>(parser.get().result_int());
  r.text = parser.get().body();
  r.body = nlohmann::json::parse(r.text, nullptr, false);
  return r;
}

Reply get(std::uint16_t port, const std::string& target, const std::string& token) {
  return call(port, Method::Get, target, token);
}

Reply post(std::uint16_t port, const std::string& body, const std::string& token) {
  return call(port, Method::Post, "/api/v1/commands", token, body);
}

struct Stream::Socket {
  explicit Socket() : ws(ioc) {}
  net::io_context ioc;
  websocket::stream<beast::tcp_stream> ws;
};

Stream::Stream(std::uint16_t port, const std::string& token, int receive_buffer, const std::string& query)
    : socket_(std::make_unique<Socket>()) {
  auto& ws = socket_->ws;
  auto& socket = beast::get_lowest_layer(ws).socket();
  socket.open(tcp::v4());
  if (receive_buffer > 0) socket.set_option(net::socket_base::receive_buffer_size(receive_buffer));
  beast::get_lowest_layer(ws).connect(tcp::endpoint(net::ip::make_address("127.0.0.1"), port));
  // A token in the header (what a program can send); a browser sends a ticket (`ticket=` in the
  // target: Stream(port, "", 0, "?ticket=…")).
  ws.set_option(websocket::stream_base::decorator([token](websocket::request_type& req) {
    if (!token.empty()) req.set(http::field::authorization, "Bearer " + token);
  }));
  ws.handshake("127.0.0.1", "/api/v1/stream" + query);
}

Stream::~Stream() = default;

nlohmann::json Stream::next() {
  beast::flat_buffer b;
  socket_->ws.read(b);
  return nlohmann::json::parse(beast::buffers_to_string(b.data()));
}

bool Stream::read_until_closed(int max_messages) {
  try {
    for (int k = 0; k < max_messages; ++k) next();
  } catch (const beast::system_error&) {
    return true;
  }
  return false;
}

}  // namespace opencnc::hmi::test
