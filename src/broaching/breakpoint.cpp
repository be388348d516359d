// SPDX-License-Identifier: GPL-3.0-or-later
// The breakpoint record's serialisation (little-endian fields after a magic and a version, a CRC-32
// at the end) and the program file's content hash.
#include "opencnc/broaching/breakpoint.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cstring>
#include <fstream>

#include <fmt/format.h>

#include "opencnc/broaching/journal.hpp"

namespace opencnc::recovery {

namespace {

constexpr std::array<char, 4> kMagic = {'O', 'C', 'B', 'P'};
/// Bound on a string field: a path or a file name, never megabytes.
constexpr std::uint32_t kMaxString = 64 * 1024;

class Out {
 public:
  void bytes(const void* p, std::size_t n) {
    const auto* b = static_cast<const std::byte*>(p);
    buf_.insert(buf_.end(), b, b + n);
  }
  template <class T>
  void num(T v) {
    static_assert(std::is_arithmetic_v<T>);
    std::array<std::byte, sizeof(T)> b;
    std::memcpy(b.data(), &v, sizeof(T));
    if constexpr (std::endian::native == std::endian::big) std::reverse(b.begin(), b.end());
    bytes(b.data(), b.size());
  }
  void str(const std::string& s) {
    num(static_cast<std::uint32_t>(s.size()));
    bytes(s.data(), s.size());
  }
  void pose(const Pose& p) {
    for (double d : p.v) num(d);
  }
  std::vector<std::byte>& buffer() { return buf_; }

 private:
  std::vector<std::byte> buf_;
};

class In {
 public:
  explicit In(std::span<const std::byte> b) : b_(b) {}
  bool ok() const { return ok_; }
  bool take(void* p, std::size_t n) {
    if (!ok_ || b_.size() - at_ < n) return ok_ = false;
    std::memcpy(p, b_.data() + at_, n);
    at_ += n;
    return true;
  }
  template <class T>
  T num() {
    std::array<std::byte, sizeof(T)> b{};
    if (!take(b.data(), b.size())) return T{};
    if constexpr (std::endian::native == std::endian::big) std::reverse(b.begin(), b.end());
    T v;
    std::memcpy(&v, b.data(), sizeof(T));
    return v;
  }
  std::string str() {
    const auto n = num<std::uint32_t>();
    if (n > kMaxString) ok_ = false;
    if (!ok_) return {};
    std::string s(n, '\0');
    take(s.data(), n);
    return s;
  }
  Pose pose() {
    Pose p;
    for (double& d : p.v) d = num<double>();
    return p;
  }
  std::size_t left() const { return b_.size() - at_; }

