// SPDX-License-Identifier: GPL-3.0-or-later
// M codes: I/O (M62-M68), tools (T, M6, M61), spindle (M3-M5, M19), modal state save and
// restore (M70-M73), coolant (M7-M9), overrides (M48-M53), stops and program end.
#include <algorithm>
#include <cmath>

#include "engine.hpp"
#include "numeric.hpp"
#include "lexer.hpp"

namespace opencnc::gcode {

// The block's M codes by modal group (LinuxCNC's order), then a user M code.
void MCodes::convert_m() {
  convert_io();
  convert_tool_change_group();
  convert_spindle_group();
  convert_coolant();
  convert_overrides();
  if (const int m = e_.block_.m[kGroupUser]; m != -1 && !e_.run_extension_m(m))
    fail_at(e_.block_.m_position(kGroupUser), ErrorCode::UnknownMCode,
            "M{} is not defined: no user M code of that number is installed", m);
}

void MCodes::convert_io() {
  const Block& b = e_.block_;
  const int m = b.m[kGroupIo];
  if (m == -1) return;
  if (e_.run_extension_m(m)) return;
  const bool comp = e_.st_.modal.cutter_comp != CutterComp::Off;
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
    if (m == 62)
      e_.out_.set_motion_output_bit(p);
    else if (m == 63)
      e_.out_.clear_motion_output_bit(p);
    else if (m == 64)
      e_.out_.set_aux_output_bit(p);
    else
      e_.out_.clear_aux_output_bit(p);
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
    e_.out_.wait_for_input(index, digital, digital ? l : 0, timeout);
    SyncValues assumed;
    assumed.kind = SyncKind::Input;
    // What rs274 reads back: a digital input keeps its truth value, an analog one its value.
    const double old = e_.st_.parameters[5399];
    assumed.input_value = digital ? (old != 0.0 ? 1.0 : 0.0) : old;
    if (e_.opt_.scan_assumption == ScanAssumption::Other)
      assumed.input_value = digital ? 1.0 - assumed.input_value : old + 1;
    e_.request_sync(assumed);
    return;
  }
  no_comp();
  if (!b.has('e') || round_to_int(b.get('e')) < 0)
    fail_at(at, ErrorCode::IoAnalogOutputMissing,
            "M{} needs an E word: the number of the analog output, 0 or more", m);
  if (m == 67)
    e_.out_.set_motion_output_value(round_to_int(b.get('e')), b.q_or(-1.0));
  else
    e_.out_.set_aux_output_value(round_to_int(b.get('e')), b.q_or(-1.0));
}

// --- tools -------------------------------------------------------------------------------

int MCodes::tool_index(int tool, int at) const {
  if (tool == 0) return 0;   // T0: no tool (the empty spindle)
  if (e_.opt_.tool_table) {
    if (const auto index = e_.opt_.tool_table->find(tool)) return static_cast<int>(*index);
  }
  if (!e_.opt_.tool_table)
    fail_at(at, ErrorCode::ToolNotFound, "tool {} is not in the tool table (no tool table is loaded)", tool);
  fail_at(at, ErrorCode::ToolNotFound, "tool {} is not in the tool table", tool);
}

int MCodes::pocket_of(int index) const noexcept {
  if (index < 1 || static_cast<std::size_t>(index) >= e_.st_.tool.table.size()) return -1;
  return e_.st_.tool.table[static_cast<std::size_t>(index)].pocket;
}

void MCodes::select_tool(int tool) {
  const int index = tool_index(tool, e_.block_.word_position('t'));
  e_.out_.select_tool(tool);
  e_.st_.tool.selected_index = index;
  e_.st_.tool.selected_tool = tool;
}

void MCodes::load_spindle(int index) {
  e_.st_.tool.current_index = index;
  e_.st_.tool.table[0] = index == 0 ? tools::ToolEntry{} : e_.st_.tool.table[static_cast<std::size_t>(index)];
  set_tool_parameters();
}

void MCodes::set_tool_parameters() {
  const tools::ToolEntry& t = e_.st_.tool.table[0];
  auto& p = e_.st_.parameters;
  p[5400] = t.tool > 0 ? t.tool : 0;
  for (int i = 0; i < kAxisCount; ++i) p[static_cast<std::size_t>(5401 + i)] = t.offset[i];
  p[5410] = t.diameter;
  p[5411] = t.front_angle;
  p[5412] = t.back_angle;
  p[5413] = t.orientation;
}

