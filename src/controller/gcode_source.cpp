// SPDX-License-Identifier: GPL-3.0-or-later
// Programs and MDI lines: interpreter → (default tolerance) → ProgramBuilder.
#include "opencnc/controller/gcode_source.hpp"

#include <cmath>

#include <fmt/format.h>

#include "opencnc/canon/tee_sink.hpp"
#include "opencnc/gcode/standard_extensions.hpp"
#include "opencnc/tools/tool_table.hpp"

namespace opencnc::control {

namespace {

/// Passes every call on to the builder (through a TeeSink) and follows a G64 without P with the
/// profile's default tolerance: the planner reads the later of two settings at the same move.
class DefaultTolerance final : public canon::Sink {
 public:
  DefaultTolerance(canon::ProgramBuilder& b, double tolerance_mm, canon::Units units)
      : b_(b), tolerance_mm_(tolerance_mm), units_(units) {}
  void use_length_units(canon::Units u) override { units_ = u; }
  void set_motion_control_mode(canon::MotionControl mode, double tolerance) override {
    // The builder takes tolerances in program units.
    if (mode == canon::MotionControl::Continuous && tolerance <= 0 && tolerance_mm_ > 0)
      b_.set_motion_control_mode(mode, tolerance_mm_ / canon::mm_per_unit(units_));
  }

