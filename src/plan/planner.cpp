// SPDX-License-Identifier: GPL-3.0-or-later
// plan::Planner: program reader → corners (blend, tangent or stop) → block limits → look-ahead →
// queue.
#include "opencnc/plan/planner.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <vector>

#include <fmt/format.h>

#include "planner_impl.hpp"
#include "vec.hpp"

namespace opencnc::plan {

using detail::Element;
using detail::PlannedBlock;
using traj::BlockKind;
using traj::FeedClass;
using traj::MarkerKind;
using traj::MotionBlock;

namespace {

constexpr int kSplitDepth = 3;         ///< a jerk-limited Bézier block becomes at most 2³ blocks
constexpr double kSplitCapGain = 1.3;  ///< halves whose caps differ by more than this are split

bool bad(double v) {
  return !std::isfinite(v);
}

/// Moving-average length in servo periods: T ≥ A/J on every axis, so that an acceleration ramp of
/// the average from 0 to A takes its jerk to J at most (the time-optimal ramp when T = A/J).
int filter_ticks(const MachineLimits& m, double servo_period_s) {
  double t = 0;
  for (int i = 0; i < kAxisCount; ++i) {
    if (!m.axes.has(static_cast<Axis>(i)) || m[i].max_jerk <= 0) continue;
    t = std::max(t, m[i].max_acceleration / m[i].max_jerk);
  }
  if (t <= 0) return 1;
  return std::max(2, static_cast<int>(std::ceil(t / servo_period_s - 1e-9)));
}

}  // namespace

double jerk_filter_s(const MachineLimits& limits, double servo_period_s) noexcept {
  if (!(servo_period_s > 0)) return 0;
  const int ticks = filter_ticks(limits, servo_period_s);
  return ticks > 1 ? ticks * servo_period_s : 0.0;
}

bool validate(const MachineLimits& limits, Diagnostics& diags) {
  bool ok = true;
  for (int i = 0; i < kAxisCount; ++i) {
    if (!limits.axes.has(static_cast<Axis>(i))) continue;
    const AxisLimits& l = limits[i];
    const auto check = [&](double v, bool zero_ok, const char* what) {
      if (bad(v) || v < 0 || (!zero_ok && v == 0)) {
        diags.error("", 0, 0,
                    fmt::format("axis {}: {} must be a positive number, not {}", kAxisLetters[i], what, v),
                    "plan.limits");
        ok = false;
      }
    };
    check(l.max_velocity, false, "max_velocity");
    check(l.max_acceleration, false, "max_acceleration");
    check(l.max_jerk, true, "max_jerk");
  }
  return ok;
}

Planner::Impl::Impl(const MachineLimits& l, const PlannerConfig& c) : limits(l), config(c) {
  check_config();
  if (!config_ok) return;
  ticks = filter_ticks(limits, config.servo_period_s);
  params.machine = limits;
  params.normal_share = config.normal_accel_share;
  params.step_share = config.jerk_step_share;
  params.period_s = config.servo_period_s;
  params.filter_s = ticks > 1 ? ticks * config.servo_period_s : 0.0;
  if (ticks > traj::kMaxFilterTicks) {
    diags.error(
        "", 0, 0,
        fmt::format("the jerk limits need a {:.3f} s moving average, longer than the {} servo periods "
                    "supported; raise max_jerk",
                    params.filter_s, traj::kMaxFilterTicks),
        "plan.config");
    config_ok = false;
  }
}

void Planner::Impl::check_config() {
  config_ok = validate(limits, diags);
  const auto err = [&](const std::string& msg) {
    diags.error("", 0, 0, msg, "plan.config");
    config_ok = false;
  };
  if (bad(config.servo_period_s) || config.servo_period_s <= 0) err("servo_period_s must be positive");
  if (config.lookahead_moves < 2) err("lookahead_moves must be at least 2");
  if (bad(config.max_feed_override) || config.max_feed_override < 1)
    err("max_feed_override must be at least 1");
  if (!(config.normal_accel_share > 0 && config.normal_accel_share < 1))
    err("normal_accel_share must be in (0, 1)");
  if (!(config.jerk_step_share > 0 && config.jerk_step_share < 1)) err("jerk_step_share must be in (0, 1)");
}

double Planner::Impl::commanded_max(const MotionBlock& b) const {
  return b.feed_class == FeedClass::Feed ? b.feed * config.max_feed_override : kInf;
}

// The fastest the corner will be asked to go: the lower of the two moves' top speeds (feed at
// the largest override, or the rapid rate), within the axis velocity limits.
detail::BlendNeed Planner::Impl::blend_need(const MotionBlock& a, const MotionBlock& e) const {
  detail::BlendNeed need;
  need.share = config.normal_accel_share;
  need.speed = std::min(commanded_max(a), commanded_max(e));
  if (!(need.speed < kInf))
    need.speed =
        std::min(detail::block_limits(a, kInf, params).cap, detail::block_limits(e, kInf, params).cap);
  for (int i = 0; i < kAxisCount; ++i) {
    if (limits.axes.has(static_cast<Axis>(i)))
      need.accel[static_cast<std::size_t>(i)] = limits[i].max_acceleration;
  }
  return need;
}

// With jerk limits a Bézier block (a G2 blend, a fitted run) is halved, up to kSplitDepth times,
// where one half's cap is more than kSplitCapGain times the other's: with one cap per block the
// tightest of its 24 pieces held the whole block. Each half must be at least as long as the
// higher cap's reach (c·T/2: the window widens every cap over that much of its neighbours), or
// the higher cap would be spent under the lower one's range. Splitting more (a gain of 1.2,
// halves down to c·T/4) measured faster on the dense programs but slower on the V-carves and at
// J = 2e4, where the generator accelerates into the gentle half and must coast for T before it
// brakes for the tight one (docs/performance.md, fifth part).
void Planner::Impl::emit_path(const MotionBlock& block, double junction) {
  const bool curve = block.kind == traj::BlockKind::Bezier || block.kind == traj::BlockKind::Quintic;
  if (params.filter_s > 0 && curve) {
    emit_pieces(block, junction, kSplitDepth, false);
  } else {
    emit_block(block, junction, nullptr, false);
  }
}

void Planner::Impl::emit_pieces(const MotionBlock& block, double junction, int depth, bool piece) {
  MotionBlock b = block;
  detail::rebase(b, last_end);
  if (b.length < detail::kMinLength) return;
  const double v_max = std::min(commanded_max(b), speed_bound());
  const detail::RawLimits raw = detail::block_limits(b, v_max, params);
  if (depth > 0 && b.length >= raw.cap * params.filter_s) {
    MotionBlock head = b, tail = b;
    detail::trim_end(head, 0.5 * b.length);
    detail::trim_start(tail, 0.5 * b.length);
    // A cap above the nominal feed buys nothing at 100 % override.
    const double feed = b.feed_class == FeedClass::Feed && b.feed > 0 ? b.feed : kInf;
    const double c1 = std::min(feed, detail::block_limits(head, v_max, params).cap);
    const double c2 = std::min(feed, detail::block_limits(tail, v_max, params).cap);
    if (std::max(c1, c2) > kSplitCapGain * std::min(c1, c2) &&
        b.length >= std::max(c1, c2) * params.filter_s) {
      emit_pieces(head, junction, depth - 1, true);
      emit_pieces(tail, kInf, depth - 1, true);
      return;
    }
  }
  emit_block(b, junction, &raw, piece);
}

// Blocks are written into the window's slot in place: a MotionBlock is 408 bytes, and on dense
// paths copying them was much of the planner's time. `raw`: the limits of `block` already at
// last_end, if known.
void Planner::Impl::emit_block(const MotionBlock& block, double junction, const detail::RawLimits* raw,
                               bool piece) {
  PlannedBlock& pb = window->next_slot();
  pb.piece = piece;
  MotionBlock& b = pb.b;
  b = block;
  detail::rebase(b, last_end);
  if (b.length < detail::kMinLength) return;
  pb.v_max = std::min(commanded_max(b), speed_bound());
  pb.raw = raw ? *raw : detail::block_limits(b, pb.v_max, params);
  if (b.feed_class == FeedClass::Rapid) b.feed = pb.raw.cap;
  pb.junction = junction;
  if (params.filter_s > 0) {  // the curvature steps matter with jerk limits only
    if (continues && junction > 0) pb.step = detail::curvature_step(prev, b);
    // A step whose largest sampled jerk, (3/4)·v²·|Δg''|/T_servo, is far below the axis's limit
    // is rounding (the joins of the curvature-continuous blends): none.
    for (int i = 0; i < kAxisCount; ++i) {
      const double j = limits[i].max_jerk;
      if (j > 0 && 0.75 * v_bound * v_bound * pb.step[i] / config.servo_period_s <= 1e-7 * j) pb.step[i] = 0;
    }
    prev = b;
  }
  continues = true;
  last_end = detail::end_point(b);
  window->push_next();
}

void Planner::Impl::emit_marker(const MotionBlock& m) {
  PlannedBlock& pb = window->next_slot();
  pb.b = m;
  pb.b.base = last_end;
  pb.b.length = 0;
  pb.junction = kInf;
  window->push_next();
  if (m.marker != MarkerKind::Report) continues = false;
}

void Planner::Impl::publish_front(traj::BlockQueue& queue) {
  window->front_for_queue(queue.pushed(), queue.next_slot());
  queue.commit();
  window->pop_front();
  ++stats.blocks;
}

void Planner::Impl::emit_reports() {
  for (const MotionBlock& m : reports) emit_marker(m);
  reports.clear();
}

/// The curve between two elements: returns true when it blended (or the corner is tangent), false
/// when the motion has to stop at the corner. Emits `a` (trimmed) and the blend.
bool Planner::Impl::corner_g1(Element& a, Element& e) {
  if (a.stop_after || a.mode == canon::MotionControl::ExactStop) return false;
  if ((a.b.feed_class == FeedClass::SpindleSync) != (e.b.feed_class == FeedClass::SpindleSync)) return false;
  const detail::CornerTurn turn = detail::corner_turn(a.b, e.b);
  const bool tangent = turn.angle <= detail::kTangentAngle;
  if (tangent && (detail::same_speed_scale(a.b, e.b) ||
                  (a.mode != canon::MotionControl::Continuous &&
                   detail::speed_scale_step(a.b, e.b) <= detail::kSpeedScaleSlack))) {
    emit_path(a.b, a.junction);
    emit_reports();
    return true;
  }
  if (a.mode != canon::MotionControl::Continuous) return false;
  double tol = 0;
  if (a.tolerance > 0) {
    tol = a.tolerance - std::max(a.merge_deviation, e.merge_deviation);
    if (tol <= 0) return false;
  }
  detail::Blend blend;
  const double avail_a = std::min(0.5 * a.orig_length, a.b.length);
  const double avail_e = std::min(0.5 * e.orig_length, e.b.length);
  if (!detail::blend_corner(a.b, avail_a, e.b, avail_e, turn, tol, blend_need(a.b, e.b), blend)) return false;
  if (!blend_pays(a, e, blend)) return false;
  detail::trim_end(a.b, blend.trim_in);
  emit_path(a.b, a.junction);
  emit_reports();
  MotionBlock& c = blend.curve;
  c.flags = static_cast<std::uint8_t>((a.b.flags & e.b.flags) | traj::kBlend);
  c.segment = a.b.segment_last;
  c.segment_first = a.b.segment_first;
  c.segment_last = e.b.segment_last;
  // Where the blend leaves its move (exact unless `a` is a G64 Q merge of several).
  c.segment_offset = a.b.segment == a.b.segment_last ? a.b.segment_offset + a.b.length : 0.0;
  if (a.b.feed_class == e.b.feed_class) {
    c.feed_class = a.b.feed_class;
    c.feed = std::min(a.b.feed, e.b.feed);
  } else {  // rapid into feed or back: the feed side rules the blend
    const MotionBlock& f = a.b.feed_class == FeedClass::Rapid ? e.b : a.b;
    c.feed_class = f.feed_class;
    c.feed = f.feed;
  }
  emit_path(c, kInf);
  detail::trim_start(e.b, blend.trim_out);
  ++stats.blends;
  return true;
}

// G64 should never be slower than stopping. Compare both from where the stopping motion has
// slowed to the blend's speed limit v_b (v_b²/2A before the corner) to where it is back at v_b:
// stopping takes 2·v_b/A; blending covers that distance with the corner cut (blend length L
// instead of the two legs 2·d) at v_b, i.e. v_b/A + (L − 2d)/v_b. With the moving average of
// length T, a stop also waits T at the corner, and the blend's speed limit holds over v_b·T of
// extra path on each side (2·T more). Blend when (L − 2d)/v_b + T < v_b/A. Without jerk limits
// (T = 0) that always holds, as L < 2d. The estimate assumes moves on both sides long enough to
// get back to full speed; between short moves (dense paths) the blend is always kept.
bool Planner::Impl::blend_pays(const Element& ea, const Element& ee, const detail::Blend& blend) const {
  if (params.filter_s <= 0) return true;
  const MotionBlock& a = ea.b;
  const MotionBlock& e = ee.b;
  const MotionBlock& c = blend.curve;
  double v_b = detail::block_limits(c, std::min(commanded_max(a), commanded_max(e)), params).cap;
  if (params.filter_s > 0) {
    MotionBlock in = a, out = e;
    detail::trim_end(in, blend.trim_in);
    detail::trim_start(out, blend.trim_out);
    for (const Pose& step : {detail::curvature_step(in, c), detail::curvature_step(c, out)}) {
      for (int i = 0; i < kAxisCount; ++i) {
        if (step[i] > 0 && limits[i].max_jerk > 0) {
          v_b = std::min(
              v_b, std::sqrt(config.jerk_step_share * limits[i].max_jerk * config.servo_period_s / step[i]));
        }
      }
    }
  }
  const detail::RawLimits la = detail::block_limits(a, commanded_max(a), params);
  const detail::RawLimits le = detail::block_limits(e, commanded_max(e), params);
  const double v_adjacent = std::min(std::min(la.cap, le.cap), std::min(commanded_max(a), commanded_max(e)));
  const double accel = std::min(la.accel, le.accel);
  if (std::min(ea.orig_length, ee.orig_length) < v_adjacent * v_adjacent / accel) return true;
  return v_b > 0 && (c.length - blend.trim_in - blend.trim_out) / v_b + params.filter_s < v_b / accel;
}

void Planner::Impl::on_element(Element& e) {
  if (pending) {
    e.junction = corner(*pending, e) ? kInf : 0.0;
    if (e.junction == 0) {  // no blend: `pending` ends with a stop at the corner
      release_held();
      emit_path(pending->b, pending->junction);
      emit_reports();
    }
  }
  pending = e;
}

void Planner::Impl::flush_pending() {
  release_held();
  if (pending) emit_path(pending->b, pending->junction);
  pending.reset();
  emit_reports();
}

void Planner::Impl::on_marker(const MotionBlock& m) {
  if (m.marker == MarkerKind::Report && pending) {
    reports.push_back(m);  // placed where `pending` ends, i.e. where a blend would start
    return;
  }
  flush_pending();
  emit_marker(m);
}

bool Planner::Impl::read_one() {
  detail::Item* it = reader->next();
  if (it == nullptr) return false;
  if (it->is_marker) {
    on_marker(it->element.b);
  } else {
    on_element(it->element);
  }
  stats.smoothed_runs = reader->smoothed_runs();
  stats.moves = reader->moves_read();
  stats.merged_moves = reader->merged();
  return true;
}

Planner::Planner(const MachineLimits& limits, const PlannerConfig& config)
    : impl_(std::make_unique<Impl>(limits, config)) {}

Planner::~Planner() = default;

traj::InterpolatorConfig Planner::interpolator_config() const noexcept {
  traj::InterpolatorConfig c;
  c.period_s = impl_->config.servo_period_s;
  c.filter_ticks = impl_->ticks;
  c.max_feed_override = impl_->config.max_feed_override;
  // No block's budget exceeds a line's in the best direction: √(Σ A_i²).
  for (int i = 0; i < kAxisCount; ++i) {
    if (impl_->limits.axes.has(static_cast<Axis>(i)))
      c.max_path_accel += impl_->limits[i].max_acceleration * impl_->limits[i].max_acceleration;
  }
  c.max_path_accel = std::sqrt(c.max_path_accel);
  c.max_path_speed = impl_->speed_bound();
  return c;
}

bool Planner::start(const canon::Program& program) {
  Impl& m = *impl_;
  m.failed = !m.config_ok || !detail::check_program(program, m.limits, m.diags);
  if (m.failed) return false;
  return m.begin(program, false);
}

bool Planner::start_stream(const canon::Program& program) {
  Impl& m = *impl_;
  m.failed = !m.config_ok;
  if (m.failed) return false;
  return m.begin(program, true);
}

void Planner::stream_readable(std::size_t moves) noexcept {
  if (impl_->reader) impl_->reader->readable(moves);
  impl_->input_waiting = false;
}

void Planner::stream_flush() noexcept {
  impl_->flush_asked = true;
  impl_->input_waiting = false;
}

void Planner::stream_end() noexcept {
  if (impl_->reader) impl_->reader->seal();
  impl_->streaming = false;
  impl_->input_waiting = false;
}

bool Planner::wants_input() const noexcept {
  const Impl& m = *impl_;
  return m.streaming && m.input_waiting && !m.flushing && !m.flush_asked && !m.failed;
}

std::size_t Planner::oldest_move_needed() const noexcept {
  return impl_->reader ? impl_->reader->oldest_move_needed() : 0;
}

std::size_t Planner::oldest_action_needed() const noexcept {
  return impl_->reader ? impl_->reader->oldest_action_needed() : 0;
}

bool Planner::Impl::begin(const canon::Program& program, bool stream) {
  Impl& m = *this;
  m.streaming = stream;
  m.flush_asked = m.flushing = m.input_waiting = false;
  m.program = &program;
  m.reader.emplace(program, stream);
  m.reader->set_smoothing(m.config.smooth_short_moves && m.params.filter_s > 0);
  detail::WindowParams wp;
  wp.filter_s = m.params.filter_s;
  wp.period_s = m.config.servo_period_s;
  wp.limits = &m.params;
  double a_min = kInf;
  for (int i = 0; i < kAxisCount; ++i) {
    if (!m.limits.axes.has(static_cast<Axis>(i))) continue;
    const AxisLimits& l = m.limits[i];
    a_min = std::min(a_min, l.max_acceleration);
    wp.v_bound += l.max_velocity * l.max_velocity;
    if (wp.filter_s > 0 && l.max_jerk > 0) {
      wp.step_budget[static_cast<std::size_t>(i)] =
          4.0 / 3.0 * m.config.jerk_step_share * l.max_jerk * m.config.servo_period_s;
    }
  }
  wp.v_bound = std::sqrt(wp.v_bound);
  m.v_bound = wp.v_bound;
  wp.step_window_s = 3.0 * wp.v_bound * m.config.servo_period_s;
  // The look-ahead never limits the speed: the window may hold the braking distance from the
  // highest speed at the lowest acceleration, beyond the blocks still settling.
  wp.soft_blocks = 2 * m.config.lookahead_moves + 16;
  wp.soft_length = wp.v_bound * wp.v_bound / (2 * a_min) + wp.v_bound * (0.5 * wp.filter_s + 4 * wp.period_s);
  m.window.emplace(wp);
  m.reading_done = false;
  m.g2 = m.params.filter_s > 0;
  m.held.reset();
  m.pending.reset();
  m.reports.clear();
  m.last_end = program.start();
  m.continues = false;
  m.stats = {};
  return true;
}

void Planner::Impl::out_of_input() {
  if (!streaming) {  // the program's end marker has been read
    flush_pending();
    window->finish();
    reading_done = true;
    return;
  }
  if (flush_asked) {
    // A sync point: the motion stops at the end of what is readable. What the reader held back
    // for a G64 Q merge comes out first.
    flush_asked = false;
    reader->flush();
    while (read_one()) {
    }
    flush_pending();
    window->finish();
    flushing = true;
    return;
  }
  input_waiting = true;
}

PlanStatus Planner::pump(traj::BlockQueue& queue) {
  Impl& m = *impl_;
  if (m.failed || m.program == nullptr) return PlanStatus::Failed;
  detail::Lookahead& w = *m.window;
  for (;;) {
    while (queue.free_slots() > 0 && w.publishable() > 0 && w.front_link_decided()) m.publish_front(queue);
    if (queue.free_slots() == 0) return PlanStatus::Working;
    if (m.reading_done && w.empty()) return PlanStatus::Finished;
    if (m.reading_done) continue;  // finish() made everything publishable
    if (m.flushing) {
      if (!w.empty()) continue;  // finish() made everything publishable
      // Published up to the sync point, where the motion stops: what follows starts afresh.
      w.reopen();
      m.flushing = false;
      m.continues = false;
    }
    if (m.input_waiting) {
      if (!m.flush_asked) return PlanStatus::Working;
      m.input_waiting = false;
    }
    if (!w.wants_more()) {
      // The window is full and nothing is final: publish the front with the entry speed it
      // has (a stop at the window's end is assumed, so it is on the safe side).
      if (w.settled() == 0) return PlanStatus::Working;
      m.publish_front(queue);
      continue;
    }
    // Read a batch before looking for final blocks again: the backward pass then runs once
    // per batch instead of once per block.
    for (int i = 0; i < 64 && w.wants_more(); ++i) {
      if (!m.read_one()) {
        m.out_of_input();
        break;
      }
    }
  }
}

const Diagnostics& Planner::diagnostics() const noexcept {
  return impl_->diags;
}
const PlanStats& Planner::stats() const noexcept {
  return impl_->stats;
}

}  // namespace opencnc::plan
