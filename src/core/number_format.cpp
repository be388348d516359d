// SPDX-License-Identifier: GPL-3.0-or-later
// Fixed-point formatting: integer arithmetic on the scaled value, snprintf near ties.
#include "opencnc/core/number_format.hpp"

#include <cmath>
#include <cstdint>
#include <cstdio>

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
  std::uint64_t r = static_cast<std::uint64_t>(std::floor(scaled + 0.5));
  const std::uint64_t int_part = r / kPow10i[decimals];
  std::uint64_t frac_part = r % kPow10i[decimals];

  char digits[24];
  int nd = 0;
  std::uint64_t ip = int_part;
  do {
    digits[nd++] = static_cast<char>('0' + ip % 10);
    ip /= 10;
  } while (ip != 0);

  std::size_t pos = 0;
  if (std::signbit(value)) out[pos++] = '-';
  while (nd > 0) out[pos++] = digits[--nd];
  if (decimals > 0) {
    out[pos++] = '.';
    for (int i = decimals - 1; i >= 0; --i) {
      out[pos + static_cast<std::size_t>(i)] = static_cast<char>('0' + frac_part % 10);
      frac_part /= 10;
    }
    pos += static_cast<std::size_t>(decimals);
  }
  out[pos] = '\0';
  return pos;
}

void append_fixed(std::string& s, double value, int decimals) {
  char buf[kFixedBufferSize];
  std::size_t n = format_fixed(buf, value, decimals);
  s.append(buf, n);
}

}  // namespace opencnc
