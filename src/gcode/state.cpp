// SPDX-License-Identifier: GPL-3.0-or-later
// A stable 64-bit digest of the interpreter state (FNV-1a over a fixed field order).
#include "opencnc/gcode/state.hpp"

#include <bit>
#include <bitset>
#include <cstring>
#include <string_view>

namespace opencnc::gcode {

namespace {

class Fnv {
 public:
  void bytes(const void* p, std::size_t n) noexcept {
    const auto* b = static_cast<const unsigned char*>(p);
    for (std::size_t i = 0; i < n; ++i) {
      h_ ^= b[i];
      h_ *= 0x100000001b3ull;
    }
  }
  void u64(std::uint64_t v) noexcept {
    unsigned char b[8];
    for (int i = 0; i < 8; ++i) b[i] = static_cast<unsigned char>(v >> (8 * i));   // fixed byte order
    bytes(b, 8);
  }
  void i64(std::int64_t v) noexcept { u64(static_cast<std::uint64_t>(v)); }
  void f64(double v) noexcept { u64(std::bit_cast<std::uint64_t>(v)); }
  void flag(bool v) noexcept { u64(v ? 1 : 0); }
  void str(std::string_view s) noexcept {
    u64(s.size());
    bytes(s.data(), s.size());
  }
  void pose(const Pose& p) noexcept {
    for (double v : p.v) f64(v);
  }
  void pos(const SourcePosition& p) noexcept {
    u64(p.file);
    u64(p.offset);
    u64(p.line);
  }
  void named(const NamedParameters& m) noexcept {
    u64(m.size());
    for (const auto& [name, v] : m) {
      str(name);
      f64(v.value);
      flag(v.set);
    }
  }
  std::uint64_t value() const noexcept { return h_; }

