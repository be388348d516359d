// SPDX-License-Identifier: GPL-3.0-or-later
// A blocking HTTP and WebSocket client on Boost.Beast for the HMI server's tests.
#pragma once

#include <boost/asio/connect.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <nlohmann/json.hpp>
#include <string>

namespace opencnc::hmi::test {

namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
namespace net = boost::asio;
using tcp = net::ip::tcp;

struct Reply {
  int status = 0;
  nlohmann::json body;
  std::string text;
};

/// One request on a connection of its own.
inline Reply call(std::uint16_t port, http::verb method, const std::string& target,
                  const std::string& token = "", const std::string& body = "") {
  net::io_context ioc;
  beast::tcp_stream stream(ioc);
  stream.connect(tcp::endpoint(net::ip::make_address("127.0.0.1"), port));
  http::request<http::string_body> req{method, target, 11};
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
inline Reply call_declaring(std::uint16_t port, const std::string& target, const std::string& token,
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

inline Reply get(std::uint16_t port, const std::string& target, const std::string& token = "") {
  return call(port, http::verb::get, target, token);
}

inline Reply post(std::uint16_t port, const std::string& body, const std::string& token) {
  return call(port, http::verb::post, "/api/v1/commands", token, body);
}

/// A WebSocket client of /api/v1/stream.
class Stream {
 public:
  /// `receive_buffer`: the socket's receive buffer (small: a client that stops reading shows soon).
  Stream(std::uint16_t port, const std::string& token, int receive_buffer = 0, const std::string& query = "")
      : ws_(ioc_) {
    auto& socket = beast::get_lowest_layer(ws_).socket();
    socket.open(tcp::v4());
    if (receive_buffer > 0) socket.set_option(net::socket_base::receive_buffer_size(receive_buffer));
    beast::get_lowest_layer(ws_).connect(tcp::endpoint(net::ip::make_address("127.0.0.1"), port));
    // A token in the header (what a program can send); a browser sends a ticket (`ticket=` in the
    // target: Stream(port, "", 0, "?ticket=…")).
    ws_.set_option(websocket::stream_base::decorator([token](websocket::request_type& req) {
      if (!token.empty()) req.set(http::field::authorization, "Bearer " + token);
    }));
    ws_.handshake("127.0.0.1", "/api/v1/stream" + query);
  }
  /// The next message, parsed; throws when the server closed the stream.
  nlohmann::json next() {
    beast::flat_buffer b;
    ws_.read(b);
    return nlohmann::json::parse(beast::buffers_to_string(b.data()));
  }
  /// Reads until the server closes (true) or `max_messages` arrived (false).
  bool read_until_closed(int max_messages) {
    try {
      for (int k = 0; k < max_messages; ++k) next();
    } catch (const beast::system_error&) {
      return true;
    }
    return false;
  }

 private:
  net::io_context ioc_;
  websocket::stream<beast::tcp_stream> ws_;
};

}  // namespace opencnc::hmi::test
