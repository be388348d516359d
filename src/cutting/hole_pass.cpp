// SPDX-License-Identifier: GPL-3.0-or-later
// The holes pass over the canonical calls: a small closed cut slowed, its height held, the
// overcut added and the torch put out before the end (docs/cutting.md, "Holes").
#include "opencnc/cutting/hole_pass.hpp"

#include <algorithm>
#include <cmath>

#include "opencnc/canon/arc_geometry.hpp"
#include "opencnc/machine/plasma.hpp"

namespace opencnc::cutting {

namespace {

/// Points closer than this (program units) are the same point: a contour closes on them.
constexpr double kSamePoint = 1e-4;
/// Pieces shorter than this (program units) are not handed on.
constexpr double kMinPiece = 1e-6;

double dist_xy(const Pose& a, const Pose& b) {
  return std::hypot(b[0] - a[0], b[1] - a[1]);
}

}  // namespace

/// A call held back: a block's origin, a feed, or a move (with where it starts).
struct HolePass::Held {
  enum class Kind { Block, Feed, Line, Arc } kind = Kind::Block;
  canon::BlockOrigin origin{};
  double rate = 0;
  canon::SegmentId id = 0;
  Pose start{}, end{};
  canon::ArcFeed arc{};
};

/// A move as geometry in the XY plane, to be cut in pieces by length.
struct HolePass::Piece {
  bool arc = false;
  canon::SegmentId id = 0;
  Pose start{}, end{};
  double cx = 0, cy = 0, r = 0, a0 = 0, sweep = 0;  ///< arcs: centre, radius, start angle, signed sweep
  double length = 0;

  static Piece of(const Held& h) {
    Piece p;
    p.id = h.id;
    p.start = h.start;
    p.end = h.end;
    if (h.kind == Held::Kind::Line) {
      p.length = dist_xy(h.start, h.end);
      return p;
    }
    p.arc = true;
    p.cx = h.arc.first_center;
    p.cy = h.arc.second_center;
    p.r = std::hypot(h.start[0] - p.cx, h.start[1] - p.cy);
    p.a0 = std::atan2(h.start[1] - p.cy, h.start[0] - p.cx);
    const double a1 = std::atan2(h.end[1] - p.cy, h.end[0] - p.cx);
    const double phi = std::remainder(a1 - p.a0, 2 * std::numbers::pi);
    p.sweep = canon::arc_sweep(phi, h.arc.rotation);
    p.length = std::fabs(p.sweep) * p.r;
    return p;
  }

  /// The point at length `s` from the start (other axes in proportion).
  Pose at(double s) const {
    const double f = length > 0 ? std::clamp(s / length, 0.0, 1.0) : 1.0;
    Pose q = start;
    for (int i = 0; i < kAxisCount; ++i) q[i] = start[i] + f * (end[i] - start[i]);
    if (arc) {
      const double a = a0 + f * sweep;
      q[0] = cx + r * std::cos(a);
      q[1] = cy + r * std::sin(a);
    }
    if (f == 1.0) q = end;
    return q;
  }

  /// The same path the other way.
  Piece reversed() const {
    Piece p = *this;
    std::swap(p.start, p.end);
    if (arc) {
      p.a0 = a0 + sweep;
      p.sweep = -sweep;
    }
    return p;
  }