void MCodes::change_tool() {
  const int at = e_.block_.m_position(kGroupToolChange);
  if (e_.st_.tool.selected_index < 0)
    fail_at(at, ErrorCode::ToolNotPrepared, "M6 with no tool selected: program a T word first");
  if (e_.st_.modal.cutter_comp != CutterComp::Off)
    fail_at(at, ErrorCode::CompToolChange,
            "M6 cannot change tools while cutter compensation is on: G40 first");
  e_.out_.start_change();
  // A lathe turret indexes with the spindle turning (the Fanuc dialect's T0101).
  if (!(e_.dialect_.turret_keeps_spindle && e_.opt_.machine == MachineKind::Lathe)) {
    e_.out_.stop_spindle_turning(0);
    e_.st_.modal.spindle = canon::SpindleDirection::Stopped;
  }
  move_to_tool_change(at);
  e_.out_.change_tool(e_.st_.tool.selected_index);
  load_spindle(e_.st_.tool.selected_index);
  SyncValues assumed;
  assumed.kind = SyncKind::ToolChange;
  assumed.position = e_.st_.position.canon_position;
  e_.request_sync(assumed);
}

// The profile's tool-change position: rapid there before the change, in machine coordinates as
// G53 takes them (the work, G92 and tool-length offsets taken off, so the spindle ends at the
// position whatever the tool), Z alone first when asked. The moves are the program's own: the
// preview, the preflight's limits check and a replay see them, and the next move starts there.
void MCodes::move_to_tool_change(int at) {
  const ToolChangePosition& tc = e_.opt_.tool_change;
  if (tc.axes.count() == 0) return;
  if (e_.st_.fanuc.transform.active()) {
    const TransformState& t = e_.st_.fanuc.transform;
    fail_at(at, ErrorCode::FanucTransformActive,
            "M6 moves to the tool-change position in machine coordinates: it cannot while {} is on (cancel "
            "it first)",
            t.rotating  ? "G68 rotation"
            : t.scaling ? "G51 scaling"
                        : "G51.1 mirroring");
  }
  const double per_mm = 1.0 / canon::mm_per_unit(e_.st_.modal.units);
  const Pose from = e_.offsets_.program_to_machine(e_.st_.position.current);
  Pose to = from;
  int z_letter = -1;  // the program letter the axis map sends to the machine's Z
  for (int i = 0; i < kAxisCount; ++i) {
    const Axis axis = e_.opt_.axis_map[static_cast<std::size_t>(i)];
    if (!tc.axes.has(axis)) continue;
    to[i] = tc.machine[axis] * (is_rotary(axis) ? 1.0 : per_mm);
    if (axis == Axis::Z) z_letter = i;
  }
  // An axis that stays keeps its program coordinate exactly (no rounding through the offsets),
  // X and Y both unless the XY rotation turns a move of one into both.
  const auto go = [&](const Pose& machine) {
    const Pose& now = e_.st_.position.current;
    const bool turned =
        e_.st_.position.rotation_xy_deg != 0 && (machine[0] != from[0] || machine[1] != from[1]);
    Pose p = e_.offsets_.machine_to_program(machine);
    for (int i = 0; i < kAxisCount; ++i) {
      if (machine[i] == from[i] && !(i < 2 && turned)) p[i] = now[i];
    }
    e_.out_.straight_traverse(0, p);
    e_.st_.position.current = p;
  };
  if (to == from) return;
  // Each move ends where it is programmed (Z up before anything goes across), then the program's
  // own path control again.
  e_.out_.set_motion_control_mode(canon::MotionControl::ExactStop, 0);
  if (tc.z_first && z_letter >= 0 && to[z_letter] != from[z_letter]) {
    Pose up = from;
    up[z_letter] = to[z_letter];
    if (!(up == to)) go(up);
  }
  go(to);
  e_.out_.set_motion_control_mode(e_.st_.modal.control, e_.st_.modal.path_tolerance);
}

void MCodes::set_tool_number(int tool) {
  const int index = tool_index(tool, e_.block_.word_position('q'));
  e_.out_.change_tool_number(index);
  // The tool becomes current, but (as in rs274) the spindle entry and #5400.. keep the tool
  // of the last M6 until the next one.
  e_.st_.tool.current_index = index;
  SyncValues assumed;
  assumed.kind = SyncKind::ToolChange;
  assumed.position = e_.st_.position.canon_position;
  e_.request_sync(assumed);
}