 private:
  std::span<const std::byte> b_;
  std::size_t at_ = 0;
  bool ok_ = true;
};

void put_body(Out& o, const BreakpointRecord& r) {
  o.num<std::uint8_t>(r.valid ? 1 : 0);
  o.num(static_cast<std::uint8_t>(r.stage));
  o.str(r.program_path);
  o.num(r.program_hash);
  o.num(r.program_size);
  o.pose(r.program_start);
  o.num(r.segment);
  o.num(r.job_move);
  o.num(r.segment_offset_mm);
  o.str(r.source_file);
  o.num(r.line);
  o.num(r.move_kind);
  o.pose(r.move_start);
  o.pose(r.move_end);
  o.num(r.move_remaining_mm);
  o.pose(r.commanded);
  o.pose(r.actual);
  o.num(r.modal_digest);
  o.num(r.tool);
  o.num(r.spindle_rpm);
  o.num(r.spindle_direction);
  o.num<std::uint8_t>(static_cast<std::uint8_t>((r.flood ? 1 : 0) | (r.mist ? 2 : 0)));
  const BreakpointCoupling& c = r.coupling;
  o.num(c.kind);
  o.num(c.master_axis);
  o.num(c.slave_axis);
  o.num(c.table);
  o.num(c.pitch_mm);
  o.num(c.pitch_rate);
  o.num(c.master_origin);
  o.num(c.slave_origin);
  o.num(r.signal_time_s);
  o.num(r.rest_time_s);
}

BreakpointRecord get_body(In& in) {
  BreakpointRecord r;
  r.valid = in.num<std::uint8_t>() != 0;
  r.stage = in.num<std::uint8_t>() == 1 ? BreakpointStage::AtRest : BreakpointStage::Stopping;
  r.program_path = in.str();
  r.program_hash = in.num<std::uint64_t>();
  r.program_size = in.num<std::uint64_t>();
  r.program_start = in.pose();
  r.segment = in.num<std::uint64_t>();
  r.job_move = in.num<std::uint64_t>();
  r.segment_offset_mm = in.num<double>();
  r.source_file = in.str();
  r.line = in.num<std::uint32_t>();
  r.move_kind = in.num<std::uint8_t>();
  r.move_start = in.pose();
  r.move_end = in.pose();
  r.move_remaining_mm = in.num<double>();
  r.commanded = in.pose();
  r.actual = in.pose();
  r.modal_digest = in.num<std::uint64_t>();
  r.tool = in.num<std::int32_t>();
  r.spindle_rpm = in.num<double>();
  r.spindle_direction = in.num<std::int8_t>();
  const auto coolant = in.num<std::uint8_t>();
  r.flood = (coolant & 1) != 0;
  r.mist = (coolant & 2) != 0;
  BreakpointCoupling& c = r.coupling;
  c.kind = in.num<std::uint8_t>();
  c.master_axis = in.num<std::int8_t>();
  c.slave_axis = in.num<std::int8_t>();
  c.table = in.num<std::int32_t>();
  c.pitch_mm = in.num<double>();
  c.pitch_rate = in.num<double>();
  c.master_origin = in.num<double>();
  c.slave_origin = in.num<double>();
  r.signal_time_s = in.num<double>();
  r.rest_time_s = in.num<double>();
  return r;
}

}  // namespace

const char* to_string(BreakpointStage s) noexcept {
  return s == BreakpointStage::AtRest ? "at-rest" : "stopping";
}

std::vector<std::byte> encode(const BreakpointRecord& r) {
  Out o;
  o.bytes(kMagic.data(), kMagic.size());
  o.num(BreakpointRecord::kVersion);
  put_body(o, r);
  o.num(crc32(o.buffer()));
  return std::move(o.buffer());
}

std::optional<BreakpointRecord> decode(std::span<const std::byte> bytes, std::string* error) {
  const auto fail = [&](const char* why) -> std::optional<BreakpointRecord> {
    if (error != nullptr) *error = why;
    return std::nullopt;
  };
  if (bytes.size() < kMagic.size() + 8) return fail("the breakpoint record is truncated");
  if (std::memcmp(bytes.data(), kMagic.data(), kMagic.size()) != 0) return fail("not a breakpoint record");
  const std::span<const std::byte> body = bytes.first(bytes.size() - 4);
  In tail(bytes.last(4));
  if (crc32(body) != tail.num<std::uint32_t>()) return fail("the breakpoint record fails its checksum");
  In in(body.subspan(kMagic.size()));
  const auto version = in.num<std::uint32_t>();
  if (version != BreakpointRecord::kVersion)
    return fail("the breakpoint record has an unknown format version");
  BreakpointRecord r = get_body(in);
  if (!in.ok()) return fail("the breakpoint record is truncated");
  if (in.left() != 0) return fail("the breakpoint record has trailing bytes");
  return r;
}

std::string describe(const BreakpointRecord& r) {
  std::string s =
      fmt::format("{} breakpoint ({}) in {} at {}:{}, segment {} + {:.4f} mm ({:.4f} mm of the move left)",
                  r.valid ? "valid" : "cleared", to_string(r.stage), r.program_path, r.source_file, r.line,
                  r.segment, r.segment_offset_mm, r.move_remaining_mm);
  if (r.coupling.kind != 0 && r.coupling.master_axis >= 0 && r.coupling.slave_axis >= 0) {
    const auto m = static_cast<std::size_t>(r.coupling.master_axis),
               sl = static_cast<std::size_t>(r.coupling.slave_axis);
    s += fmt::format("; coupled (law {}): {} {:.4f}, {} {:.4f}", r.coupling.kind,
                     letter(static_cast<Axis>(r.coupling.master_axis)), r.commanded.v[m],
                     letter(static_cast<Axis>(r.coupling.slave_axis)), r.commanded.v[sl]);
  }
  return s;
}

std::optional<FileHash> hash_file(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  if (!f) return std::nullopt;
  FileHash h{0xcbf29ce484222325ULL, 0};
  std::array<char, 1 << 16> buf;
  while (f) {
    f.read(buf.data(), buf.size());
    const std::streamsize n = f.gcount();
    for (std::streamsize i = 0; i < n; ++i) {
      h.hash ^= static_cast<unsigned char>(buf[static_cast<std::size_t>(i)]);
      h.hash *= 0x100000001b3ULL;
    }
    h.size += static_cast<std::uint64_t>(n);
  }
  if (f.bad()) return std::nullopt;
  return h;
}

}  // namespace opencnc::recovery
