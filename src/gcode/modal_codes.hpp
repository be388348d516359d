// SPDX-License-Identifier: GPL-3.0-or-later
// ModalCodes — the modal settings of one engine's blocks: spindle and feed modes, plane, lathe
// diameter mode, cutter compensation off, path control, distance modes, canned cycle return
// (modal_codes.cpp).
#pragma once

namespace opencnc::gcode {

class Engine;

/// Sets the modes a block's codes name (`code`: the G code ×10). Reaches the engine's state
/// through `e_` (a friend of the engine). Interpreter thread.
class ModalCodes {
 public:
  explicit ModalCodes(Engine& e) noexcept : e_(e) {}
  ModalCodes(const ModalCodes&) = delete;
  ModalCodes& operator=(const ModalCodes&) = delete;

  void set_spindle_mode();  ///< G96, G97
  void set_feed_mode(int code);
  void set_plane(int code);
  void set_lathe_mode(int code);  ///< G7, G8
  void set_cutter_comp(int code);
  void set_control_mode(int code);  ///< G61, G61.1, G64
  void set_distance_mode(int code);
  void set_ijk_mode(int code);
  void set_retract_mode(int code);

 private:
  Engine& e_;
};

}  // namespace opencnc::gcode