 private:
  canon::ProgramBuilder& b_;
  double tolerance_mm_;
  canon::Units units_;
};

std::vector<Diagnostic> since(const Diagnostics& d, std::size_t first) {
  return {d.items().begin() + static_cast<std::ptrdiff_t>(std::min(first, d.items().size())),
          d.items().end()};
}

}  // namespace

std::shared_ptr<GcodeProgramSource> GcodeProgramSource::create(const config::MachineProfile& profile,
                                                               Diagnostics& diags) {
  gcode::Options o;
  o.dialect = profile.interpreter.dialect == config::Dialect::Fanuc ? gcode::Dialect::Fanuc
                                                                    : gcode::Dialect::LinuxCnc;
  o.mode = gcode::Mode::Scan;
  o.axes = profile.axis_mask();
  o.subroutine_path = profile.interpreter.subroutine_path;
  o.user_units = canon::Units::Mm;
  o.initial_units = canon::Units::Mm;
  o.optional_stop = true;  // M1 always reaches the servo, which decides with the live switch
  o.extensions = gcode::standard_extensions(o.dialect);
  if (!profile.interpreter.tool_table.empty()) {
    const std::size_t before = diags.error_count();
    auto table = tools::ToolTable::load(profile.interpreter.tool_table, diags);
    if (!table || diags.error_count() > before) return nullptr;
    o.tool_table = std::make_shared<tools::ToolTable>(std::move(*table));
  }
  return std::shared_ptr<GcodeProgramSource>(
      new GcodeProgramSource(std::move(o), profile.planner.default_tolerance, hand_axes(profile)));
}

GcodeProgramSource::GcodeProgramSource(gcode::Options options, double default_tolerance, HandAxes hand)
    : options_(std::move(options)), default_tolerance_(default_tolerance), hand_(hand) {}

// A rapid in machine coordinates to where the machine is, without output: the interpreter's
// position follows (in its units and work coordinates). G90 for it, G91 back if it was on.
bool GcodeProgramSource::place(gcode::Interpreter& interp, const Pose& machine, Diagnostics& diags) const {
  const gcode::ModalState m = interp.state().modal;
  if (m.cutter_comp != gcode::CutterComp::Off) return true;  // it cannot have moved under compensation
  const double unit = m.units == canon::Units::Inch ? 25.4 : 1.0;
  std::string line = "G90 G53 G0";
  for (int i = 0; i < kAxisCount; ++i) {
    if (options_.axes.has(static_cast<Axis>(i)))
      line += fmt::format(" {}{:.9f}", kAxisLetters[static_cast<std::size_t>(i)], machine[i] / unit);
  }
  if (m.distance == gcode::DistanceMode::Incremental) line += "\nG91";
  line += m.motion == 10 && m.feed_rate > 0 ? "\nG1" : (m.motion == 0 ? "" : "\nG80");
  canon::Sink quiet;
  std::size_t start = 0;
  while (start < line.size()) {
    const std::size_t end = std::min(line.find('\n', start), line.size());
    if (interp.execute_mdi(std::string_view(line).substr(start, end - start), quiet) ==
        gcode::RunStatus::Error) {
      diags.error("", 0, 0, "the interpreter cannot be placed at the machine position", "control.program");
      return false;
    }
    start = end + 1;
  }
  return true;
}

LoadedProgram GcodeProgramSource::load(const std::string& path, const Pose& start,
                                       const LoadOptions& options) {
  gcode::Options o = options_;
  o.block_delete = options.block_delete;
  gcode::Interpreter interp(o);
  canon::ProgramBuilder builder(o.axes, start);
  builder.program().set_sources(interp.sources());
  DefaultTolerance tolerance(builder, default_tolerance_, canon::Units::Mm);
  canon::TeeSink sink(builder, tolerance);
  builder.set_motion_control_mode(canon::MotionControl::Continuous, default_tolerance_);  // in mm yet
  LoadedProgram out;
  // The file first (file 0 of the source map, the main program of every move; start() checks
  // its head), then the start-up calls, then the position.
  gcode::RunStatus status = gcode::RunStatus::Error;
  if (interp.open(path) && interp.start(sink) != gcode::RunStatus::Error &&
      place(interp, start, out.diagnostics)) {
    status = interp.run(sink);
  }
  for (const Diagnostic& d : interp.diagnostics().items()) out.diagnostics.add(d);
  if (status != gcode::RunStatus::Error && !out.diagnostics.has_errors())
    out.program = hand_axis_program(std::make_shared<canon::Program>(builder.take()), hand_, out.diagnostics);
  return out;
}

// The builder of each line starts from the state the session's earlier lines left: units,
// offsets, rotation, plane, feed, path control (the interpreter repeats a setting only when it
// changes, and every line gets a fresh program).
void GcodeProgramSource::replay_state(const gcode::InterpState& s, canon::ProgramBuilder& b) const {
  const gcode::ModalState& m = s.modal;
  b.use_length_units(m.units);
  b.set_g5x_offset(m.coord_system, s.position.origin_offset);
  b.set_g92_offset(s.position.axis_offset);
  b.set_xy_rotation(s.position.rotation_xy_deg);
  b.use_tool_length_offset(s.position.tool_offset);
  b.select_plane(m.plane);
  b.set_feed_mode(0, m.feed_mode);
  b.set_feed_rate(m.feed_rate);
  const double tol =
      m.control == canon::MotionControl::Continuous && m.path_tolerance <= 0
          ? default_tolerance_ / canon::mm_per_unit(m.units)  // the builder scales by the units
          : m.path_tolerance;
  b.set_motion_control_mode(m.control, tol);
  b.set_naivecam_tolerance(m.naivecam_tolerance);
  if (!m.feed_override) b.disable_feed_override();
  if (!m.feed_hold) b.disable_feed_hold();
}

LoadedProgram GcodeProgramSource::mdi(std::string_view line, const Pose& start) {
  LoadedProgram out;
  if (!mdi_) {
    mdi_ = std::make_unique<gcode::Interpreter>(options_);
    canon::Sink quiet;
    mdi_->start(quiet);
    mdi_placed_ = false;
  }
  if (!mdi_placed_ || mdi_end_ != start) {
    if (!place(*mdi_, start, out.diagnostics)) return out;
    mdi_placed_ = true;
  }
  canon::ProgramBuilder builder(options_.axes, start);
  builder.program().set_sources(mdi_->sources());
  replay_state(mdi_->state(), builder);
  DefaultTolerance tolerance(builder, default_tolerance_, mdi_->state().modal.units);
  canon::TeeSink sink(builder, tolerance);
  const std::size_t first = mdi_->diagnostics().items().size();
  const gcode::RunStatus status = mdi_->execute_mdi(line, sink);
  for (const Diagnostic& d : since(mdi_->diagnostics(), first)) out.diagnostics.add(d);
  if (status == gcode::RunStatus::Error || out.diagnostics.has_errors()) return out;
  mdi_end_ = builder.position();
  out.program = hand_axis_program(std::make_shared<canon::Program>(builder.take()), hand_, out.diagnostics);
  return out;
}

}  // namespace opencnc::control
