// SPDX-License-Identifier: GPL-3.0-or-later
// The simulated broach's workpiece beside the journal: its bytes, checksum and file.
#include "opencnc/broaching/sim_bore.hpp"

#include <bit>
#include <cerrno>
#include <cstring>
#include <filesystem>

#include "opencnc/broaching/journal.hpp"
#include "opencnc/core/atomic_file.hpp"

namespace opencnc::recovery {

namespace {

constexpr char kMagic[4] = {'O', 'C', 'S', 'B'};
constexpr std::uint32_t kVersion = 1;
/// A bore larger than this is not one of ours (the model has 256 × 72 cells).
constexpr std::uint32_t kMaxCells = 1u << 20;

static_assert(std::endian::native == std::endian::little, "the bore is stored little-endian as in memory");

template <class T>
void put(std::string& out, const T& v) {
  char raw[sizeof(T)];
  std::memcpy(raw, &v, sizeof(T));
  out.append(raw, sizeof(T));
}

template <class T>
bool take(std::string_view& in, T& v) {
  if (in.size() < sizeof(T)) return false;
  std::memcpy(&v, in.data(), sizeof(T));
  in.remove_prefix(sizeof(T));
  return true;
}

std::uint32_t crc_of(std::string_view bytes) {
  return crc32(std::as_bytes(std::span<const char>(bytes.data(), bytes.size())));
}

}  // namespace

std::string encode_sim_bore(const SimBore& b) {
  std::string out(kMagic, sizeof kMagic);
  put(out, kVersion);
  put(out, b.program_hash);
  put(out, b.signal_time_s);
  put(out, static_cast<std::uint32_t>(b.cells.size()));
  out.append(reinterpret_cast<const char*>(b.cells.data()), b.cells.size() * sizeof(float));
  put(out, crc_of(out));
  return out;
}

std::optional<SimBore> decode_sim_bore(std::string_view bytes, std::string* error) {
  const auto fail = [&](const char* why) -> std::optional<SimBore> {
    if (error != nullptr) *error = why;
    return std::nullopt;
  };
  if (bytes.size() < sizeof kMagic + sizeof(std::uint32_t) ||
      std::memcmp(bytes.data(), kMagic, sizeof kMagic) != 0)
    return fail("not a simulated bore (no OCSB magic)");
  std::uint32_t stored_crc = 0;
  std::string_view tail = bytes.substr(bytes.size() - sizeof stored_crc);
  take(tail, stored_crc);
  const std::string_view body = bytes.substr(0, bytes.size() - sizeof stored_crc);
  if (crc_of(body) != stored_crc)
    return fail("the simulated bore's checksum does not match (a torn or corrupt file)");
  std::string_view in = body.substr(sizeof kMagic);
  std::uint32_t version = 0, count = 0;
  SimBore b;
  if (!take(in, version) || version != kVersion) return fail("the simulated bore has an unknown version");
  if (!take(in, b.program_hash) || !take(in, b.signal_time_s) || !take(in, count) || count > kMaxCells ||
      in.size() != count * sizeof(float))
    return fail("the simulated bore is truncated or of the wrong size");
  b.cells.resize(count);
  std::memcpy(b.cells.data(), in.data(), in.size());
  return b;
}

bool save_sim_bore(const std::string& dir, const SimBore& b, std::string* error) {
  return write_file_atomically((std::filesystem::path(dir) / kSimBoreFile).string(), encode_sim_bore(b),
                               error);
}

std::optional<SimBore> load_sim_bore(const std::string& dir, std::string* error) {
  const std::string path = (std::filesystem::path(dir) / kSimBoreFile).string();
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) {
    if (error != nullptr) error->clear();
    return std::nullopt;
  }
  std::string bytes;
  if (!read_file(path, bytes, error)) return std::nullopt;
  return decode_sim_bore(bytes, error);
}

}  // namespace opencnc::recovery
