// SPDX-License-Identifier: GPL-3.0-or-later
// G40/G41/G42/G41.1/G42.1 and the motion stage of cutter radius compensation.
#include "opencnc/gcode/cutter_comp.hpp"

#include <cmath>
#include <memory>

#include "comp_path.hpp"
#include "gcode_error.hpp"
#include "numeric.hpp"

namespace opencnc::gcode {

namespace {

// Index in the interpreter's tool table copy of tool `tool` (0: the spindle entry).
std::size_t tool_index(const InterpState& st, int tool) {
  if (tool == 0) return 0;
  for (std::size_t i = 1; i < st.tool.table.size(); ++i) {
    if (st.tool.table[i].tool == tool) return i;
  }
  fail(ErrorCode::ToolNotFound, "tool {} (D word) is not in the tool table", tool);
}

// A tool table length (machine units) in program units, as LinuxCNC converts it: through
// millimetres, an inch being 1 / 0.03937007874016 mm (the stand-alone interpreter's value;
// exact 25.4 would differ in the last bits and, now and then, in rs274's fourth decimal).
double user_to_program_length(double v, canon::Units user, canon::Units program) noexcept {
  const double mm = user == canon::Units::Inch ? v / 0.03937007874016 : v;
  return program == canon::Units::Inch ? mm / 25.4 : mm;
}

// Radius (program units) and lathe orientation from a G41/G42 block's D word (a tool number)
// or the tool in the spindle.
void radius_from_tool(ExecContext& ctx, const Block& b, int code, double& radius, int& orientation) {
  const InterpState& st = ctx.state();
  std::size_t index = 0;
  if (b.has('d')) {
    const double d = b.get('d');
    const int tool = trunc_to_int(d + 0.5);
    if (std::fabs(tool - d) >= 0.0001)
      fail(ErrorCode::CompToolNumber, "G{} needs a whole tool number in D (got {})", code / 10, d);
    index = tool_index(st, tool);
  }
  const tools::ToolEntry& t = st.tool.table[index];
  radius = user_to_program_length(t.diameter, ctx.options().user_units, st.modal.units) / 2.0;
  orientation = t.orientation;
  if (st.modal.plane != canon::Plane::XZ && orientation != 0 && orientation != 9)
    fail(ErrorCode::CompWrongPlane, "G{} with a lathe tool (orientation {}) needs the XZ plane (G18)",
         code / 10, orientation);
}

// The held moves end where the tool is (checked for gouges) and go out.
void release_at_tool(ExecContext& ctx) {
  comp::CompPath path(ctx);
  double c1, c2, c3;
  path.current(c1, c2, c3);
  path.settle(c1, c2);
  path.release();
}

// G41, G42 (tool table) and G41.1, G42.1 (diameter in D, orientation in L): compensation
// starts with the next move in the plane.
class CompOn final : public CodeHandler {
 public:
  void execute(ExecContext& ctx, const Block& b, int code) override {
    InterpState& st = ctx.state();
    ModalState& m = st.modal;
    if (m.plane != canon::Plane::XY && m.plane != canon::Plane::XZ)
      fail(ErrorCode::CompYzPlane, "cutter compensation works only in the XY (G17) and XZ (G18) planes");
    if (m.cutter_comp != CutterComp::Off)
      fail(ErrorCode::CompAlreadyOn, "cutter compensation is already on (G40 ends it)");
    const bool dynamic = code % 10 == 1;
    bool left = code / 10 == 41;
    double radius = 0;
    int orientation = 0;
    if (dynamic) {
      if (!b.has('d'))
        fail(ErrorCode::CompDiameterMissing, "G{}.1 needs the tool diameter in a D word", code / 10);
      radius = b.get('d') / 2.0;
      if (b.has('l')) {
        if (m.plane != canon::Plane::XZ)
          fail(ErrorCode::CompWrongPlane, "G{}.1 with a lathe tool orientation (L) needs the XZ plane (G18)",
               code / 10);
        orientation = round_to_int(b.get('l'));
      }
    } else {
      radius_from_tool(ctx, b, code, radius, orientation);
    }
    // A negative radius (a tool smaller than the path was made for) offsets to the other side.
    if (radius < 0) {
      radius = -radius;
      left = !left;
    }
    ctx.output().comment(left ? "interpreter: cutter radius compensation on left"
                              : "interpreter: cutter radius compensation on right");
    m.comp_radius = radius;
    m.comp_orientation = orientation;
    m.cutter_comp = left ? CutterComp::Left : CutterComp::Right;
  }
};

// G40: the last move's end is settled against nothing (it ends where the tool is), the
// held moves are released, and the tool continues from the programmed point.
class CompOff final : public CodeHandler {
 public:
  void execute(ExecContext& ctx, const Block&, int) override {
    ctx.output().comment("interpreter: cutter radius compensation off");
    InterpState& st = ctx.state();
    ModalState& m = st.modal;
    if (m.cutter_comp != CutterComp::Off && m.comp_radius > 0.0 && !m.comp_first_move) {
      release_at_tool(ctx);
      for (int i = 0; i < 3; ++i)
        st.position.current[i] = st.position.programmed[static_cast<std::size_t>(i)];
      m.arc_not_allowed = true;  // the move after G40 has no corner to join: a line
    }
    m.cutter_comp = CutterComp::Off;
    m.comp_first_move = true;
  }
};

class Compensator final : public MotionStage {
 public:
  void straight(ExecContext& ctx, bool rapid, const Pose& end) override {
    comp::CompPath path(ctx);
    if (ctx.state().modal.comp_first_move)
      comp::straight_first(path, rapid, end);
    else
      comp::straight_next(path, rapid, end);
  }
  void arc(ExecContext& ctx, const Block& block, int motion, const Pose& end) override {
    comp::CompPath path(ctx);
    if (ctx.state().modal.comp_first_move)
      comp::arc_first(path, ctx, block, motion, end);
    else
      comp::arc_next(path, ctx, block, motion, end);
  }
  // M0, M1, M2, M30, M60: the held moves end where the tool is (checked for gouges) and go
  // out; compensation stays on, from the tool's position.
  void finish(ExecContext& ctx) override { release_at_tool(ctx); }
  void rescale(ExecContext& ctx, double factor) override {
    CompState& cs = ctx.state().comp;
    // LinuxCNC scales its queue's start point once per queued call, not once: reproduced,
    // since the gouge checks measure from it.
    for (std::size_t i = 0; i < ctx.queued(); ++i) {
      cs.start1 *= factor;
      cs.start2 *= factor;
    }
    for (CompQueuedMove& q : cs.queued) {
      q.center1 *= factor;
      q.center2 *= factor;
      q.end1 *= factor;
      q.end2 *= factor;
    }
  }
};

}  // namespace

void add_cutter_compensation(Extensions& ext) {
  auto on = std::make_shared<CompOn>();
  for (int code : {410, 420, 411, 421}) ext.g[static_cast<std::size_t>(code)] = on;
  ext.g[400] = std::make_shared<CompOff>();
  ext.compensator = std::make_shared<Compensator>();
}

}  // namespace opencnc::gcode
