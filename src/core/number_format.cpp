// SPDX-License-Identifier: GPL-3.0-or-later
// Fixed-point formatting: integer arithmetic on the scaled value, snprintf near ties.
#include "opencnc/core/number_format.hpp"

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>

namespace opencnc {

namespace {
constexpr double kPow10[] = {1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9};
}  // namespace

std::size_t format_fixed(char* out, double value, int decimals) noexcept {
  if (decimals < 0) decimals = 0;
  if (decimals > 9) decimals = 9;
  const double mag = std::fabs(value);
  const double scaled = mag * kPow10[decimals];
  auto by_printf = [&] {
    const int n = std::snprintf(out, kFixedBufferSize, "%.*f", decimals, value);
    return n > 0 ? static_cast<std::size_t>(n) : std::size_t{0};
  };
  // Below 9e15 (< 2^53) every integer is a double, so converting to an integer is exact and
  // is floor() for these non-negative values (a library call avoided twice per number).
  if (!(scaled < 9e15)) return by_printf();
  // printf rounds the exact binary value; `scaled` carries at most ~1 ulp of error, so only
  // values whose fraction lies within a few ulps of one half need the C library to decide.
  // (signed conversions: they are single instructions, the unsigned ones are not)
  const double fraction = scaled - static_cast<double>(static_cast<std::int64_t>(scaled));
  const double window = 1e-7 + scaled * 1e-15;
  if (std::fabs(fraction - 0.5) < window) return by_printf();
  auto r = static_cast<std::uint64_t>(static_cast<std::int64_t>(scaled + 0.5));

  // Digits right to left, two at a time: the decimals, the point, then the whole part (no
  // division by a variable power of ten). They end in the middle of `digits` so that the
  // copy below can move a fixed 32 bytes, whatever the length.
  static constexpr char kPairs[] =
      "0001020304050607080910111213141516171819202122232425262728293031323334353637383940414243444546474849"
      "5051525354555657585960616263646566676869707172737475767778798081828384858687888990919293949596979899";
  char digits[64];
  char* const end = digits + 32;
  char* p = end;
  for (int i = decimals; i > 0;) {
    if (i >= 2) {
      p -= 2;
      std::memcpy(p, kPairs + 2 * (r % 100), 2);
      r /= 100;
      i -= 2;
    } else {
      *--p = static_cast<char>('0' + r % 10);
      r /= 10;
      --i;
    }
  }
  if (decimals > 0) *--p = '.';
  while (r >= 100) {
    p -= 2;
    std::memcpy(p, kPairs + 2 * (r % 100), 2);
    r /= 100;
  }
  if (r >= 10) {
    p -= 2;
    std::memcpy(p, kPairs + 2 * r, 2);
  } else {
    *--p = static_cast<char>('0' + r);
  }
  std::size_t pos = 0;
  if (std::signbit(value)) out[pos++] = '-';
  const auto n = static_cast<std::size_t>(end - p);   // at most 26: 16 whole digits, '.', 9 decimals
  std::memcpy(out + pos, p, 32);
  pos += n;
  out[pos] = '\0';
  return pos;
}

void append_fixed(std::string& s, double value, int decimals) {
  char buf[kFixedBufferSize];
  std::size_t n = format_fixed(buf, value, decimals);
  s.append(buf, n);
}

}  // namespace opencnc