void MCodes::convert_tool_change_group() {
  const int m = e_.block_.m[kGroupToolChange];
  if (m == -1) return;
  if (e_.run_extension_m(m)) return;
  if (m == 6) {
    change_tool();
    return;
  }
  const int tool = round_to_int(e_.block_.q_or(-1.0));
  if (tool < 0) {
    if (!e_.block_.has('q'))
      fail_at(e_.block_.m_position(kGroupToolChange), ErrorCode::M61QMissing,
              "M61 needs a Q word: the number of the tool in the spindle");
    fail_at(e_.block_.word_position('q'), ErrorCode::M61QMissing,
            "M61 Q{}: the tool number must be 0 or more", e_.block_.get('q'));
  }
  set_tool_number(tool);
}

// --- spindle, context, coolant, overrides -------------------------------------------------

void MCodes::convert_spindle_group() {
  const Block& b = e_.block_;
  const int m = b.m[kGroupSpindle];
  if (m == -1) return;
  if (e_.run_extension_m(m)) return;
  if (b.dollar_flag && (m == 3 || m == 4 || m == 5 || m == 19)) e_.check_spindle_number(true);
  switch (m) {
    case 3:
      e_.out_.start_spindle_clockwise(0);
      e_.st_.modal.spindle = canon::SpindleDirection::Clockwise;
      return;
    case 4:
      e_.out_.start_spindle_counterclockwise(0);
      e_.st_.modal.spindle = canon::SpindleDirection::Counterclockwise;
      return;
    case 5:
      e_.out_.stop_spindle_turning(0);
      e_.st_.modal.spindle = canon::SpindleDirection::Stopped;
      return;
    case 19:
      e_.st_.modal.spindle = canon::SpindleDirection::Stopped;
      if (b.has('r') || b.has('p'))
        e_.out_.orient_spindle(0, b.has('r') ? b.get('r') : 0.0, b.has('p') ? trunc_to_int(b.get('p')) : 0);
      if (b.has('q')) {
        if (b.get('q') <= 0.0)
          fail_at(b.word_position('q'), ErrorCode::M19Timeout,
                  "M19 Q{}: the time to wait for the orientation must be above 0", b.get('q'));
        e_.out_.wait_spindle_orient_complete(0, b.get('q'));
      }
      return;
    case 70:
    case 73:
      save_context(m == 73 && e_.st_.frames.size() > 1);
      return;
    case 71:
      e_.st_.frames.back().saved.valid = false;
      return;
    case 72:
      if (!e_.st_.frames.back().saved.valid)
        fail_at(b.m_position(kGroupSpindle), ErrorCode::RestoreWithoutSave,
                "M72 restores the modal state saved by M70 or M73, and none is saved at this call level");
      restore_context(e_.st_.frames.back().saved);
      return;
    default:
      return;
  }
}

