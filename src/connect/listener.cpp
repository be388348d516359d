// SPDX-License-Identifier: GPL-3.0-or-later
#include "opencnc/connect/listener.hpp"

#include <fmt/format.h>

namespace opencnc::connect {

std::string open_listener(boost::asio::ip::tcp::acceptor& acceptor, const std::string& address,
                          std::uint16_t port) {
  namespace net = boost::asio;
  boost::system::error_code ec;
  const auto ip = net::ip::make_address(address, ec);
  if (ec) return fmt::format("'{}' is not an IP address", address);
  const net::ip::tcp::endpoint at(ip, port);
  acceptor.open(at.protocol(), ec);
  if (!ec) acceptor.set_option(net::socket_base::reuse_address(true), ec);
  if (!ec) acceptor.bind(at, ec);
  if (!ec) acceptor.listen(net::socket_base::max_listen_connections, ec);
  if (ec) return fmt::format("cannot listen on {}:{}: {}", address, port, ec.message());
  return {};
}

}  // namespace opencnc::connect
