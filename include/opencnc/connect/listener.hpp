// SPDX-License-Identifier: GPL-3.0-or-later
// connect: a TCP listener opened on an address and port, as every server of opencnc opens one
// (the HMI, the fleet view, the SHDR adapter).
#pragma once

#include <boost/asio/ip/tcp.hpp>
#include <cstdint>
#include <string>

namespace opencnc::connect {

/// Opens `acceptor` on `address`:`port` (an IPv4 or IPv6 literal; port 0: any free one), the address
/// reusable, listening. Returns "" or why not: "'x' is not an IP address", "cannot listen on A:P: …".
std::string open_listener(boost::asio::ip::tcp::acceptor& acceptor, const std::string& address,
                          std::uint16_t port);

}  // namespace opencnc::connect
