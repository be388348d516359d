// SPDX-License-Identifier: GPL-3.0-or-later
// Compensation — the servo tick's per-joint correction of lead-screw pitch error and backlash,
// applied to the commanded position after interpolation and before the drives.
#pragma once

#include <array>
#include <cstdint>
#include <type_traits>

namespace opencnc::motion {

/// Joints a Compensation serves (the machine layer's kMaxJoints).
inline constexpr int kMaxCompensatedJoints = 9;
/// Most points of one pitch-error table (LinuxCNC allows as many per joint).
inline constexpr int kMaxPitchPoints = 256;

/// A lead-screw error table of one joint: at machine position `position[i]` the axis stands
/// `forward[i]` (moving in +) or `reverse[i]` (moving in −) off where it was told to be
/// (actual − nominal, units). Linear between points, the end values held beyond the ends.
/// Positions strictly increase; a table measured one way only has forward == reverse.
struct PitchTable {
  int count = 0;  ///< points in use; 0 = no table
  std::array<double, kMaxPitchPoints> position{};
  std::array<double, kMaxPitchPoints> forward{};
  std::array<double, kMaxPitchPoints> reverse{};
};

/// What one joint is corrected for.
struct JointCompensation {
  bool enabled = false;
  PitchTable pitch;
  double backlash = 0;  ///< lost motion on reversal, units
  /// Limits of the correction's own motion (the take-up of a reversal, the pitch table switched
  /// on at homing): units/s and units/s². The planner keeps this much of the axis' limits free.
  double max_velocity = 0;
  double max_acceleration = 0;
};

/// Plain fixed-size data (it travels inside the servo's configuration).
struct CompensationConfig {
  double period_s = 1e-3;
  std::array<JointCompensation, kMaxCompensatedJoints> joints{};
};

static_assert(std::is_trivially_copyable_v<CompensationConfig>);

/// Error of `table` at `x` for a motion in `direction` (+1, −1; 0 = the mean of both tables).
/// Any thread; real-time safe. `segment` is a hint (the segment found last time) and is updated,
/// so a slowly moving axis costs O(1); the result does not depend on it.
double pitch_error(const PitchTable& table, double x, int direction, int& segment) noexcept;

/// The compensation stage. Per joint, the correction added to the command is
///
///     c = target + u,   target = −E_dir(x) + dir · backlash / 2
///
/// where x is the commanded machine position, dir the direction of the joint's last commanded
/// motion (from joint positions, so that homing's change of the offset is not a motion) and E_dir
/// the pitch table of that direction (only while the joint is homed: the table is measured from
/// the origin). Whenever the target jumps — a reversal, the table switched on — u takes the jump so
/// that c stays continuous, and then runs back to 0 with |u̇| ≤ max_velocity and |ü| ≤
/// max_acceleration, stopping exactly at 0 (a braking curve kept from period to period). The
/// target itself moves with x at no more than the table's slope times the axis' speed.
/// Fixed-size; every member is real-time safe, noexcept, allocation-free.
class Compensation {
 public:
  Compensation() = default;
  /// Setup thread.
  explicit Compensation(const CompensationConfig& config) noexcept : config_(config) {}

  /// One period of joint `j` commanded to `joint_position` (before correction), which is machine
  /// position joint_position + offset; `homed`: the pitch table applies. Returns the correction
  /// to add to the joint command. Servo thread.
  double update(int j, double joint_position, double offset, bool homed) noexcept;

  /// Joint `j`'s backlash and take-up limits changed (an admin's edit while it stands): the
  /// correction stays where it is and the change of its target is taken up within the new
  /// limits, as a reversal's is. Servo thread; real-time safe.
  void set_backlash(int j, double backlash, double max_velocity, double max_acceleration) noexcept;
  /// Joint `j`'s pitch-error table is now `*table` (an admin's edit while it stands; the table is
  /// the caller's and must stay unchanged while in use: the channels' double-buffered area). The
  /// correction stays where it is and the change of its target at the joint's position is taken
  /// up within the take-up limits, as a reversal's is. Servo thread; real-time safe.
  void set_pitch_table(int j, const PitchTable* table) noexcept;
  /// The pitch-error table joint `j` uses now (the configuration's, or the last set_pitch_table()).
  /// Servo thread.
  const PitchTable& pitch_table(int j) const noexcept {
    const PitchTable* t = tables_[index(j)];
    return t ? *t : config_.joints[index(j)].pitch;
  }
  /// The correction of the last update(). Servo thread.
  double correction(int j) const noexcept { return state_[index(j)].correction; }
  /// Direction of the last motion: +1, −1, 0 before the first. Servo thread.
  int direction(int j) const noexcept { return state_[index(j)].direction; }
  /// What is still to be taken up (u above). Servo thread.
  double pending(int j) const noexcept { return state_[index(j)].take_up; }
  bool enabled(int j) const noexcept { return config_.joints[index(j)].enabled; }
  const CompensationConfig& config() const noexcept { return config_; }

 private:
  struct JointState {
    bool started = false;
    double last_position = 0;  // joint coordinates
    double last_x = 0;         // machine coordinates (the table's)
    int direction = 0;
    bool homed = false;
    double target = 0;
    double take_up = 0;           // u
    double take_up_velocity = 0;  // du/dt
    double correction = 0;
    int segment = 0;
  };
  static std::size_t index(int j) noexcept { return static_cast<std::size_t>(j); }
  double target(int j, double x) noexcept;
  void run_take_up(JointState& s, const JointCompensation& c) const noexcept;

  CompensationConfig config_{};
  std::array<JointState, kMaxCompensatedJoints> state_{};
  /// Tables set by set_pitch_table() (nullptr: the configuration's own). Not owned.
  std::array<const PitchTable*, kMaxCompensatedJoints> tables_{};
};

}  // namespace opencnc::motion
