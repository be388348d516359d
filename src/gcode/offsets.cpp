// SPDX-License-Identifier: GPL-3.0-or-later
// Units, coordinate systems (G54..G59.3, G10 L2/L20), axis offsets (G52, G92 family),
// reference points (G28/G30 and .1), tool offsets (G43 family, G49, G10 L1/L10/L11).
#include <cmath>

#include "engine.hpp"
#include "numeric.hpp"

namespace opencnc::gcode {

namespace {
bool linear(int axis) noexcept { return !is_rotary(static_cast<Axis>(axis)); }
bool near_int(int& result, double v) noexcept {
  result = trunc_to_int(v + 0.5);
  return std::fabs(result - v) < 0.0001;
}
}  // namespace

void Offsets::update_unit_factor() noexcept {
  user_to_program_factor_ = canon::mm_per_unit(e_.opt_.user_units) / canon::mm_per_unit(e_.st_.modal.units);
}

void Offsets::set_units(int code) {
  // LinuxCNC lets the units change while compensation is on; the radius is converted below.
  const canon::Units units = code == 200 ? canon::Units::Inch : canon::Units::Mm;
  units_programmed_ = true;
  e_.out_.use_length_units(units);
  if (e_.st_.modal.units == units) return;
  const double k = units == canon::Units::Inch ? 1.0 / 25.4 : 25.4;
  PositionState& p = e_.st_.position;
  for (int i : {0, 1, 2, 6, 7, 8}) {
    p.current[i] *= k;
    p.axis_offset[i] *= k;
    p.origin_offset[i] *= k;
  }
  for (double& v : p.programmed) v *= k;
  e_.st_.modal.comp_radius *= k;
  // Compensation may run on (as in LinuxCNC): what it holds between blocks changes units too.
  if (e_.st_.modal.cutter_comp != CutterComp::Off && e_.ext_ != nullptr && e_.ext_->compensator)
    e_.ext_->compensator->rescale(e_.ctx_, k);
  // LinuxCNC rereads the tool offset and the feed rate from its canon, which keeps the values
  // it was given: neither is converted.
  e_.st_.modal.units = units;
  update_unit_factor();
}

Pose Offsets::current_in_system(int system, bool without_tlo) const {
  const PositionState& s = e_.st_.position;
  const auto& par = e_.st_.parameters;
  Pose p = s.current;
  for (int i = 0; i < kAxisCount; ++i) p[i] += s.axis_offset[i];
  rotate_xy(p[0], p[1], s.rotation_xy_deg);
  for (int i = 0; i < kAxisCount; ++i) {
    p[i] += s.origin_offset[i];
    if (without_tlo) p[i] += s.tool_offset[i];
    const double o = par[static_cast<std::size_t>(5201 + 20 * system + i)];
    p[i] -= linear(i) ? user_to_program(o) : o;
  }
  rotate_xy(p[0], p[1], -par[static_cast<std::size_t>(5210 + 20 * system)]);
  if (par[5210] != 0.0) {
    for (int i = 0; i < kAxisCount; ++i) {
      const double g = par[static_cast<std::size_t>(5211 + i)];
      p[i] -= linear(i) ? user_to_program(g) : g;
    }
  }
  return p;
}

// Absolute (machine) coordinates in program units → the active system under the current
// offsets (LinuxCNC's find_relative).
Pose Offsets::machine_to_program(const Pose& m) const {
  const PositionState& s = e_.st_.position;
  Pose r;
  double x = m[0] - s.origin_offset[0] - s.tool_offset[0];
  double y = m[1] - s.origin_offset[1] - s.tool_offset[1];
  rotate_xy(x, y, -s.rotation_xy_deg);
  r[0] = x - s.axis_offset[0];
  r[1] = y - s.axis_offset[1];
  r[2] = m[2] - s.origin_offset[2] - s.axis_offset[2] - s.tool_offset[2];
  for (int i = 3; i < 6; ++i) r[i] = m[i] - s.origin_offset[i] - s.axis_offset[i];
  for (int i = 6; i < 9; ++i) r[i] = m[i] - s.origin_offset[i] - s.axis_offset[i] - s.tool_offset[i];
  return r;
}

Pose Offsets::program_to_machine(const Pose& p) const {
  const PositionState& s = e_.st_.position;
  Pose m;
  double x = p[0] + s.axis_offset[0];
  double y = p[1] + s.axis_offset[1];
  rotate_xy(x, y, s.rotation_xy_deg);
  m[0] = x + s.origin_offset[0] + s.tool_offset[0];
  m[1] = y + s.origin_offset[1] + s.tool_offset[1];
  m[2] = p[2] + s.origin_offset[2] + s.axis_offset[2] + s.tool_offset[2];
  for (int i = 3; i < 6; ++i) m[i] = p[i] + s.origin_offset[i] + s.axis_offset[i];
  for (int i = 6; i < 9; ++i) m[i] = p[i] + s.origin_offset[i] + s.axis_offset[i] + s.tool_offset[i];
  return m;
}

void Offsets::set_coordinate_system(int code) {
  if (e_.st_.modal.cutter_comp != CutterComp::Off)
    fail_at(e_.block_.g_position(kGroupCoordSystem), ErrorCode::CompCoordinateSystem,
            "{} cannot change the coordinate system while cutter compensation is on: G40 first",
            g_name(code));
  int origin = 1;
  switch (code) {
    case 540: origin = 1; break;
    case 550: origin = 2; break;
    case 560: origin = 3; break;
    case 570: origin = 4; break;
    case 580: origin = 5; break;
    case 590: origin = 6; break;
    case 591: origin = 7; break;
    case 592: origin = 8; break;
    case 593: origin = 9; break;
    default: break;
  }
  if (origin == e_.st_.modal.coord_system) {
    e_.out_.comment("interpreter: continuing to use same coordinate system");
    return;
  }
  PositionState& s = e_.st_.position;
  s.current = current_in_system(origin, false);
  e_.st_.modal.coord_system = origin;
  e_.st_.parameters[5220] = origin;
  for (int i = 0; i < kAxisCount; ++i) {
    const double o = e_.st_.parameters[static_cast<std::size_t>(5201 + 20 * origin + i)];
    s.origin_offset[i] = linear(i) ? user_to_program(o) : o;
  }
  s.rotation_xy_deg = e_.st_.parameters[static_cast<std::size_t>(5210 + 20 * origin)];
  e_.out_.set_g5x_offset(origin, s.origin_offset);
  e_.out_.set_g92_offset(s.axis_offset);
  e_.out_.set_xy_rotation(s.rotation_xy_deg);
}

void Offsets::convert_modal_0(int code) {
  switch (code) {
    case 100:
      if (e_.block_.get('l') == 1 || e_.block_.get('l') == 10 || e_.block_.get('l') == 11)
        g10_tool();
      else g10_coordinate_system();
      return;
    case 280:
    case 300:
      go_home(code);
      return;
    case 281:
    case 301:
      save_home(code);
      return;
    case 520:
    case 920:
    case 921:
    case 922:
    case 923:
      axis_offsets(code);
      return;
    case 53:   // G5.3 ends a NURBS before the block's motion (the splines module)
      if (!e_.run_extension_g(code)) e_.unsupported_g(code, e_.block_.g_position(kGroupNonModal));
      return;
    default:
      return;   // G4 and G53 are handled in their own steps
  }
}

void Offsets::g10_coordinate_system() {
  const Block& b = e_.block_;
  if (b.has('i') || b.has('j'))
    fail_at(b.word_position(b.has('i') ? 'i' : 'j'), ErrorCode::G10IjWords,
            "I and J cannot be used with G10 L{}: they set tool angles (G10 L1)",
            static_cast<int>(b.get('l')));
  auto& par = e_.st_.parameters;
  PositionState& s = e_.st_.position;
  const bool l20 = b.get('l') == 20;
  int p = trunc_to_int(b.get('p') + 0.0001);
  if (p == 0) p = e_.st_.modal.coord_system;
  const bool active = p == e_.st_.modal.coord_system;
  if (e_.st_.modal.cutter_comp != CutterComp::Off && active)
    fail_at(
        b.g_position(kGroupNonModal), ErrorCode::CompActiveSystemOffset,
        "G10 L{} cannot move the active coordinate system (P{}) while cutter compensation is on: G40 first",
        static_cast<int>(b.get('l')), p);
  const Pose c = current_in_system(p, false);
  const std::size_t base = static_cast<std::size_t>(5200 + 20 * p);
  double r;
  if (b.has('r')) {
    if (l20)
      fail_at(b.word_position('r'), ErrorCode::G10L20Rotation,
              "R (rotation) cannot be used with G10 L20: set it with G10 L2");
    r = b.get('r');
    par[base + 10] = r;
  } else {
    r = par[base + 10];
  }
  Pose v{};
  if (l20) {
    // New origin such that the current point gets the given coordinates (rotation applied).
    double oldx = c[0], oldy = c[1];
    double x = b.has('x') ? b.get('x') : c[0];
    double y = b.has('y') ? b.get('y') : c[1];
    rotate_xy(oldx, oldy, r);
    rotate_xy(x, y, r);
    v[0] = oldx + user_to_program(par[base + 1]) - x;
    v[1] = oldy + user_to_program(par[base + 2]) - y;
    par[base + 1] = program_to_user(v[0]);
    par[base + 2] = program_to_user(v[1]);
    if (active) {
      rotate_xy(s.current[0], s.current[1], s.rotation_xy_deg);
      s.rotation_xy_deg = 0;
    }
  } else {
    for (int i = 0; i < 2; ++i) {
      if (b.has(kAxisWordLetters[i])) {
        v[i] = b.get(kAxisWordLetters[i]);
        par[base + 1 + static_cast<std::size_t>(i)] = program_to_user(v[i]);
      } else {
        v[i] = user_to_program(par[base + 1 + static_cast<std::size_t>(i)]);
      }
    }
  }
  for (int i = 2; i < kAxisCount; ++i) {
    const std::size_t k = base + 1 + static_cast<std::size_t>(i);
    const bool lin = linear(i);
    if (b.has(kAxisWordLetters[i])) {
      v[i] = b.get(kAxisWordLetters[i]);
      if (l20) v[i] = c[i] + (lin ? user_to_program(par[k]) : par[k]) - v[i];
      par[k] = lin ? program_to_user(v[i]) : v[i];
    } else {
      v[i] = lin ? user_to_program(par[k]) : par[k];
    }
  }
  if (!active) {
    e_.out_.comment("interpreter: setting coordinate system origin");
    return;
  }
  rotate_xy(s.current[0], s.current[1], s.rotation_xy_deg);
  for (int i = 0; i < kAxisCount; ++i) {
    s.current[i] += s.origin_offset[i];
    s.origin_offset[i] = v[i];
    s.current[i] -= v[i];
  }
  e_.out_.set_g5x_offset(p, s.origin_offset);
  rotate_xy(s.current[0], s.current[1], -r);
  s.rotation_xy_deg = r;
  e_.out_.set_xy_rotation(r);
}

void Offsets::g10_tool() {
  const Block& b = e_.block_;
  int toolno;
  near_int(toolno, b.get('p'));
  const int index = e_.mcodes_.tool_index(toolno, b.word_position('p'));
  const bool any = b.any_axis() || b.has('r') || b.has('q') || b.has('i') || b.has('j');
  if (!any)
    fail_at(b.g_position(kGroupNonModal), ErrorCode::G10NoOffsets,
            "G10 L{} without any value changes nothing: give axis words, R, I, J or Q",
            static_cast<int>(b.get('l')));
  tools::ToolEntry e = e_.st_.tool.table[static_cast<std::size_t>(index)];
  const int l = static_cast<int>(b.get('l'));
  if (l == 1) {
    for (int i = 0; i < kAxisCount; ++i) {
      if (b.has(kAxisWordLetters[i])) e.offset[i] = linear(i) ? program_to_user(b.get(kAxisWordLetters[i])) : b.get(kAxisWordLetters[i]);
    }
  } else {
    // L10/L11: offsets such that the current point (without tool offset) reads as given.
    const bool fixture = l == 11;
    const int dest = fixture ? 9 : e_.st_.modal.coord_system;
    Pose t = current_in_system(dest, true);
    if (fixture && e_.st_.parameters[5210] != 0.0) {
      for (int i = 0; i < kAxisCount; ++i) {
        const double g = e_.st_.parameters[static_cast<std::size_t>(5211 + i)];
        t[i] += linear(i) ? user_to_program(g) : g;
      }
    }
    const double rot = e_.st_.parameters[static_cast<std::size_t>(5210 + dest * 20)];
    if (b.has('x') && b.has('y')) {
      double tx = t[0] - b.get('x'), ty = t[1] - b.get('y');
      rotate_xy(tx, ty, rot);
      e.offset[0] = program_to_user(tx);
      e.offset[1] = program_to_user(ty);
    } else if (b.has('x') || b.has('y')) {
      // Keep the component of the old offset along the axis not given (in rotated axes).
      double ox = user_to_program(e.offset[0]), oy = user_to_program(e.offset[1]);
      rotate_xy(ox, oy, -rot);
      double tx, ty;
      if (b.has('x')) {
        ox = 0;
        tx = t[0] - b.get('x');
        ty = 0;
      } else {
        oy = 0;
        tx = 0;
        ty = t[1] - b.get('y');
      }
      rotate_xy(ox, oy, rot);
      rotate_xy(tx, ty, rot);
      e.offset[0] = program_to_user(tx + ox);
      e.offset[1] = program_to_user(ty + oy);
    }
    for (int i = 2; i < kAxisCount; ++i) {
      if (!b.has(kAxisWordLetters[i])) continue;
      const double v = t[i] - b.get(kAxisWordLetters[i]);
      e.offset[i] = linear(i) ? program_to_user(v) : v;
    }
  }
  if (b.has('r')) e.diameter = program_to_user(b.get('r')) * 2.0;
  if (b.has('i')) e.front_angle = b.get('i');
  if (b.has('j')) e.back_angle = b.get('j');
  if (b.q_or(-1.0) != -1.0) {
    int q;
    if (!near_int(q, b.get('q')))
      fail_at(b.word_position('q'), ErrorCode::G10Orientation,
              "Q{}: the tool orientation must be a whole number, 0 to 9", b.get('q'));
    if (q > 9)
      fail_at(b.word_position('q'), ErrorCode::G10Orientation, "Q{}: the tool orientation must be 0 to 9", q);
    e.orientation = q;
  }
  e_.st_.tool.table[static_cast<std::size_t>(index)] = e;
  e_.out_.set_tool_table_entry(index, e.tool, e.offset, e.diameter, e.front_angle, e.back_angle,
                               e.orientation);
  if (index == e_.st_.tool.current_index) {
    e_.st_.tool.table[0] = e;
    e_.mcodes_.set_tool_parameters();
    e_.out_.set_tool_table_entry(0, e.tool, e.offset, e.diameter, e.front_angle, e.back_angle, e.orientation);
  } else {
    e_.mcodes_.set_tool_parameters();
  }
}

void Offsets::axis_offsets(int code) {
  if (e_.st_.modal.cutter_comp != CutterComp::Off)
    fail_at(e_.block_.g_position(kGroupNonModal), ErrorCode::CompAxisOffsets,
            "{} cannot change the axis offsets while cutter compensation is on: G40 first", g_name(code));
  const Block& b = e_.block_;
  auto& par = e_.st_.parameters;
  PositionState& s = e_.st_.position;
  if (code == 520 || code == 920) {
    par[5210] = 1.0;
    for (int i = 0; i < kAxisCount; ++i) {
      const char letter = kAxisWordLetters[i];
      if (!b.has(letter)) continue;
      if (code == 520) {
        s.current[i] += s.axis_offset[i] - b.get(letter);
        s.axis_offset[i] = b.get(letter);
      } else {
        s.axis_offset[i] = s.current[i] + s.axis_offset[i] - b.get(letter);
        s.current[i] = b.get(letter);
      }
    }
    e_.out_.set_g92_offset(s.axis_offset);
    for (int i = 0; i < kAxisCount; ++i)
      par[static_cast<std::size_t>(5211 + i)] = linear(i) ? program_to_user(s.axis_offset[i]) : s.axis_offset[i];
  } else if (code == 921 || code == 922) {
    par[5210] = 0.0;
    for (int i = 0; i < kAxisCount; ++i) s.current[i] += s.axis_offset[i];
    e_.out_.set_g92_offset(Pose{});
    s.axis_offset = Pose{};
    if (code == 921) {
      for (int i = 0; i < kAxisCount; ++i) par[static_cast<std::size_t>(5211 + i)] = 0.0;
    }
  } else {   // G92.3: offsets back from the parameters
    par[5210] = 1.0;
    for (int i = 0; i < kAxisCount; ++i) {
      const double g = par[static_cast<std::size_t>(5211 + i)];
      const double v = linear(i) ? user_to_program(g) : g;
      s.current[i] = s.current[i] + s.axis_offset[i] - v;
      s.axis_offset[i] = v;
    }
    e_.out_.set_g92_offset(s.axis_offset);
  }
}

void Offsets::go_home(int code) {
  Pose end = e_.motion_.find_ends(e_.block_);
  if (e_.st_.modal.cutter_comp != CutterComp::Off)
    fail_at(e_.block_.g_position(kGroupNonModal), ErrorCode::CompG28G30,
            "{} cannot be used while cutter compensation is on: G40 first", g_name(code));
  e_.out_.straight_traverse(0, end);
  e_.st_.position.current = end;
  Pose home_machine;
  const std::size_t base = code == 280 ? 5161 : 5181;
  for (int i = 0; i < kAxisCount; ++i) {
    const double v = e_.st_.parameters[base + static_cast<std::size_t>(i)];
    home_machine[i] = linear(i) ? user_to_program(v) : v;
  }
  const Pose home = machine_to_program(home_machine);
  const bool any = e_.block_.any_axis();
  for (int i = 0; i < kAxisCount; ++i) {
    if (!any || e_.block_.has(kAxisWordLetters[i])) end[i] = home[i];
  }
  e_.out_.straight_traverse(0, end);
  e_.st_.position.current = end;
}

void Offsets::save_home(int code) {
  if (e_.st_.modal.cutter_comp != CutterComp::Off)
    fail_at(e_.block_.g_position(kGroupNonModal), ErrorCode::CompReferencePoint,
            "{} cannot store a reference point while cutter compensation is on: G40 first", g_name(code));
  // The machine position: X and Y leave the G92 frame through the XY rotation (LinuxCNC's
  // convert_savehome), the inverse of machine_to_program().
  const PositionState& s = e_.st_.position;
  Pose p = s.current;
  for (int i = 0; i < kAxisCount; ++i) p[i] += s.axis_offset[i];
  rotate_xy(p[0], p[1], s.rotation_xy_deg);
  const std::size_t base = code == 281 ? 5161 : 5181;
  for (int i = 0; i < kAxisCount; ++i) {
    const double v = p[i] + s.tool_offset[i] + s.origin_offset[i];
    e_.st_.parameters[base + static_cast<std::size_t>(i)] = linear(i) ? program_to_user(v) : v;
  }
}

void Offsets::tool_length_offset(int code) {
  const Block& b = e_.block_;
  if (e_.st_.modal.cutter_comp != CutterComp::Off)
    fail_at(b.g_position(kGroupToolLength), ErrorCode::CompToolOffset,
            "{} cannot change the tool length offset while cutter compensation is on: G40 first",
            g_name(code));
  PositionState& s = e_.st_.position;
  Pose offset{};
  auto from_table = [&](int index) {
    Pose o;
    const auto& e = e_.st_.tool.table[static_cast<std::size_t>(index)];
    for (int i = 0; i < kAxisCount; ++i) o[i] = linear(i) ? user_to_program(e.offset[i]) : e.offset[i];
    return o;
  };
  if (code == 430) {
    const int index = b.has('h') ? e_.mcodes_.tool_index(static_cast<int>(b.get('h')), b.word_position('h'))
                                 : (e_.block_.m[kGroupToolChange] != -1 ? e_.st_.tool.current_index : 0);
    offset = from_table(index);
  } else if (code == 431) {
    offset = s.tool_offset;
    for (int i = 0; i < kAxisCount; ++i) {
      if (b.has(kAxisWordLetters[i])) offset[i] = b.get(kAxisWordLetters[i]);
    }
  } else if (code == 432) {
    // LinuxCNC 2.9 adds the offset of the tool H names; axis words do not replace H there
    // (rs274 looks up a tool -1), so G43.2 always needs H and takes no axis words.
    const int at = b.g_position(kGroupToolLength);
    if (b.has('h') && b.any_axis())
      fail_at(b.first_axis_position(), ErrorCode::G43_2AxisWords,
              "G43.2 takes an H word only: remove the axis words");
    if (!b.has('h'))
      fail_at(at, ErrorCode::G43_2HMissing, "G43.2 needs an H word: the tool whose length offset it adds{}",
              b.any_axis() ? " (axis words cannot replace it)" : "");
    offset = s.tool_offset;
    const Pose add = from_table(e_.mcodes_.tool_index(static_cast<int>(b.get('h')), b.word_position('h')));
    for (int i = 0; i < kAxisCount; ++i) offset[i] += add[i];
  }
  e_.out_.use_tool_length_offset(offset);
  // The controlled point stays where it is: its coordinates change by the offset change.
  double dx = s.tool_offset[0] - offset[0];
  double dy = s.tool_offset[1] - offset[1];
  rotate_xy(dx, dy, -s.rotation_xy_deg);
  s.current[0] += dx;
  s.current[1] += dy;
  for (int i = 2; i < kAxisCount; ++i) s.current[i] += s.tool_offset[i] - offset[i];
  s.tool_offset = offset;
  e_.st_.modal.tool_length_mode = code;
}

}  // namespace opencnc::gcode
