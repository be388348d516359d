// SPDX-License-Identifier: GPL-3.0-or-later
// CouplingLaw — a slave axis as a function of a master axis (helix of constant or variable pitch,
// tabulated cam), evaluated by the servo tick's coupling stage and checked by the preflight.
#pragma once

#include <array>
#include <cstdint>
#include <type_traits>
#include <utility>

namespace opencnc::motion {

/// Most points of one coupling table (pitch table or cam).
inline constexpr int kMaxCouplingPoints = 64;
/// Most tables a machine profile may define.
inline constexpr int kMaxCouplingTables = 8;

/// The shape of the law. Every law gives the slave's offset (degrees for a rotary slave) from the
/// point of engagement as a function of the master's offset d (mm) from it, for d of either sign.
enum class CouplingKind : std::uint8_t {
  Off,
  ConstantPitch,  ///< s = 360·d/p (p mm per revolution; negative p: a left-hand helix)
  LinearPitch,    ///< p(d) = p0 + k·d, s = 360·∫₀ᵈ dz/p(z) = (360/k)·ln(p(d)/p0)
  PitchTable,     ///< p(d) linear between table points (the end pitches held beyond), s = 360·∫dz/p
  Cam,            ///< s(d) = v(d) − v(0), v a cubic Hermite through the table points (C1; linear beyond)
};

/// A table of the profile: `master` offsets (mm, strictly increasing) and `value`s (pitch in mm per
/// revolution for a pitch table, slave offsets in degrees for a cam). Plain data.
struct CouplingTable {
  int count = 0;
  std::array<double, kMaxCouplingPoints> master{};
  std::array<double, kMaxCouplingPoints> value{};
};

/// One law with its own copy of the table and what prepare() derives from it (the integral of a
/// pitch table at each point, a cam's slopes). Plain fixed-size data: the servo copies it when a
/// program engages the coupling.
class CouplingLaw {
 public:
  CouplingLaw() = default;
  /// A helix of constant pitch `pitch_mm` (≠ 0). Any thread; RT-safe.
  static CouplingLaw constant(double pitch_mm) noexcept;
  /// A helix whose pitch goes from `pitch_mm` at the engagement linearly by `rate` mm per mm of
  /// master travel. Any thread; RT-safe.
  static CouplingLaw linear(double pitch_mm, double rate) noexcept;
  /// A pitch table or a cam (`kind` PitchTable or Cam) through the points of `table`. Any thread;
  /// RT-safe (bounded by kMaxCouplingPoints).
  static CouplingLaw tabulated(CouplingKind kind, const CouplingTable& table) noexcept;

  CouplingKind kind() const noexcept { return kind_; }
  bool active() const noexcept { return kind_ != CouplingKind::Off; }
  double pitch_mm() const noexcept { return pitch_; }
  double pitch_rate() const noexcept { return rate_; }
  const CouplingTable& table() const noexcept { return table_; }

  /// Slave offset (degrees) at master offset `d_mm`. Any thread; RT-safe.
  double slave(double d_mm) const noexcept;
  /// ds/dd at `d_mm` (degrees per mm). Any thread; RT-safe.
  double slope(double d_mm) const noexcept;
  /// d²s/dd² at `d_mm` (degrees per mm²; one-sided at a cam's points). Any thread; RT-safe.
  double curvature(double d_mm) const noexcept;
  /// The largest |slope| and |curvature| for master offsets between `a_mm` and `b_mm` (either
  /// order): exact for every kind (the extremes lie at the ends, the table points or, for a cam's
  /// slope, the vertex of its quadratic). Any thread; RT-safe.
  double max_slope(double a_mm, double b_mm) const noexcept;
  double max_curvature(double a_mm, double b_mm) const noexcept;
  /// The smallest and largest slave offset for master offsets between `a_mm` and `b_mm` (either
  /// order; exact: a cam's interior extremes are the roots of its slope). Any thread; RT-safe.
  std::pair<double, double> slave_extent(double a_mm, double b_mm) const noexcept;
  /// Pitch at master offset `d_mm` for the pitch laws (mm per revolution; 0 for a cam). Any thread.
  double pitch_at(double d_mm) const noexcept;

 private:
  int segment(double d) const noexcept;  ///< table segment of d (−1 before the first point)
  double cam_value(double d) const noexcept;
  double pitch_integral(double d) const noexcept;  ///< revolutions from the first point to d

  CouplingKind kind_ = CouplingKind::Off;
  double pitch_ = 0;   ///< constant pitch, or p0 of the linear law
  double rate_ = 0;    ///< dp/dd of the linear law
  double origin_ = 0;  ///< v(0) of a cam, or the pitch integral at 0
  CouplingTable table_{};
  std::array<double, kMaxCouplingPoints> derived_{};  ///< pitch integral (revs) or cam slope at each point
};

static_assert(std::is_trivially_copyable_v<CouplingLaw>);

/// Which master position the tick couples to.
enum class CouplingSource : std::uint8_t {
  Command,  ///< the master's commanded position (the slave follows the path exactly)
  Actual,   ///< the master's feedback (the slave follows where the master really is)
};

/// The machine's coupling, from the profile's [coupling] section: which axes, which master
/// position, and the tables programs may name. Plain fixed-size data (inside ServoConfig).
struct CouplingConfig {
  bool enabled = false;
  std::int8_t master_axis = 2;  ///< Axis index (Z)
  std::int8_t slave_axis = 5;   ///< Axis index (C)
  CouplingSource source = CouplingSource::Command;
  /// A coupling code's law takes master and slave once both stand within these of their commands
  /// (master units, slave degrees; 0: at once), waiting at most `engage_timeout_s`.
  double engage_tolerance_master = 0;
  double engage_tolerance_slave = 0;
  double engage_timeout_s = 2;
  /// Tables by number (1-based in programs: P1 is tables[0]); kind Off = no table there.
  std::array<CouplingKind, kMaxCouplingTables> table_kind{};
  std::array<CouplingTable, kMaxCouplingTables> tables{};
};

/// The law a coupling names by its kind: a constant pitch `pitch_mm`, a linear one from `pitch_mm`
/// changing by `rate` mm per mm, or the machine's table number `table` (1-based) of that kind.
/// Off for kind Off and for a table the machine does not have (or has of the other kind). Any
/// thread; RT-safe.
CouplingLaw law_for(const CouplingConfig& config, CouplingKind kind, double pitch_mm, double rate,
                    int table) noexcept;

}  // namespace opencnc::motion