SavedContext MCodes::active_context() const {
  const ModalState& m = e_.st_.modal;
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
  for (int i = 0; i < kAxisCount; ++i) offset = offset || e_.st_.position.tool_offset[i] != 0.0;
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

void MCodes::save_context(bool restore_on_return) {
  SavedContext c = active_context();
  c.valid = true;
  c.restore_on_return = restore_on_return;
  e_.st_.frames.back().saved = c;
}

// Restores modes by executing the G-code that re-establishes them, as LinuxCNC does, so that
// the same canonical calls are made: units first, then F/S and M codes, then G codes.
void MCodes::restore_context(const SavedContext& saved) {
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

void MCodes::execute_text(std::string_view text) {
  const Block saved_block = e_.block_;
  const std::string saved_raw = e_.line_.raw;
  auto saved_numbered = e_.parser_.numbered_assignments;
  auto saved_named = e_.parser_.named_assignments;
  e_.line_.raw.assign(text);
  if (e_.line_.norm.size() < e_.line_.raw.size() + 1) e_.line_.norm.resize(e_.line_.raw.size() + 1);
  std::vector<char> saved_norm(e_.line_.norm.begin(),
                               e_.line_.norm.begin() + static_cast<std::ptrdiff_t>(e_.line_.norm_len));
  const std::size_t n = normalize_line(e_.line_.raw, e_.line_.norm.data());
  e_.parser_.parse(std::string_view(e_.line_.norm.data(), n), e_.parse_env(), e_.block_);
  e_.checks_.enhance_block();
  e_.checks_.check_block();
  e_.apply_assignments();
  e_.execute_block();
  e_.block_ = saved_block;
  e_.line_.raw = saved_raw;
  std::copy(saved_norm.begin(), saved_norm.end(), e_.line_.norm.begin());
  e_.parser_.numbered_assignments = std::move(saved_numbered);
  e_.parser_.named_assignments = std::move(saved_named);
}

void MCodes::convert_coolant() {
  const int m = e_.block_.m[kGroupCoolant];
  if (m == -1) return;
  if (e_.run_extension_m(m)) return;
  if (m == 7) {
    e_.out_.mist_on();
    e_.st_.modal.mist = true;
  } else if (m == 8) {
    e_.out_.flood_on();
    e_.st_.modal.flood = true;
  } else {
    e_.out_.mist_off();
    e_.st_.modal.mist = false;
    e_.out_.flood_off();
    e_.st_.modal.flood = false;
  }
}

void MCodes::convert_overrides() {
  const int m = e_.block_.m[kGroupOverride];
  if (m == -1) return;
  if (e_.run_extension_m(m)) return;
  if (e_.st_.modal.cutter_comp != CutterComp::Off)
    fail_at(e_.block_.m_position(kGroupOverride), ErrorCode::CompOverrides,
            "M{} cannot switch overrides while cutter compensation is on: G40 first", m);
  // M50..M53: P0 disables, any other P (or none) enables.
  const bool enable = m == 48 || (m != 49 && e_.block_.p_or(-1.0) != 0.0);
  ModalState& s = e_.st_.modal;
  switch (m) {
    case 48:
    case 49:
      if (enable) {
        e_.out_.enable_feed_override();
        e_.out_.enable_speed_override(0);
      } else {
        e_.out_.disable_feed_override();
        e_.out_.disable_speed_override(0);
      }
      s.feed_override = s.speed_override = enable;
      return;
    case 50:
      enable ? e_.out_.enable_feed_override() : e_.out_.disable_feed_override();
      s.feed_override = enable;
      return;
    case 51:
      enable ? e_.out_.enable_speed_override(0) : e_.out_.disable_speed_override(0);
      s.speed_override = enable;
      return;
    case 52:
      enable ? e_.out_.enable_adaptive_feed() : e_.out_.disable_adaptive_feed();
      s.adaptive_feed = enable;
      return;
    default:
      enable ? e_.out_.enable_feed_hold() : e_.out_.disable_feed_hold();
      s.feed_hold = enable;
      return;
  }
}

// --- stops and end ------------------------------------------------------------------------

void MCodes::convert_stop() {
  const int m = e_.block_.m[kGroupStop];
  if (e_.run_extension_m(m)) return;
  if (e_.dialect_.stop_code && e_.dialect_.stop_code(e_, m)) return;  // its calls and returns (M98, M99)
  if (e_.st_.modal.cutter_comp != CutterComp::Off && e_.ext_ != nullptr && e_.ext_->compensator) {
    const Engine::ExtensionSite site(e_, e_.block_.m_position(kGroupStop));
    e_.ext_->compensator->finish(e_.ctx_);
  }
  switch (m) {
    case 0:
      e_.out_.program_stop();
      e_.request_stop_sync();
      return;
    case 60:
      e_.out_.pallet_shuttle();
      e_.out_.program_stop();
      e_.request_stop_sync();
      return;
    case 1:
      e_.out_.optional_program_stop();
      e_.request_stop_sync();
      return;
    case 2:
    case 30:
      end_program(m);
      return;
    default:
      break;
  }
  // M99. In a subprogram it is its return, read as such when it starts the line.
  if (e_.st_.frames.size() > 1)
    fail_at(
        e_.block_.m_position(kGroupStop), ErrorCode::OwordSyntax,
        "M99 returns from a subprogram only at the start of its line: put the other words on a line of their "
        "own");
  if (e_.opt_.main_m99 == MainM99::Repeat) return repeat_main();
  // Read as rs274 reads it; a reader of the scan (a preflight, `opencnc check`) should know
  // that the machine will not stop here.
  if (!e_.mdi_.active)
    e_.warn_once(warned_repeat_, ErrorCode::MainProgramRepeats,
                 "M99 in the main program: the scan ends here, but a run on the machine starts the program "
                 "again from its first line, endlessly, until the operator stops it");
  end_program(m);
}

// M99 in the main program with MainM99::Repeat: what LinuxCNC's task does, back to the first
// line with every setting and parameter as it is (no program-end reset). A scan cannot run
// an endless program to its end: it stops after max_main_repeats passes with an error that
// says so. In execute mode each pass starts the block and loop counts afresh, so that the
// limits still bound a runaway loop inside a pass.
void MCodes::repeat_main() {
  ControlState& c = e_.st_.control;
  e_.out_.finish();
  ++c.main_repeats;
  if (e_.opt_.mode == Mode::Scan) {
    const std::uint64_t limit =
        e_.opt_.limits.max_main_repeats == 0 ? Limits{}.max_main_repeats : e_.opt_.limits.max_main_repeats;
    if (c.main_repeats > limit)
      fail_at(
          e_.block_.m_position(kGroupStop), ErrorCode::LimitMainRepeats,
          "M99 starts the main program again, endlessly: the scan stopped after {} repetitions (limit "
          "max_main_repeats); a run repeats it until the operator stops it (or a /M30 with block delete off)",
          limit);
  } else {
    e_.st_.blocks_executed = 0;
    e_.st_.loop_iterations = 0;
    e_.bounds_.restart();
  }
  e_.jump_to(c.main_start);
}

void MCodes::end_program(int code) {
  ModalState& m = e_.st_.modal;
  PositionState& s = e_.st_.position;
  auto& par = e_.st_.parameters;
  // Back to G54: the current point is re-expressed in its coordinates.
  for (int i = 0; i < kAxisCount; ++i) s.current[i] += s.origin_offset[i];
  rotate_xy(s.current[0], s.current[1], s.rotation_xy_deg);
  m.coord_system = 1;
  par[5220] = 1.0;
  for (int i = 0; i < kAxisCount; ++i) {
    const double o = par[static_cast<std::size_t>(5221 + i)];
    s.origin_offset[i] = is_rotary(static_cast<Axis>(i)) ? o : e_.offsets_.user_to_program(o);
  }
  s.rotation_xy_deg = par[5230];
  rotate_xy(s.current[0], s.current[1], -s.rotation_xy_deg);
  for (int i = 0; i < kAxisCount; ++i) s.current[i] -= s.origin_offset[i];
  e_.out_.set_g5x_offset(1, s.origin_offset);
  e_.out_.set_xy_rotation(s.rotation_xy_deg);
  if (m.plane != canon::Plane::XY) {
    e_.out_.select_plane(canon::Plane::XY);
    m.plane = canon::Plane::XY;
  }
  m.distance = DistanceMode::Absolute;
  m.feed_mode = canon::FeedMode::UnitsPerMinute;
  e_.out_.set_feed_mode(0, canon::FeedMode::UnitsPerMinute);
  m.feed_rate = 0;
  e_.out_.set_feed_rate(0);
  if (!m.feed_override) {
    e_.out_.enable_feed_override();
    m.feed_override = true;
  }
  if (!m.speed_override) {
    e_.out_.enable_speed_override(0);
    m.speed_override = true;
  }
  m.cutter_comp = CutterComp::Off;
  m.comp_first_move = true;
  e_.out_.stop_spindle_turning(0);
  m.spindle = canon::SpindleDirection::Stopped;
  e_.out_.set_spindle_mode(0, 0);
  m.motion = 10;
  if (m.mist) {
    e_.out_.mist_off();
    m.mist = false;
  }
  if (m.flood) {
    e_.out_.flood_off();
    m.flood = false;
  }
  if (code == 30) e_.out_.pallet_shuttle();
  e_.out_.program_end();
  if (e_.st_.percent_delimited && !e_.mdi_.active) {
    // A '%'-delimited file should still have its closing '%' after M2/M30.
    SourceFile& f = e_.current_file();
    if (e_.need_seek_) {
      f.seek(e_.st_.next.offset);
      e_.need_seek_ = false;
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
    if (!found) e_.out_.comment("interpreter: percent sign missing from end of file");
  }
  e_.st_.frames.resize(1);
  e_.st_.control.skipping_to.clear();
  e_.st_.control.seeking_sub.clear();
  e_.st_.control.defining_sub = false;
  e_.st_.ended = true;
}

}  // namespace opencnc::gcode
