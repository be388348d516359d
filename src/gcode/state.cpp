// SPDX-License-Identifier: GPL-3.0-or-later
// A stable 64-bit digest of the interpreter state (FNV-1a over a fixed field order).
#include "opencnc/gcode/state.hpp"

#include <bit>
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
    for (double v : f.saved_args) h.f64(v);
    h.named(f.locals);
    h.pos(f.return_to);
    h.u64(f.context);
    hash_saved(h, f.saved);
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
  h.pos(next);
  h.flag(percent_delimited);
  h.flag(ended);
  h.u64(blocks_executed);
  h.u64(loop_iterations);
  h.u64(segments);
  return h.value();
}

}  // namespace opencnc::gcode
