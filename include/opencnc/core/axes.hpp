// SPDX-License-Identifier: GPL-3.0-or-later
// Axis names, axis masks and the nine-axis pose used by every layer.
#pragma once

#include <array>
#include <cstdint>
#include <string_view>

namespace opencnc {

/// The nine RS274/NGC axes in canonical order. Linear axes in mm (or program units
/// where a name says so), rotary axes (A, B, C) in degrees.
enum class Axis : std::uint8_t { X, Y, Z, A, B, C, U, V, W };

inline constexpr int kAxisCount = 9;
inline constexpr std::string_view kAxisLetters = "XYZABCUVW";

constexpr int index(Axis a) noexcept { return static_cast<int>(a); }
constexpr char letter(Axis a) noexcept { return kAxisLetters[static_cast<std::size_t>(a)]; }
constexpr bool is_rotary(Axis a) noexcept { return a == Axis::A || a == Axis::B || a == Axis::C; }

/// A set of axes, bit i = Axis(i). Plain data; real-time safe.
class AxisMask {
 public:
  constexpr AxisMask() noexcept = default;
  constexpr explicit AxisMask(std::uint16_t bits) noexcept : bits_(bits) {}
  /// Parses letters such as "XYZ" or "xyzc"; unknown letters are ignored.
  static constexpr AxisMask from_letters(std::string_view letters) noexcept {
    std::uint16_t b = 0;
    for (char ch : letters) {
      char up = (ch >= 'a' && ch <= 'z') ? static_cast<char>(ch - 'a' + 'A') : ch;
      auto pos = kAxisLetters.find(up);
      if (pos != std::string_view::npos) b = static_cast<std::uint16_t>(b | (1u << pos));
    }
    return AxisMask(b);
  }
  static constexpr AxisMask all() noexcept { return AxisMask(0x1FF); }

  constexpr bool has(Axis a) const noexcept { return (bits_ >> index(a)) & 1u; }
  constexpr void set(Axis a) noexcept { bits_ = static_cast<std::uint16_t>(bits_ | (1u << index(a))); }
  constexpr int count() const noexcept {
    int n = 0;
    for (int i = 0; i < kAxisCount; ++i) n += (bits_ >> i) & 1;
    return n;
  }
  constexpr std::uint16_t bits() const noexcept { return bits_; }
  constexpr bool operator==(const AxisMask&) const noexcept = default;

 private:
  std::uint16_t bits_ = 0;
};

/// XYZABC: the axes LinuxCNC's standalone interpreter (rs274) knows.
inline constexpr AxisMask kXyzabc = AxisMask(0x3F);

/// A position on all nine axes. Plain data; real-time safe.
struct Pose {
  std::array<double, kAxisCount> v{};

  constexpr double& operator[](Axis a) noexcept { return v[static_cast<std::size_t>(a)]; }
  constexpr double operator[](Axis a) const noexcept { return v[static_cast<std::size_t>(a)]; }
  constexpr double& operator[](int i) noexcept { return v[static_cast<std::size_t>(i)]; }
  constexpr double operator[](int i) const noexcept { return v[static_cast<std::size_t>(i)]; }
  constexpr double x() const noexcept { return v[0]; }
  constexpr double y() const noexcept { return v[1]; }
  constexpr double z() const noexcept { return v[2]; }
  constexpr bool operator==(const Pose&) const noexcept = default;
};

}  // namespace opencnc
