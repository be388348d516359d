// SPDX-License-Identifier: GPL-3.0-or-later
// The holes pass: a cut (M190 … M191) whose path closes on itself within the hole diameter is cut
// at a share of its feed with the height held, goes on past its end by the overcut, and the torch
// goes out before the end (QtPlasmaC's hole settings; docs/cutting.md, "Holes").
#pragma once

#include <memory>
#include <vector>

#include "opencnc/config/machine_profile.hpp"
#include "opencnc/controller/extensions.hpp"

namespace opencnc::cutting {

/// A pass over the canonical calls (controller::CallPass) that holds a cut's calls from M190 on
/// while its path stays within `holes.diameter_mm` across; at M191, a cut whose last move ends
/// on the start of one of its moves (a closed contour: a full circle, a closed polyline, after
/// any lead-in) is handed on as a hole: M192 after the torch's M190, every feed times
/// `speed_share`, the contour followed on for `overcut_mm` past its end, M191 `arc_off_mm` before
/// the end of that, then M193 and the feed as programmed. Other cuts are handed on unchanged.
/// XY-plane cuts in units per minute only. The builder's thread; not real-time.
class HolePass final : public controller::CallPass {
 public:
  explicit HolePass(const config::PlasmaHoles& holes);
  ~HolePass() override;

  /// Holes handed on as holes so far.
  int holes() const noexcept { return holes_; }

  void flush() override;

  void use_length_units(canon::Units units) override;
  void select_plane(canon::Plane plane) override;
  void set_feed_mode(int spindle, canon::FeedMode mode) override;
  void set_feed_rate(double rate) override;
  void begin_block(const canon::BlockOrigin& origin) override;
  void straight_traverse(canon::SegmentId id, const Pose& end) override;
  void straight_feed(canon::SegmentId id, const Pose& end) override;
  void arc_feed(canon::SegmentId id, const canon::ArcFeed& arc) override;
  void process_code(const canon::ProcessCode& code) override;

 protected:
  void before_call() override { flush(); }

 private:
  struct Held;
  struct Piece;
  /// Holds a move of a cut while its path stays within the diameter; false: hand it on.
  bool hold(const Held& h);
  void hand_on_as_hole(const canon::ProcessCode& torch_off);
  void emit_piece(const Piece& p);

  config::PlasmaHoles holes_cfg_;
  canon::Units units_ = canon::Units::Mm;
  canon::Plane plane_ = canon::Plane::XY;
  canon::FeedMode feed_mode_ = canon::FeedMode::UnitsPerMinute;
  double feed_ = 0;  ///< the feed in force as handed on
  Pose pos_{};       ///< where the last move ended (program coordinates)
  bool has_pos_ = false;
  bool in_cut_ = false;  ///< after M190, holding
  std::vector<Held> held_;
  double min_[2] = {0, 0}, max_[2] = {0, 0};
  int holes_ = 0;
};

}  // namespace opencnc::cutting
