// SPDX-License-Identifier: GPL-3.0-or-later
// Tokens for the HMI: the environment's, or a 0600 file written once with random ones.
#include "opencnc/hmi/tokens.hpp"

#include <fcntl.h>
#include <sys/random.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <sstream>

#include <fmt/format.h>

#include "opencnc/core/atomic_file.hpp"

namespace opencnc::hmi {

namespace {

constexpr std::size_t kMinLength = 16;

std::optional<std::string> random_token(std::string* error) {
  unsigned char bytes[24];
  std::size_t got = 0;
  while (got < sizeof bytes) {
    const ssize_t n = ::getrandom(bytes + got, sizeof bytes - got, 0);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      if (error) *error = fmt::format("no random numbers: {}", std::strerror(errno));
      return std::nullopt;
    }
    got += static_cast<std::size_t>(n);
  }
  std::string t;
  for (unsigned char b : bytes) t += fmt::format("{:02x}", b);
  return t;
}

/// Writes `content` to `path` with mode 0600 from the first byte: a temporary file created
/// exclusively, fdatasync, rename, then the folder synced.
bool write_private(const std::filesystem::path& path, const std::string& content, std::string* error) {
  const std::string tmp = path.string() + fmt::format(".tmp.{}", ::getpid());
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
  bool ok = fd >= 0;
  if (ok) ok = ::write(fd, content.data(), content.size()) == static_cast<ssize_t>(content.size());
  if (ok) ok = ::fdatasync(fd) == 0;
  const int saved = errno;
  if (fd >= 0) ::close(fd);
  if (ok) ok = ::rename(tmp.c_str(), path.c_str()) == 0;
  if (!ok) {
    if (error)
      *error = fmt::format("cannot write {}: {}", path.string(), std::strerror(saved ? saved : errno));
    ::unlink(tmp.c_str());
    return false;
  }
  const std::string dir = path.has_parent_path() ? path.parent_path().string() : ".";
  if (const int d = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC); d >= 0) {
    ::fsync(d);
    ::close(d);
  }
  return true;
}

std::optional<Tokens> read_tokens(const std::filesystem::path& path, std::string* error) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) {
    if (error) *error = fmt::format("{}: {}", path.string(), std::strerror(errno));
    return std::nullopt;
  }
  if ((st.st_mode & 077) != 0) {
    if (error)
      *error =
          fmt::format("{}: others may read it (mode {:o}); chmod 600 it", path.string(), st.st_mode & 0777);
    return std::nullopt;
  }
  std::string text;
  if (!read_file(path.string(), text, error)) return std::nullopt;
  std::istringstream in(text);
  std::string line, op, admin;
  int n = 0;
  while (std::getline(in, line)) {
    ++n;
    if (line.empty() || line[0] == '#') continue;
    std::istringstream words(line);
    std::string role, token, extra;
    words >> role >> token >> extra;
    if (!extra.empty() || token.size() < kMinLength || (role != "operator" && role != "admin")) {
      if (error)
        *error =
            fmt::format("{}:{}:1: expected \"operator TOKEN\" or \"admin TOKEN\" (16 characters or more)",
                        path.string(), n);
      return std::nullopt;
    }
    (role == "admin" ? admin : op) = token;
  }
  if (op.empty() || admin.empty() || op == admin) {
    if (error)
      *error =
          fmt::format("{}: needs an operator and an admin token, different from each other", path.string());
    return std::nullopt;
  }
  Tokens t = Tokens::of(op, admin);
  return t;
}

bool same(std::string_view a, std::string_view b) noexcept {
  if (a.size() != b.size()) return false;
  unsigned char diff = 0;
  for (std::size_t i = 0; i < a.size(); ++i) diff |= static_cast<unsigned char>(a[i] ^ b[i]);
  return diff == 0;
}

}  // namespace

Tokens Tokens::of(std::string operator_token, std::string admin_token) {
  Tokens t;
  t.operator_ = std::move(operator_token);
  t.admin_ = std::move(admin_token);
  t.origin_ = "given";
  return t;
}

std::optional<Tokens> Tokens::load(const std::filesystem::path& path, std::string* error) {
  const char* op = std::getenv("OPENCNC_OPERATOR_TOKEN");
  const char* admin = std::getenv("OPENCNC_ADMIN_TOKEN");
  if (op || admin) {
    if (!op || !admin || std::strlen(op) < kMinLength || std::strlen(admin) < kMinLength ||
        std::strcmp(op, admin) == 0) {
      if (error)
        *error =
            "OPENCNC_OPERATOR_TOKEN and OPENCNC_ADMIN_TOKEN must both be set, differ, and have 16 characters "
            "or more";
      return std::nullopt;
    }
    Tokens t = of(op, admin);
    t.origin_ = "environment";
    return t;
  }
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) {
    const auto o = random_token(error);
    const auto a = o ? random_token(error) : std::nullopt;
    if (!a) return std::nullopt;
    const std::string text =
        fmt::format("# opencnc serve: HMI tokens (keep this file private)\noperator {}\nadmin {}\n", *o, *a);
    if (!write_private(path, text, error)) return std::nullopt;
  }
  auto t = read_tokens(path, error);
  if (t) t->origin_ = path.string();
  return t;
}

std::optional<Role> Tokens::role_of(std::string_view token) const noexcept {
  if (token.empty()) return std::nullopt;
  const bool is_admin = same(token, admin_);
  const bool is_operator = same(token, operator_);
  if (is_admin) return Role::Admin;
  if (is_operator) return Role::Operator;
  return std::nullopt;
}

std::optional<std::string> random_secret(std::string* error) {
  return random_token(error);
}

}  // namespace opencnc::hmi
