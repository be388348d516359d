// SPDX-License-Identifier: GPL-3.0-or-later
// What the command line's servers share: an ADDRESS:PORT option read, the built front end found.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>

namespace opencnc::cli {

/// `listen` ("127.0.0.1:8080", "[::1]:8080") split into its address and port; false when it is
/// not ADDRESS:PORT with a port of 0 to 65535.
bool split_listen(const std::string& listen, std::string& address, std::uint16_t& port);

/// The built front end beside the executable: <build>/../web/dist.
std::filesystem::path default_static_dir();

}  // namespace opencnc::cli
