// SPDX-License-Identifier: GPL-3.0-or-later
// Reading runs of decimal digits eight at a time (the number reader's inner loop).
#pragma once

#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>

namespace opencnc::gcode {

/// The eight bytes at `p` as a little-endian word (byte k = p[k]); bytes at or beyond `limit`
/// read as 0. Reads nothing outside [text, limit): near the end it loads the last eight bytes
/// of the text and shifts. Requires text <= p <= limit.
inline std::uint64_t load_eight(const char* p, const char* text, const char* limit) noexcept {
  const auto left = static_cast<std::size_t>(limit - p);
  std::uint64_t w = 0;
  if (left >= 8) {
    std::memcpy(&w, p, 8);
  } else if (left == 0) {
    return 0;
  } else if (limit - text >= 8) {
    std::memcpy(&w, limit - 8, 8);
    w >>= 8 * (8 - left);
  } else {
    for (std::size_t k = 0; k < left; ++k) w |= std::uint64_t{static_cast<unsigned char>(p[k])} << (8 * k);
  }
  return w;
}

/// Reads the run of digits '0'-'9' starting at `p` (not beyond `limit`; `text` as for
/// load_eight): appends them to `value` (value = value * 10^n + run, wrapping modulo 2^64
/// after 19 digits, so callers use it for short runs only) and returns their count n.
inline std::size_t read_digit_run(const char* p, const char* text, const char* limit, std::uint64_t& value) noexcept {
  if constexpr (std::endian::native != std::endian::little) {
    std::size_t n = 0;
    while (p + n < limit && p[n] >= '0' && p[n] <= '9') value = value * 10 + static_cast<std::uint64_t>(p[n++] - '0');
    return n;
  } else {
    constexpr std::uint64_t kOnes = 0x0101010101010101u;
    constexpr std::uint64_t kPow10[] = {1, 10, 100, 1000, 10000, 100000, 1000000, 10000000, 100000000};
    std::size_t total = 0;
    for (;;) {
      // XOR with '0' turns digit bytes into 0..9; any other byte keeps a high nibble, or has
      // a low nibble above 9 (which the +6 carries into the high nibble).
      const std::uint64_t x = load_eight(p + total, text, limit) ^ (0x30 * kOnes);
      const std::uint64_t other = (x & (0xF0 * kOnes)) | (((x & (0x0F * kOnes)) + 0x06 * kOnes) & (0xF0 * kOnes));
      const std::size_t n = other == 0 ? 8 : static_cast<std::size_t>(std::countr_zero(other)) / 8;
      if (n == 0) return total;
      // The n digits moved to the top bytes (zeros in front), first digit most significant;
      // then pairs, quadruples and the eight combined by multiply-and-add in place.
      std::uint64_t v = x << (8 * (8 - n));
      v = (v * 10 + (v >> 8)) & (0x00FF00FF00FF00FFu);
      v = (v * 100 + (v >> 16)) & (0x0000FFFF0000FFFFu);
      v = (v * 10000 + (v >> 32)) & 0xFFFFFFFFu;
      value = value * kPow10[n] + v;
      total += n;
      if (n < 8) return total;
    }
  }
}

}  // namespace opencnc::gcode
