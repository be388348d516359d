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
constexpr std::uint64_t kPow10i[] = {1,      10,      100,      1000,      10000,
                                     100000, 1000000, 10000000, 100000000, 1000000000};
}  // namespace

std::size_t format_fixed(char* out, double value, int decimals) noexcept {
  if (decimals < 0) decimals = 0;
  if (decimals > 9) decimals = 9;
  const double mag = std::fabs(value);
  const double scaled = mag * kPow10[decimals];
  // printf rounds the exact binary value; `scaled` carries at most ~1 ulp of error, so only
  // values whose fraction lies within a few ulps of one half need the C library to decide.
  const double fraction = scaled - std::floor(scaled);
  const double window = 1e-7 + scaled * 1e-15;
  if (!(scaled < 9e15) || std::fabs(fraction - 0.5) < window) {
    int n = std::snprintf(out, kFixedBufferSize, "%.*f", decimals, value);
    return n > 0 ? static_cast<std::size_t>(n) : 0;
  }
  const std::uint64_t r = static_cast<std::uint64_t>(std::floor(scaled + 0.5));
  std::uint64_t int_part = r / kPow10i[decimals];
  std::uint64_t frac_part = r % kPow10i[decimals];

  // Digits right to left, two at a time.
  static constexpr char kPairs[] =
      "0001020304050607080910111213141516171819202122232425262728293031323334353637383940414243444546474849"
      "5051525354555657585960616263646566676869707172737475767778798081828384858687888990919293949596979899";
  char digits[32];
  char* p = digits + sizeof digits;
  for (int i = decimals; i > 0;) {
    if (i >= 2) {
      p -= 2;
      std::memcpy(p, kPairs + 2 * (frac_part % 100), 2);
      frac_part /= 100;
      i -= 2;
    } else {
      *--p = static_cast<char>('0' + frac_part % 10);
      frac_part /= 10;
      --i;
    }
  }
  if (decimals > 0) *--p = '.';
  while (int_part >= 100) {
    p -= 2;
    std::memcpy(p, kPairs + 2 * (int_part % 100), 2);
    int_part /= 100;
  }
  if (int_part >= 10) {
    p -= 2;
    std::memcpy(p, kPairs + 2 * int_part, 2);
  } else {
    *--p = static_cast<char>('0' + int_part);
  }
  std::size_t pos = 0;
  if (std::signbit(value)) out[pos++] = '-';
  const auto n = static_cast<std::size_t>(digits + sizeof digits - p);
  std::memcpy(out + pos, p, n);
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
