// SPDX-License-Identifier: GPL-3.0-or-later
// Fast fixed-point formatting of doubles, byte-identical to printf("%.Nf").
#pragma once

#include <cstddef>
#include <string>

namespace opencnc {

inline constexpr std::size_t kFixedBufferSize = 352;

/// Writes `value` with `decimals` digits after the point (0..9) into `out`, exactly as
/// printf("%.*f") would, and returns the number of characters written. `out` must hold at
/// least kFixedBufferSize characters (enough for the largest double). Falls back to snprintf where rounding is too close to call, so the
/// result always matches the C library. Any thread; real-time safe.
std::size_t format_fixed(char* out, double value, int decimals) noexcept;

/// Appends the same text to `s`. Any thread; allocates.
void append_fixed(std::string& s, double value, int decimals);

}  // namespace opencnc
