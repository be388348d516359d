// SPDX-License-Identifier: GPL-3.0-or-later
// A blocking HTTP and WebSocket client for the HMI server's tests (Boost.Beast, in client.cpp).
// Errors of the connection (a refused handshake, a closed stream) throw std::runtime_error's kin.
#pragma once

#include <cstdint>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

namespace opencnc::hmi::test {

struct Reply {
  int status = 0;
  nlohmann::json body;
  std::string text;
};

enum class Method { Get, Post };

/// One request on a connection of its own.
Reply call(std::uint16_t port, Method method, const std::string& target, const std::string& token = "",
           const std::string& body = "");

/// A request that declares a body of `declared_bytes` and sends only its header: what the server
/// answers from the header alone. (Sending a body the server refuses races its close: once it
/// answers and closes, the rest of the body gets a reset and the answer may be lost on the way.)
Reply call_declaring(std::uint16_t port, const std::string& target, const std::string& token,
                     std::size_t declared_bytes);

Reply get(std::uint16_t port, const std::string& target, const std::string& token = "");
Reply post(std::uint16_t port, const std::string& body, const std::string& token);

/// A WebSocket client of /api/v1/stream.
class Stream {
 public:
  /// `receive_buffer`: the socket's receive buffer (small: a client that stops reading shows soon).
  Stream(std::uint16_t port, const std::string& token, int receive_buffer = 0, const std::string& query = "");
  ~Stream();
  /// The next message, parsed; throws when the server closed the stream.
  nlohmann::json next();
  /// Reads until the server closes (true) or `max_messages` arrived (false).
  bool read_until_closed(int max_messages);

 private:
  struct Socket;
  std::unique_ptr<Socket> socket_;
};

}  // namespace opencnc::hmi::test