 private:
  std::uint64_t h_ = 0xcbf29ce484222325ull;
};

void hash_modal(Fnv& h, const ModalState& m) noexcept {
  h.i64(m.motion);
  h.u64(static_cast<std::uint64_t>(m.plane));
  h.u64(static_cast<std::uint64_t>(m.units));
  h.u64(static_cast<std::uint64_t>(m.distance));
  h.u64(static_cast<std::uint64_t>(m.ijk_distance));
  h.u64(static_cast<std::uint64_t>(m.feed_mode));
  h.u64(static_cast<std::uint64_t>(m.cutter_comp));
  h.flag(m.comp_first_move);
  h.flag(m.arc_not_allowed);
  h.f64(m.comp_radius);
  h.i64(m.comp_orientation);
  h.i64(m.tool_length_mode);
  h.i64(m.coord_system);
  h.u64(static_cast<std::uint64_t>(m.control));
  h.f64(m.path_tolerance);
  h.f64(m.naivecam_tolerance);
  h.u64(static_cast<std::uint64_t>(m.retract));
  h.u64(static_cast<std::uint64_t>(m.spindle_mode));
  h.flag(m.lathe_diameter);
  h.f64(m.feed_rate);
  h.f64(m.spindle_speed);
  h.u64(static_cast<std::uint64_t>(m.spindle));
  for (bool b : {m.mist, m.flood, m.feed_override, m.speed_override, m.adaptive_feed, m.feed_hold}) h.flag(b);
}

void hash_tool(Fnv& h, const tools::ToolEntry& t) noexcept {
  h.i64(t.tool);
  h.i64(t.pocket);
  h.pose(t.offset);
  h.f64(t.diameter);
  h.f64(t.front_angle);
  h.f64(t.back_angle);
  h.i64(t.orientation);
  h.str(t.comment);
}

void hash_saved(Fnv& h, const SavedContext& s) noexcept {
  h.flag(s.valid);
  h.flag(s.restore_on_return);
  for (int v : s.g) h.i64(v);
  for (int v : s.m) h.i64(v);
  h.f64(s.feed);
  h.f64(s.speed);
}

void hash_comp_move(Fnv& h, const CompQueuedMove& q) noexcept {
  h.u64(static_cast<std::uint64_t>(q.kind));
  for (double v : {q.dir1, q.dir2, q.center1, q.center2, q.end1, q.end2, q.sweep}) h.f64(v);
  h.i64(q.turn);
}

void hash_transform(Fnv& h, const TransformState& t) noexcept {
  h.u64(t.mirror_axes);
  h.pose(t.mirror_at);
  h.flag(t.scaling);
  h.pose(t.scale_centre);
  for (double v : t.scale) h.f64(v);
  h.flag(t.rotating);
  h.u64(static_cast<std::uint64_t>(t.rotation_plane));
  h.f64(t.rotation_centre1);
  h.f64(t.rotation_centre2);
  h.f64(t.rotation_deg);
}

template <std::size_t N>
void hash_bits(Fnv& h, const std::bitset<N>& b) noexcept {
  for (std::size_t i = 0; i < N; i += 64) {
    std::uint64_t word = 0;
    for (std::size_t k = 0; k < 64 && i + k < N; ++k) word |= static_cast<std::uint64_t>(b[i + k]) << k;
    h.u64(word);
  }
}

void hash_fanuc_frame(Fnv& h, const FanucFrame& f) noexcept {
  h.pos(f.body);
  h.u64(f.program);
  h.u64(f.repeats_left);
  h.flag(f.macro);
  h.flag(f.started);
  for (double v : f.saved_locals) h.f64(v);
  hash_bits(h, f.saved_vacant);
  h.flag(f.range);
  h.pos(f.range_end);
  h.pose(f.range_return);
  h.u64(f.loops.size());
  for (const FanucLoop& l : f.loops) {
    h.i64(l.id);
    h.pos(l.start);
    h.pos(l.after_end);
  }
}

}  // namespace

std::uint64_t InterpState::digest() const noexcept {
  Fnv h;
  hash_modal(h, modal);
  h.pose(position.current);
  h.pose(position.origin_offset);
  h.pose(position.axis_offset);
  h.pose(position.tool_offset);
  h.f64(position.rotation_xy_deg);
  for (double v : position.programmed) h.f64(v);
  h.u64(tool.table.size());
  for (const auto& t : tool.table) hash_tool(h, t);
  h.i64(tool.selected_index);
  h.i64(tool.selected_tool);
  h.i64(tool.current_index);
  for (double v : parameters) h.f64(v);
  h.named(globals);
  h.u64(frames.size());
  for (const CallFrame& f : frames) {
    h.str(f.sub);
    h.u64(static_cast<std::uint64_t>(f.kind));
    h.i64(f.m98_left);
    h.i64(f.m98_runs_left);
    for (double v : f.saved_args) h.f64(v);
    h.named(f.locals);
    h.pos(f.return_to);
    h.u64(f.context);
    hash_saved(h, f.saved);
    hash_fanuc_frame(h, f.fanuc);
  }
  h.u64(control.labels.size());
  for (const auto& [name, l] : control.labels) {
    h.str(name);
    h.u64(static_cast<std::uint64_t>(l.kind));
    h.pos(l.at);
    h.i64(l.repeat_left);
  }
  h.str(control.skipping_to);
  h.str(control.seeking_sub);
  h.u64(control.skip_start_line);
  h.flag(control.defining_sub);
  h.str(control.defining_name);
  for (bool b : {control.executed_if, control.doing_break, control.doing_continue, control.value_returned}) h.flag(b);
  h.f64(control.return_value);
  h.pos(control.main_start);
  h.u64(control.main_repeats);
  h.f64(comp.start1);
  h.f64(comp.start2);
  h.flag(comp.start_valid);
  h.u64(comp.queued.size());
  for (const CompQueuedMove& q : comp.queued) hash_comp_move(h, q);
  hash_comp_move(h, comp.last_first);
  for (double v : {cycle.r, cycle.bottom, cycle.p, cycle.q, cycle.i, cycle.j, cycle.k, cycle.initial_level}) h.f64(v);
  h.flag(cycle.initial_level_valid);
  h.u64(spline.points.size());
  for (const canon::NurbsPoint& p : spline.points) {
    h.f64(p.x);
    h.f64(p.y);
    h.f64(p.weight);
  }
  h.i64(spline.order);
  h.f64(spline.g5_i);
  h.f64(spline.g5_j);
  hash_transform(h, fanuc.transform);
  for (double v : {fanuc.cycles.rough_depth, fanuc.cycles.rough_retract, fanuc.cycles.groove_retract,
                   fanuc.cycles.thread_chamfer, fanuc.cycles.thread_angle_deg, fanuc.cycles.thread_min_depth,
                   fanuc.cycles.thread_allowance})
    h.f64(v);
  h.i64(fanuc.cycles.thread_finish_passes);
  hash_bits(h, fanuc.vacant);
  h.f64(fanuc.spindle_clamp_rpm);
  h.pos(next);
  h.flag(percent_delimited);
  h.flag(ended);
  h.u64(blocks_executed);
  h.u64(loop_iterations);
  h.u64(segments);
  return h.value();
}

}  // namespace opencnc::gcode
