// SPDX-License-Identifier: GPL-3.0-or-later
// Offsets — units and the coordinate transforms of one engine: coordinate systems (G54..G59.3,
// G10 L2/L20), axis offsets (G52, G92 family), reference points (G28/G30), tool offsets (G43
// family, G49, G10 L1/L10/L11) (offsets.cpp).
#pragma once

#include "opencnc/core/axes.hpp"

namespace opencnc::gcode {

class Engine;

/// Converts between machine and program coordinates and runs the codes that change them.
/// Reaches the engine's state through `e_` (a friend of the engine). Interpreter thread.
class Offsets {
 public:
  explicit Offsets(Engine& e) noexcept : e_(e) {}
  Offsets(const Offsets&) = delete;
  Offsets& operator=(const Offsets&) = delete;

  void set_units(int code);  ///< G20, G21
  void set_coordinate_system(int code);
  void tool_length_offset(int code);
  /// The non-modal group: G10, G28/G30 and .1, G52, G92 family.
  void convert_modal_0(int code);
  Pose machine_to_program(const Pose& machine_user) const;
  Pose program_to_machine(const Pose& program) const;  ///< machine_to_program's inverse
  /// A length in the user's units (Options::user_units) in the program's.
  double user_to_program(double v) const noexcept { return v * user_to_program_factor_; }
  void update_unit_factor() noexcept;
  /// A G20 or G21 was met: the program does not rely on the machine's default units.
  bool units_programmed() const noexcept { return units_programmed_; }

 private:
  void g10_coordinate_system();
  void g10_tool();
  void axis_offsets(int code);
  void go_home(int code);
  void save_home(int code);
  Pose current_in_system(int system, bool without_tlo) const;
  double program_to_user(double v) const noexcept { return v / user_to_program_factor_; }

  Engine& e_;
  double user_to_program_factor_ = 1.0;
  bool units_programmed_ = false;
};

}  // namespace opencnc::gcode