  /// The piece from length `s0` to `s1`.
  Piece between(double s0, double s1) const {
    Piece p = *this;
    p.start = at(s0);
    p.end = at(s1);
    p.length = s1 - s0;
    if (arc) {
      p.a0 = a0 + (length > 0 ? s0 / length : 0) * sweep;
      p.sweep = (length > 0 ? (s1 - s0) / length : 0) * sweep;
    }
    return p;
  }
};

HolePass::HolePass(const config::PlasmaHoles& holes) : holes_cfg_(holes) {}
HolePass::~HolePass() = default;

void HolePass::flush() {
  in_cut_ = false;
  std::vector<Held> held;
  held.swap(held_);
  for (const Held& h : held) {
    switch (h.kind) {
      case Held::Kind::Block:
        next_->begin_block(h.origin);
        break;
      case Held::Kind::Feed:
        feed_ = h.rate;
        next_->set_feed_rate(h.rate);
        break;
      case Held::Kind::Line:
        next_->straight_feed(h.id, h.end);
        break;
      case Held::Kind::Arc:
        next_->arc_feed(h.id, h.arc);
        break;
    }
  }
}

void HolePass::use_length_units(canon::Units units) {
  flush();
  units_ = units;
  next_->use_length_units(units);
}

void HolePass::select_plane(canon::Plane plane) {
  flush();
  plane_ = plane;
  next_->select_plane(plane);
}

void HolePass::set_feed_mode(int spindle, canon::FeedMode mode) {
  flush();
  feed_mode_ = mode;
  next_->set_feed_mode(spindle, mode);
}

void HolePass::set_feed_rate(double rate) {
  if (in_cut_) {
    Held h;
    h.kind = Held::Kind::Feed;
    h.rate = rate;
    held_.push_back(h);
    return;
  }
  feed_ = rate;
  next_->set_feed_rate(rate);
}

void HolePass::begin_block(const canon::BlockOrigin& origin) {
  if (in_cut_) {
    Held h;
    h.kind = Held::Kind::Block;
    h.origin = origin;
    held_.push_back(h);
    return;
  }
  next_->begin_block(origin);
}

void HolePass::straight_traverse(canon::SegmentId id, const Pose& end) {
  flush();
  pos_ = end;
  has_pos_ = true;
  next_->straight_traverse(id, end);
}

void HolePass::straight_feed(canon::SegmentId id, const Pose& end) {
  Held h;
  h.kind = Held::Kind::Line;
  h.id = id;
  h.start = pos_;
  h.end = end;
  pos_ = end;
  if (hold(h)) return;
  next_->straight_feed(id, end);
}

void HolePass::arc_feed(canon::SegmentId id, const canon::ArcFeed& arc) {
  Held h;
  h.kind = Held::Kind::Arc;
  h.id = id;
  h.start = pos_;
  h.end = arc.end;
  h.arc = arc;
  pos_ = arc.end;
  if (hold(h)) return;
  next_->arc_feed(id, arc);
}

bool HolePass::hold(const Held& h) {
  if (!in_cut_) return false;
  // Only whole turns at most, in the XY plane: the pieces below are cut in it.
  if (h.kind == Held::Kind::Arc && (plane_ != canon::Plane::XY || std::abs(h.arc.rotation) > 1)) {
    flush();
    return false;
  }
  const Piece p = Piece::of(h);
  constexpr int kSamples = 32;
  for (int i = 0; i <= kSamples; ++i) {
    const Pose q = p.at(p.length * i / kSamples);
    for (int k = 0; k < 2; ++k) {
      min_[k] = std::min(min_[k], q[k]);
      max_[k] = std::max(max_[k], q[k]);
    }
  }
  const double diameter = holes_cfg_.diameter_mm / canon::mm_per_unit(units_);
  if (max_[0] - min_[0] > diameter + kSamePoint || max_[1] - min_[1] > diameter + kSamePoint) {
    flush();  // no hole: this cut is handed on as programmed
    return false;
  }
  held_.push_back(h);
  return true;
}

void HolePass::process_code(const canon::ProcessCode& code) {
  if (in_cut_ && code.code == machine::kTorchOffCode) {
    hand_on_as_hole(code);
    return;
  }
  flush();
  next_->process_code(code);
  const bool can_hold = has_pos_ && holes_cfg_.diameter_mm > 0 && plane_ == canon::Plane::XY &&
                        feed_mode_ == canon::FeedMode::UnitsPerMinute;
  if (code.code == machine::kTorchOnCode && can_hold) {
    in_cut_ = true;
    min_[0] = max_[0] = pos_[0];
    min_[1] = max_[1] = pos_[1];
  }
}

void HolePass::emit_piece(const Piece& p) {
  if (p.length < kMinPiece) return;
  if (!p.arc) {
    next_->straight_feed(p.id, p.end);
    return;
  }
  canon::ArcFeed a;
  a.plane = canon::Plane::XY;
  a.first_end = p.end[0];
  a.second_end = p.end[1];
  a.first_center = p.cx;
  a.second_center = p.cy;
  a.rotation = p.sweep >= 0 ? 1 : -1;
  a.axis_end = p.end[2];
  a.end = p.end;
  next_->arc_feed(p.id, a);
}

void HolePass::hand_on_as_hole(const canon::ProcessCode& torch_off) {
  // The contour: the last move ends where move k starts (the first such k, after the lead-in).
  std::vector<std::size_t> moves;
  for (std::size_t i = 0; i < held_.size(); ++i)
    if (held_[i].kind == Held::Kind::Line || held_[i].kind == Held::Kind::Arc) moves.push_back(i);
  std::size_t loop = moves.size();
  if (!moves.empty()) {
    const Pose& last = held_[moves.back()].end;
    for (std::size_t k = 0; k < moves.size(); ++k)
      if (dist_xy(held_[moves[k]].start, last) < kSamePoint) {
        loop = k;
        break;
      }
  }
  if (loop == moves.size()) {  // not closed: an ordinary small cut
    flush();
    next_->process_code(torch_off);
    return;
  }
  in_cut_ = false;
  const double share = holes_cfg_.speed_share;
  const double programmed_feed = feed_;
  // The overcut: the contour again from its start, for overcut_mm.
  std::vector<Piece> over;
  const double overcut = holes_cfg_.overcut_mm / canon::mm_per_unit(units_);
  double loop_length = 0;
  for (std::size_t k = loop; k < moves.size(); ++k) loop_length += Piece::of(held_[moves[k]]).length;
  const canon::SegmentId last_id = held_[moves.back()].id;
  for (double left = overcut; left > kMinPiece && loop_length > kMinPiece;) {
    for (std::size_t k = loop; k < moves.size() && left > kMinPiece; ++k) {
      Piece p = Piece::of(held_[moves[k]]);
      p.id = last_id;  // pieces of the last segment: the builder notes the split
      const double take = std::min(left, p.length);
      over.push_back(p.between(0, take));
      left -= take;
    }
  }
  double total = 0;
  for (std::size_t i : moves) total += Piece::of(held_[i]).length;
  for (const Piece& p : over) total += p.length;
  double lead = 0;
  for (std::size_t k = 0; k < loop; ++k) lead += Piece::of(held_[moves[k]]).length;
  const double arc_off = holes_cfg_.arc_off_mm / canon::mm_per_unit(units_);
  const double off_at = std::max(lead, total - arc_off);  // where the torch goes out

  canon::ProcessCode hold_height;
  hold_height.code = machine::kThcHoldCode;
  hold_height.group = machine::kThcHoldCode;
  next_->process_code(hold_height);
  next_->set_feed_rate(programmed_feed * share);

  double done = 0;
  bool off = false;
  auto cut = [&](const Piece& p) {
    if (!off && done + p.length >= off_at - kMinPiece) {
      const double s = std::clamp(off_at - done, 0.0, p.length);
      emit_piece(p.between(0, s));
      next_->process_code(torch_off);
      off = true;
      emit_piece(p.between(s, p.length));
    } else {
      emit_piece(p);
    }
    done += p.length;
  };
  std::vector<Held> held;
  held.swap(held_);
  const std::size_t last_move = moves.back();
  for (std::size_t i = 0; i <= last_move; ++i) {
    const Held& h = held[i];
    if (h.kind == Held::Kind::Block) {
      next_->begin_block(h.origin);
    } else if (h.kind == Held::Kind::Feed) {
      feed_ = h.rate;
      next_->set_feed_rate(h.rate * share);
    } else {
      cut(Piece::of(h));
    }
  }
  for (const Piece& p : over) cut(p);
  if (!off) next_->process_code(torch_off);
  // Back along the overcut, the torch out, to where the program's contour ended: the interpreter
  // goes on from there (an arc after the hole starts where it thinks), and the way back stays in
  // the kerf just cut.
  for (auto p = over.rbegin(); p != over.rend(); ++p) emit_piece(p->reversed());
  for (std::size_t i = last_move + 1; i < held.size(); ++i) {
    if (held[i].kind == Held::Kind::Block) next_->begin_block(held[i].origin);
    if (held[i].kind == Held::Kind::Feed) feed_ = held[i].rate;
  }
  canon::ProcessCode release;
  release.code = machine::kThcReleaseCode;
  release.group = machine::kThcHoldCode;
  next_->process_code(release);
  next_->set_feed_rate(feed_);
  pos_ = held[last_move].end;
  ++holes_;
}

}  // namespace opencnc::cutting
