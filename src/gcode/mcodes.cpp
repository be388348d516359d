// SPDX-License-Identifier: GPL-3.0-or-later
// M codes: I/O (M62-M68), tools (T, M6, M61), spindle (M3-M5, M19), modal state save and
// restore (M70-M73), coolant (M7-M9), overrides (M48-M53), stops and program end.
#include <algorithm>
#include <cmath>

#include "engine.hpp"
#include "numeric.hpp"
#include "lexer.hpp"

namespace opencnc::gcode {

void Engine::convert_io() {
  const Block& b = block_;
  const int m = b.m[kGroupIo];
  if (m == -1) return;
  if (run_extension_m(m)) return;
  const bool comp = st_.modal.cutter_comp != CutterComp::Off;
  const int at = b.m_position(kGroupIo);
  auto no_comp = [&] {
    if (comp)
      fail_at(at, ErrorCode::CompIo, "M{} cannot be used while cutter compensation is on: G40 first", m);
  };
  if (m >= 62 && m <= 65) {
    no_comp();
    if (!b.has('p'))
      fail_at(at, ErrorCode::IoOutputMissing, "M{} needs a P word: the number of the output", m);
    const int p = round_to_int(b.get('p'));
    if (m == 62) out_.set_motion_output_bit(p);
    else if (m == 63) out_.clear_motion_output_bit(p);
    else if (m == 64) out_.set_aux_output_bit(p);
    else out_.clear_aux_output_bit(p);
    return;
  }
  if (m == 66) {
    if (b.has('p') && b.has('e'))
      fail_at(std::max(b.word_position('p'), b.word_position('e')), ErrorCode::IoM66BothInputs,
              "M66 with both P (a digital input) and E (an analog input): give one of them");
    const int l = b.has('l') ? round_to_int(b.get('l')) : 0;
    if (b.q_or(-1.0) <= 0 && b.has('l') && l > 0)
      fail_at(b.word_position('l'), ErrorCode::IoM66TimeoutMissing,
              "M66 L{} waits for the input: give a timeout Q greater than 0", l);
    if (b.has('e') && b.has('l') && l != 0)
      fail_at(b.word_position('l'), ErrorCode::IoM66AnalogWait,
              "M66 E (an analog input) reads the input at once only: use L0");
    if ((b.has('p') && round_to_int(b.get('p')) < 0) || (b.has('e') && round_to_int(b.get('e')) < 0) ||
        (!b.has('p') && !b.has('e')))
      fail_at(at, ErrorCode::IoM66InputMissing,
              "M66 needs the input to read: P (digital) or E (analog), numbered from 0");
    no_comp();
    const bool digital = b.has('p');
    const int index = round_to_int(digital ? b.get('p') : b.get('e'));
    const double timeout = digital && b.q_or(-1.0) > 0 ? b.get('q') : 0.0;
    out_.wait_for_input(index, digital, digital ? l : 0, timeout);
    SyncValues assumed;
    assumed.kind = SyncKind::Input;
    // What rs274 reads back: a digital input keeps its truth value, an analog one its value.
    const double old = st_.parameters[5399];
    assumed.input_value = digital ? (old != 0.0 ? 1.0 : 0.0) : old;
    if (opt_.scan_assumption == ScanAssumption::Other) assumed.input_value = digital ? 1.0 - assumed.input_value : old + 1;
    request_sync(assumed);
    return;
  }
  no_comp();
  if (!b.has('e') || round_to_int(b.get('e')) < 0)
    fail_at(at, ErrorCode::IoAnalogOutputMissing,
            "M{} needs an E word: the number of the analog output, 0 or more", m);
  if (m == 67) out_.set_motion_output_value(round_to_int(b.get('e')), b.q_or(-1.0));
  else out_.set_aux_output_value(round_to_int(b.get('e')), b.q_or(-1.0));
}

// --- tools -------------------------------------------------------------------------------

int Engine::tool_index(int tool, int at) const {
  if (tool == 0) return 0;   // T0: no tool (the empty spindle)
  if (opt_.tool_table) {
    if (const auto index = opt_.tool_table->find(tool)) return static_cast<int>(*index);
  }
  if (!opt_.tool_table)
    fail_at(at, ErrorCode::ToolNotFound, "tool {} is not in the tool table (no tool table is loaded)", tool);
  fail_at(at, ErrorCode::ToolNotFound, "tool {} is not in the tool table", tool);
}

int Engine::pocket_of(int index) const noexcept {
  if (index < 1 || static_cast<std::size_t>(index) >= st_.tool.table.size()) return -1;
  return st_.tool.table[static_cast<std::size_t>(index)].pocket;
}

void Engine::select_tool(int tool) {
  const int index = tool_index(tool, block_.word_position('t'));
  out_.select_tool(tool);
  st_.tool.selected_index = index;
  st_.tool.selected_tool = tool;
}

void Engine::load_spindle(int index) {
  st_.tool.current_index = index;
  st_.tool.table[0] = index == 0 ? tools::ToolEntry{} : st_.tool.table[static_cast<std::size_t>(index)];
  set_tool_parameters();
}

void Engine::set_tool_parameters() {
  const tools::ToolEntry& t = st_.tool.table[0];
  auto& p = st_.parameters;
  p[5400] = t.tool > 0 ? t.tool : 0;
  for (int i = 0; i < kAxisCount; ++i) p[static_cast<std::size_t>(5401 + i)] = t.offset[i];
  p[5410] = t.diameter;
  p[5411] = t.front_angle;
  p[5412] = t.back_angle;
  p[5413] = t.orientation;
}

void Engine::change_tool() {
  const int at = block_.m_position(kGroupToolChange);
  if (st_.tool.selected_index < 0)
    fail_at(at, ErrorCode::ToolNotPrepared, "M6 with no tool selected: program a T word first");
  if (st_.modal.cutter_comp != CutterComp::Off)
    fail_at(at, ErrorCode::CompToolChange,
            "M6 cannot change tools while cutter compensation is on: G40 first");
  out_.start_change();
  // A lathe turret indexes with the spindle turning (the Fanuc dialect's T0101).
  if (!(dialect_.turret_keeps_spindle && opt_.machine == MachineKind::Lathe)) {
    out_.stop_spindle_turning(0);
    st_.modal.spindle = canon::SpindleDirection::Stopped;
  }
  move_to_tool_change(at);
  out_.change_tool(st_.tool.selected_index);
  load_spindle(st_.tool.selected_index);
  SyncValues assumed;
  assumed.kind = SyncKind::ToolChange;
  assumed.position = st_.position.canon_position;
  request_sync(assumed);
}

// The profile's tool-change position: rapid there before the change, in machine coordinates as
// G53 takes them (the work, G92 and tool-length offsets taken off, so the spindle ends at the
// position whatever the tool), Z alone first when asked. The moves are the program's own: the
// preview, the preflight's limits check and a replay see them, and the next move starts there.
void Engine::move_to_tool_change(int at) {
  const ToolChangePosition& tc = opt_.tool_change;
  if (tc.axes.count() == 0) return;
  if (st_.fanuc.transform.active()) {
    const TransformState& t = st_.fanuc.transform;
    fail_at(at, ErrorCode::FanucTransformActive,
            "M6 moves to the tool-change position in machine coordinates: it cannot while {} is on (cancel "
            "it first)",
            t.rotating  ? "G68 rotation"
            : t.scaling ? "G51 scaling"
                        : "G51.1 mirroring");
  }
  const double per_mm = 1.0 / canon::mm_per_unit(st_.modal.units);
  const Pose from = program_to_machine(st_.position.current);
  Pose to = from;
  int z_letter = -1;  // the program letter the axis map sends to the machine's Z
  for (int i = 0; i < kAxisCount; ++i) {
    const Axis axis = opt_.axis_map[static_cast<std::size_t>(i)];
    if (!tc.axes.has(axis)) continue;
    to[i] = tc.machine[axis] * (is_rotary(axis) ? 1.0 : per_mm);
    if (axis == Axis::Z) z_letter = i;
  }
  // An axis that stays keeps its program coordinate exactly (no rounding through the offsets),
  // X and Y both unless the XY rotation turns a move of one into both.
  const auto go = [&](const Pose& machine) {
    const Pose& now = st_.position.current;
    const bool turned = st_.position.rotation_xy_deg != 0 && (machine[0] != from[0] || machine[1] != from[1]);
    Pose p = machine_to_program(machine);
    for (int i = 0; i < kAxisCount; ++i) {
      if (machine[i] == from[i] && !(i < 2 && turned)) p[i] = now[i];
    }
    out_.straight_traverse(0, p);
    st_.position.current = p;
  };
  if (to == from) return;
  // Each move ends where it is programmed (Z up before anything goes across), then the program's
  // own path control again.
  out_.set_motion_control_mode(canon::MotionControl::ExactStop, 0);
  if (tc.z_first && z_letter >= 0 && to[z_letter] != from[z_letter]) {
    Pose up = from;
    up[z_letter] = to[z_letter];
    if (!(up == to)) go(up);
  }
  go(to);
  out_.set_motion_control_mode(st_.modal.control, st_.modal.path_tolerance);
}

void Engine::set_tool_number(int tool) {
  const int index = tool_index(tool, block_.word_position('q'));
  out_.change_tool_number(index);
  // The tool becomes current, but (as in rs274) the spindle entry and #5400.. keep the tool
  // of the last M6 until the next one.
  st_.tool.current_index = index;
  SyncValues assumed;
  assumed.kind = SyncKind::ToolChange;
  assumed.position = st_.position.canon_position;
  request_sync(assumed);
}

void Engine::convert_tool_change_group() {
  const int m = block_.m[kGroupToolChange];
  if (m == -1) return;
  if (run_extension_m(m)) return;
  if (m == 6) {
    change_tool();
    return;
  }
  const int tool = round_to_int(block_.q_or(-1.0));
  if (tool < 0) {
    if (!block_.has('q'))
      fail_at(block_.m_position(kGroupToolChange), ErrorCode::M61QMissing,
              "M61 needs a Q word: the number of the tool in the spindle");
    fail_at(block_.word_position('q'), ErrorCode::M61QMissing, "M61 Q{}: the tool number must be 0 or more",
            block_.get('q'));
  }
  set_tool_number(tool);
}

// --- spindle, context, coolant, overrides -------------------------------------------------

void Engine::convert_spindle_group() {
  const Block& b = block_;
  const int m = b.m[kGroupSpindle];
  if (m == -1) return;
  if (run_extension_m(m)) return;
  if (b.dollar_flag && (m == 3 || m == 4 || m == 5 || m == 19)) check_spindle_number(true);
  switch (m) {
    case 3:
      out_.start_spindle_clockwise(0);
      st_.modal.spindle = canon::SpindleDirection::Clockwise;
      return;
    case 4:
      out_.start_spindle_counterclockwise(0);
      st_.modal.spindle = canon::SpindleDirection::Counterclockwise;
      return;
    case 5:
      out_.stop_spindle_turning(0);
      st_.modal.spindle = canon::SpindleDirection::Stopped;
      return;
    case 19:
      st_.modal.spindle = canon::SpindleDirection::Stopped;
      if (b.has('r') || b.has('p'))
        out_.orient_spindle(0, b.has('r') ? b.get('r') : 0.0, b.has('p') ? trunc_to_int(b.get('p')) : 0);
      if (b.has('q')) {
        if (b.get('q') <= 0.0)
          fail_at(b.word_position('q'), ErrorCode::M19Timeout,
                  "M19 Q{}: the time to wait for the orientation must be above 0", b.get('q'));
        out_.wait_spindle_orient_complete(0, b.get('q'));
      }
      return;
    case 70:
    case 73:
      save_context(m == 73 && st_.frames.size() > 1);
      return;
    case 71:
      st_.frames.back().saved.valid = false;
      return;
    case 72:
      if (!st_.frames.back().saved.valid)
        fail_at(b.m_position(kGroupSpindle), ErrorCode::RestoreWithoutSave,
                "M72 restores the modal state saved by M70 or M73, and none is saved at this call level");
      restore_context(st_.frames.back().saved);
      return;
    default:
      return;
  }
}

SavedContext Engine::active_context() const {
  const ModalState& m = st_.modal;
  SavedContext c;
  c.g.fill(-1);
  c.m.fill(-1);
  static constexpr int kPlaneCodes[] = {170, 190, 180, 171, 191, 181};   // XY YZ XZ UV VW UW
  c.g[3] = kPlaneCodes[static_cast<int>(m.plane)];
  c.g[4] = m.cutter_comp == CutterComp::Right ? 420 : m.cutter_comp == CutterComp::Left ? 410 : 400;
  c.g[5] = m.units == canon::Units::Inch ? 200 : 210;
  c.g[6] = m.distance == DistanceMode::Absolute ? 900 : 910;
  c.g[7] = m.feed_mode == canon::FeedMode::InverseTime ? 930 : m.feed_mode == canon::FeedMode::UnitsPerMinute ? 940 : 950;
  c.g[8] = m.coord_system < 7 ? 530 + 10 * m.coord_system : 584 + m.coord_system;
  bool offset = false;
  for (int i = 0; i < kAxisCount; ++i) offset = offset || st_.position.tool_offset[i] != 0.0;
  c.g[9] = offset ? 430 : 490;
  c.g[10] = m.retract == RetractMode::OldZ ? 980 : 990;
  c.g[11] = m.control == canon::MotionControl::Continuous ? 640 : m.control == canon::MotionControl::ExactPath ? 610 : 611;
  c.g[13] = m.spindle_mode == SpindleMode::Rpm ? 970 : 960;
  c.g[14] = m.ijk_distance == DistanceMode::Absolute ? 901 : 911;
  c.g[15] = m.lathe_diameter ? 70 : 80;
  c.m[2] = m.spindle == canon::SpindleDirection::Stopped ? 5 : m.spindle == canon::SpindleDirection::Clockwise ? 3 : 4;
  c.m[4] = m.mist ? 7 : (m.flood ? -1 : 9);
  c.m[5] = m.flood ? 8 : -1;
  c.m[6] = m.feed_override ? (m.speed_override ? 48 : 50) : (m.speed_override ? 51 : 49);
  c.m[7] = m.adaptive_feed ? 52 : -1;
  c.m[8] = m.feed_hold ? 53 : -1;
  c.feed = m.feed_rate;
  c.speed = m.spindle_speed;
  return c;
}

void Engine::save_context(bool restore_on_return) {
  SavedContext c = active_context();
  c.valid = true;
  c.restore_on_return = restore_on_return;
  st_.frames.back().saved = c;
}

// Restores modes by executing the G-code that re-establishes them, as LinuxCNC does, so that
// the same canonical calls are made: units first, then F/S and M codes, then G codes.
void Engine::restore_context(const SavedContext& saved) {
  const SavedContext now = active_context();
  if (now.g[5] != saved.g[5]) execute_text(saved.g[5] == 200 ? "G20" : "G21");
  std::string cmd;
  if (saved.feed != now.feed) cmd += fmt::format(" F{:.1f}", saved.feed);
  if (saved.speed != now.speed) cmd += fmt::format(" S{:.0f}", saved.speed);
  for (int i = 2; i <= 8; ++i) {
    if (i == 3 || saved.m[static_cast<std::size_t>(i)] == now.m[static_cast<std::size_t>(i)]) continue;
    if (saved.m[static_cast<std::size_t>(i)] != -1) cmd += fmt::format("M{}\n", saved.m[static_cast<std::size_t>(i)]);
  }
  for (int i : {3, 4, 6, 7, 8, 9, 10, 11, 13, 14, 15}) {
    const int v = saved.g[static_cast<std::size_t>(i)];
    if (v == now.g[static_cast<std::size_t>(i)] || v == -1) continue;
    cmd += v % 10 ? fmt::format(" G{}.{}", v / 10, v % 10) : fmt::format(" G{}", v / 10);
  }
  std::string_view rest = cmd;
  while (!rest.empty()) {
    const std::size_t nl = rest.find('\n');
    const std::string_view piece = rest.substr(0, nl);
    if (!piece.empty()) execute_text(piece);
    if (nl == std::string_view::npos) break;
    rest.remove_prefix(nl + 1);
  }
}

void Engine::execute_text(std::string_view text) {
  const Block saved_block = block_;
  const std::string saved_raw = raw_;
  auto saved_numbered = parser_.numbered_assignments;
  auto saved_named = parser_.named_assignments;
  raw_.assign(text);
  if (norm_.size() < raw_.size() + 1) norm_.resize(raw_.size() + 1);
  std::vector<char> saved_norm(norm_.begin(), norm_.begin() + static_cast<std::ptrdiff_t>(norm_len_));
  const std::size_t n = normalize_line(raw_, norm_.data());
  parser_.parse(std::string_view(norm_.data(), n), parse_env(), block_);
  enhance_block();
  check_block();
  apply_assignments();
  execute_block();
  block_ = saved_block;
  raw_ = saved_raw;
  std::copy(saved_norm.begin(), saved_norm.end(), norm_.begin());
  parser_.numbered_assignments = std::move(saved_numbered);
  parser_.named_assignments = std::move(saved_named);
}

void Engine::convert_coolant() {
  const int m = block_.m[kGroupCoolant];
  if (m == -1) return;
  if (run_extension_m(m)) return;
  if (m == 7) {
    out_.mist_on();
    st_.modal.mist = true;
  } else if (m == 8) {
    out_.flood_on();
    st_.modal.flood = true;
  } else {
    out_.mist_off();
    st_.modal.mist = false;
    out_.flood_off();
    st_.modal.flood = false;
  }
}

void Engine::convert_overrides() {
  const int m = block_.m[kGroupOverride];
  if (m == -1) return;
  if (run_extension_m(m)) return;
  if (st_.modal.cutter_comp != CutterComp::Off)
    fail_at(block_.m_position(kGroupOverride), ErrorCode::CompOverrides,
            "M{} cannot switch overrides while cutter compensation is on: G40 first", m);
  // M50..M53: P0 disables, any other P (or none) enables.
  const bool enable = m == 48 || (m != 49 && block_.p_or(-1.0) != 0.0);
  ModalState& s = st_.modal;
  switch (m) {
    case 48:
    case 49:
      if (enable) {
        out_.enable_feed_override();
        out_.enable_speed_override(0);
      } else {
        out_.disable_feed_override();
        out_.disable_speed_override(0);
      }
      s.feed_override = s.speed_override = enable;
      return;
    case 50:
      enable ? out_.enable_feed_override() : out_.disable_feed_override();
      s.feed_override = enable;
      return;
    case 51:
      enable ? out_.enable_speed_override(0) : out_.disable_speed_override(0);
      s.speed_override = enable;
      return;
    case 52:
      enable ? out_.enable_adaptive_feed() : out_.disable_adaptive_feed();
      s.adaptive_feed = enable;
      return;
    default:
      enable ? out_.enable_feed_hold() : out_.disable_feed_hold();
      s.feed_hold = enable;
      return;
  }
}

// --- stops and end ------------------------------------------------------------------------

void Engine::convert_stop() {
  const int m = block_.m[kGroupStop];
  if (run_extension_m(m)) return;
  if (dialect_.stop_code && dialect_.stop_code(*this, m)) return;  // its calls and returns (M98, M99)
  if (st_.modal.cutter_comp != CutterComp::Off && ext_ != nullptr && ext_->compensator) {
    const ExtensionSite site(*this, block_.m_position(kGroupStop));
    ext_->compensator->finish(*this);
  }
  switch (m) {
    case 0:
      out_.program_stop();
      request_stop_sync();
      return;
    case 60:
      out_.pallet_shuttle();
      out_.program_stop();
      request_stop_sync();
      return;
    case 1:
      out_.optional_program_stop();
      request_stop_sync();
      return;
    case 2:
    case 30:
      end_program(m);
      return;
    default:
      break;
  }
  // M99. In a subprogram it is its return, read as such when it starts the line.
  if (st_.frames.size() > 1)
    fail_at(
        block_.m_position(kGroupStop), ErrorCode::OwordSyntax,
        "M99 returns from a subprogram only at the start of its line: put the other words on a line of their "
        "own");
  if (opt_.main_m99 == MainM99::Repeat) return repeat_main();
  // Read as rs274 reads it; a reader of the scan (a preflight, `opencnc check`) should know
  // that the machine will not stop here.
  if (!in_mdi_)
    warn_once(warned_repeat_, ErrorCode::MainProgramRepeats,
              "M99 in the main program: the scan ends here, but a run on the machine starts the program "
              "again from its first line, endlessly, until the operator stops it");
  end_program(m);
}

// M99 in the main program with MainM99::Repeat: what LinuxCNC's task does, back to the first
// line with every setting and parameter as it is (no program-end reset). A scan cannot run
// an endless program to its end: it stops after max_main_repeats passes with an error that
// says so. In execute mode each pass starts the block and loop counts afresh, so that the
// limits still bound a runaway loop inside a pass.
void Engine::repeat_main() {
  ControlState& c = st_.control;
  out_.finish();
  ++c.main_repeats;
  if (opt_.mode == Mode::Scan) {
    const std::uint64_t limit =
        opt_.limits.max_main_repeats == 0 ? Limits{}.max_main_repeats : opt_.limits.max_main_repeats;
    if (c.main_repeats > limit)
      fail_at(
          block_.m_position(kGroupStop), ErrorCode::LimitMainRepeats,
          "M99 starts the main program again, endlessly: the scan stopped after {} repetitions (limit "
          "max_main_repeats); a run repeats it until the operator stops it (or a /M30 with block delete off)",
          limit);
  } else {
    st_.blocks_executed = 0;
    st_.loop_iterations = 0;
    skipped_lines_ = 0;
  }
  jump_to(c.main_start);
}

void Engine::end_program(int code) {
  ModalState& m = st_.modal;
  PositionState& s = st_.position;
  auto& par = st_.parameters;
  // Back to G54: the current point is re-expressed in its coordinates.
  for (int i = 0; i < kAxisCount; ++i) s.current[i] += s.origin_offset[i];
  rotate(s.current[0], s.current[1], s.rotation_xy_deg);
  m.coord_system = 1;
  par[5220] = 1.0;
  for (int i = 0; i < kAxisCount; ++i) {
    const double o = par[static_cast<std::size_t>(5221 + i)];
    s.origin_offset[i] = is_rotary(static_cast<Axis>(i)) ? o : user_to_program(o);
  }
  s.rotation_xy_deg = par[5230];
  rotate(s.current[0], s.current[1], -s.rotation_xy_deg);
  for (int i = 0; i < kAxisCount; ++i) s.current[i] -= s.origin_offset[i];
  out_.set_g5x_offset(1, s.origin_offset);
  out_.set_xy_rotation(s.rotation_xy_deg);
  if (m.plane != canon::Plane::XY) {
    out_.select_plane(canon::Plane::XY);
    m.plane = canon::Plane::XY;
  }
  m.distance = DistanceMode::Absolute;
  m.feed_mode = canon::FeedMode::UnitsPerMinute;
  out_.set_feed_mode(0, canon::FeedMode::UnitsPerMinute);
  m.feed_rate = 0;
  out_.set_feed_rate(0);
  if (!m.feed_override) {
    out_.enable_feed_override();
    m.feed_override = true;
  }
  if (!m.speed_override) {
    out_.enable_speed_override(0);
    m.speed_override = true;
  }
  m.cutter_comp = CutterComp::Off;
  m.comp_first_move = true;
  out_.stop_spindle_turning(0);
  m.spindle = canon::SpindleDirection::Stopped;
  out_.set_spindle_mode(0, 0);
  m.motion = 10;
  if (m.mist) {
    out_.mist_off();
    m.mist = false;
  }
  if (m.flood) {
    out_.flood_off();
    m.flood = false;
  }
  if (code == 30) out_.pallet_shuttle();
  out_.program_end();
  if (st_.percent_delimited && !in_mdi_) {
    // A '%'-delimited file should still have its closing '%' after M2/M30.
    SourceFile& f = current_file();
    if (need_seek_) {
      f.seek(st_.next.offset);
      need_seek_ = false;
    }
    RawLine line;
    bool found = false;
    while (f.next(line)) {
      std::string_view t = trim_raw_line(line.text);
      while (!t.empty() && (t.front() == ' ' || t.front() == '\t')) t.remove_prefix(1);
      if (t == "%") {
        found = true;
        break;
      }
    }
    if (!found) out_.comment("interpreter: percent sign missing from end of file");
  }
  st_.frames.resize(1);
  st_.control.skipping_to.clear();
  st_.control.seeking_sub.clear();
  st_.control.defining_sub = false;
  st_.ended = true;
}

}  // namespace opencnc::gcode
