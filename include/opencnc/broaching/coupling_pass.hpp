// SPDX-License-Identifier: GPL-3.0-or-later
// The coupling pass: while a program's coupling code (M171-M174) holds, every move's slave
// coordinate becomes the law's, so the planner sees the slave through the law; moves the law
// would drive past the slave's limits are refused at their line.
#pragma once

#include "opencnc/canon/program.hpp"
#include "opencnc/config/machine_profile.hpp"
#include "opencnc/controller/extensions.hpp"
#include "opencnc/core/diagnostic.hpp"
#include "opencnc/motion/coupling.hpp"

namespace opencnc::broaching {

/// The machine's coupling and the limits the pass checks the slave against.
struct CoupledAxes {
  motion::CouplingConfig config;  ///< enabled = false: no coupling on this machine
  double master_velocity = 0;     ///< mm/s the planner allows the master
  double slave_velocity = 0;      ///< deg/s the planner allows the slave
  double slave_acceleration = 0;  ///< deg/s²
  bool slave_wrapped = false;
  double slave_min = 0, slave_max = 0;  ///< soft limits (unless wrapped)
  bool any() const noexcept { return config.enabled; }
};

/// The coupling of `profile` with the planner's limits of its axes. Any thread; non-real-time.
CoupledAxes coupled_axes(const config::MachineProfile& profile);

/// Rewrites the moves of a program as they are appended: while a coupling code holds, the slave's
/// end coordinate of each move is the law's value at the master's end (origin: where the code
/// stands, as in the tick), so the planner limits the slave by the chord — exact for a constant
/// pitch. After M175 the slave stays where the law left it until the program moves it (a slave
/// word is then absolute, as programmed). Refused, at the move's line (code control.coupling):
/// a slave word, a probe, a rigid tap or a spindle-synchronised move while coupled; a table the
/// machine lacks; the slave beyond its soft limits; a pitch that reaches 0 along the move; a move
/// on which the law's slope or curvature would take the slave past its velocity or past 5 % of
/// its acceleration at the fastest the planner may run it (the planner sees the chord only).
/// Non-real-time; one thread (the program's builder's).
class CouplingPass final : public controller::MovePass {
 public:
  explicit CouplingPass(const CoupledAxes& axes) : axes_(axes) {}

  /// Handles the moves (and the coupling actions before them) appended since the last call.
  void process(canon::Program& program) override;
  /// A new leg (a new window numbered from 0, starting where the machine stands).
  void restart() noexcept override { started_ = false; }
  const Diagnostics& failures() const noexcept override { return failures_; }
  /// The law in force after the moves handled so far (kind Off: uncoupled).
  const motion::CouplingLaw& law() const noexcept { return law_; }

 private:
  void take_actions(canon::Program& program, std::size_t before_move);
  void engage(const canon::Program& program, const canon::Action& a);
  void process_move(canon::Program& program, canon::SegmentId id);
  void check_move(const canon::Program& program, canon::SegmentId id, double d0, double d1);
  double master_speed_bound(const canon::Program& program, canon::SegmentId id, double chord_slope) const;
  void fail(const canon::Program& program, std::uint32_t context, std::uint32_t line, std::string message);

  CoupledAxes axes_;
  bool started_ = false;
  std::size_t next_ = 0, next_action_ = 0;
  motion::CouplingLaw law_{};
  double master_origin_ = 0, slave_origin_ = 0;
  double programmed_slave_ = 0;  ///< the slave coordinate the program asked for last
  double slave_shift_ = 0;       ///< machine − programmed slave since M175 (until the program moves it)
  Diagnostics failures_;
};

}  // namespace opencnc::broaching
