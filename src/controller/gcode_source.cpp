// SPDX-License-Identifier: GPL-3.0-or-later
// G-code as streams of moves: the interpreter (execute mode) → default tolerance, tool table →
// ProgramBuilder, leg by leg; and the preflight scan (scan mode) that checks every move in bounded
// memory and, for programs with sync points, finds the moves that rest on an assumed answer.
#include "opencnc/controller/gcode_source.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "opencnc/canon/program_builder.hpp"
#include "opencnc/canon/replay_filter.hpp"
#include "opencnc/canon/tee_sink.hpp"
#include "opencnc/controller/preflight.hpp"
#include "opencnc/gcode/dialect.hpp"
#include "opencnc/gcode/standard_extensions.hpp"

namespace opencnc::controller {

namespace {

/// Blocks executed per call of the interpreter while streaming; a read() stops after
/// kReadBlockBudget blocks even without moves (a long computation), so that the controller's
/// service stays short; it reads on at the next service.
constexpr std::uint64_t kBlocksPerCall = 64;
constexpr std::uint64_t kReadBlockBudget = 20000;
/// Moves a preflight scan reads before it checks them and frees what it has checked.
constexpr std::size_t kScanBatch = 4096;

/// Follows a G64 without P with the profile's default tolerance: the planner reads the later of
/// two settings at the same move.
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

/// G10 L1/L10/L11 of a running program reach the machine's tool table (pocket and comment kept).
/// A change that cannot be stored is an error: the program stops rather than cut with tool data
/// the table does not hold.
class ToolTableWriter final : public canon::Sink {
 public:
  explicit ToolTableWriter(tools::ToolTableService* tools) : tools_(tools) {}
  void set_tool_table_entry(int index, int tool, const Pose& offset, double diameter, double front_angle,
                            double back_angle, int orientation) override {
    if (tools_ == nullptr || index <= 0) return;  // entry 0 is the interpreter's copy of the spindle
    const auto table = tools_->snapshot();
    if (static_cast<std::size_t>(index) > table->size()) return;
    tools::ToolEntry e = table->at_index(static_cast<std::size_t>(index));
    e.tool = tool;
    e.offset = offset;
    e.diameter = diameter;
    e.front_angle = front_angle;
    e.back_angle = back_angle;
    e.orientation = orientation;
    tools_->update(static_cast<std::size_t>(index), e, tools::ChangeSource::Program, failures_);
  }
  Diagnostics& failures() noexcept { return failures_; }

 private:
  tools::ToolTableService* tools_;
  Diagnostics failures_;
};

SyncKind from_gcode(gcode::SyncKind k) {
  switch (k) {
    case gcode::SyncKind::Probe:
      return SyncKind::Probe;
    case gcode::SyncKind::Input:
      return SyncKind::Input;
    case gcode::SyncKind::ToolChange:
      return SyncKind::ToolChange;
    case gcode::SyncKind::ProgramStop:
      return SyncKind::ProgramStop;
    case gcode::SyncKind::None:
      break;
  }
  return SyncKind::None;
}

void append(Diagnostics& to, const Diagnostics& from, std::size_t first = 0) {
  for (std::size_t i = first; i < from.items().size(); ++i) to.add(from.items()[i]);
}

/// A canonical sink after the builder (in a TeeSink): after every call that appends moves it runs
/// a feature's pass over them. `program` is where the builder appends.
class PassSink final : public canon::Sink {
 public:
  PassSink(MovePass& pass, canon::Program& program) : pass_(pass), program_(program) {}
  void straight_traverse(canon::SegmentId, const Pose&) override { pass_.process(program_); }
  void straight_feed(canon::SegmentId, const Pose&) override { pass_.process(program_); }
  void arc_feed(canon::SegmentId, const canon::ArcFeed&) override { pass_.process(program_); }
  void straight_probe(canon::SegmentId, const Pose&) override { pass_.process(program_); }
  void rigid_tap(canon::SegmentId, const Pose&, double) override { pass_.process(program_); }
  void nurbs_feed(canon::SegmentId, int, std::span<const canon::NurbsPoint>) override {
    pass_.process(program_);
  }

 private:
  MovePass& pass_;
  canon::Program& program_;
};

using SourceParts = std::vector<std::shared_ptr<const SourcePart>>;

/// The interpreter, its builder and sinks for one program (or the MDI session's line): what a
/// stream and a preflight scan share.
class Pipeline {
 public:
  Pipeline(gcode::Interpreter& interp, const Pose& start, double tolerance_mm, tools::ToolTableService* tools,
           const SourceParts& parts)
      : interp_(&interp), tolerance_mm_(tolerance_mm), writer_(tools) {
    for (const auto& part : parts) {
      if (std::unique_ptr<MovePass> pass = part->pass()) passes_.push_back(std::move(pass));
      if (std::unique_ptr<CallPass> pass = part->call_pass()) call_passes_.push_back(std::move(pass));
    }
    auto b = std::make_unique<canon::ProgramBuilder>(interp.options().axes, start);
    b->program().set_sources(interp.sources());
    attach(std::move(b), interp.state().modal.units);
  }

  canon::ProgramBuilder& builder() noexcept { return *builder_; }
  const canon::ProgramBuilder& builder() const noexcept { return *builder_; }
  const canon::Program& program() const noexcept { return builder_->program(); }
  canon::Sink& sink() noexcept { return *sink_; }
  ToolTableWriter& writer() noexcept { return writer_; }
  /// The interpreter stopped (a sync point, the end, an error): the passes over the calls hand
  /// on what they hold, in their order.
  void flush() {
    for (const auto& pass : call_passes_) pass->flush();
  }
  /// What the features' passes refused (moves they cannot rewrite), pass by pass.
  void append_pass_failures(Diagnostics& to) const {
    for (const auto& pass : passes_) append(to, pass->failures());
  }
  bool passes_failed() const noexcept {  // a pass's warnings (the cut chart's feed check) go on
    return std::any_of(passes_.begin(), passes_.end(),
                       [](const auto& pass) { return pass->failures().has_errors(); });
  }

  /// A new leg at `start`: the builder's continuation; the old one is kept until the next leg
  /// (a run's last trace samples may still refer to its moves).
  void restart(const Pose& start) {
    auto next = builder_->continuation(start);
    previous_ = std::move(builder_);
    attach(std::move(next), interp_->state().modal.units);
  }

 private:
  void attach(std::unique_ptr<canon::ProgramBuilder> b, canon::Units units) {
    builder_ = std::move(b);
    tolerance_ = std::make_unique<DefaultTolerance>(*builder_, tolerance_mm_, units);
    inner_ = std::make_unique<canon::TeeSink>(*builder_, *tolerance_);
    outer_ = std::make_unique<canon::TeeSink>(*inner_, writer_);
    sink_ = outer_.get();
    // After the builder has appended a move, the features' passes rewrite it, in their order.
    tees_.clear();
    pass_sinks_.clear();
    for (const auto& pass : passes_) {
      pass->restart();
      pass_sinks_.push_back(std::make_unique<PassSink>(*pass, builder_->program()));
      tees_.push_back(std::make_unique<canon::TeeSink>(*sink_, *pass_sinks_.back()));
      sink_ = tees_.back().get();
    }
    // Before the builder, the features' passes over the calls, in their order; the pieces of a
    // move they split keep its segment id, which the builder notes as a split.
    builder_->note_repeated_ids_as_splits(!call_passes_.empty());
    for (auto it = call_passes_.rbegin(); it != call_passes_.rend(); ++it) {
      (*it)->set_next(*sink_);
      sink_ = it->get();
    }
  }

  gcode::Interpreter* interp_;
  double tolerance_mm_;
  ToolTableWriter writer_;
  std::vector<std::unique_ptr<MovePass>> passes_;
  std::vector<std::unique_ptr<CallPass>> call_passes_;
  std::unique_ptr<canon::ProgramBuilder> builder_, previous_;
  std::unique_ptr<DefaultTolerance> tolerance_;
  std::unique_ptr<canon::TeeSink> inner_, outer_;
  std::vector<std::unique_ptr<PassSink>> pass_sinks_;
  std::vector<std::unique_ptr<canon::TeeSink>> tees_;
  canon::Sink* sink_ = nullptr;
};

/// Where the interpreter is placed for a program: the start-up calls, the profile's default
/// tolerance while none is programmed, then the machine position. False (with diagnostics in the
/// interpreter) when the file cannot be read or its head is wrong.
bool begin_program(gcode::Interpreter& interp, Pipeline& p, const std::string& path, const Pose& start,
                   double tolerance_mm) {
  if (!interp.open(path)) return false;
  // The file first (file 0 of the source map, the main program of every move), then the
  // start-up calls, then the position.
  p.builder().set_motion_control_mode(canon::MotionControl::Continuous, tolerance_mm);  // in mm yet
  if (interp.start(p.sink()) == gcode::RunStatus::Error) return false;
  interp.set_machine_position(start);
  return true;
}

// --- execution ---------------------------------------------------------------------------------

/// A file or an MDI line executed as a stream (gcode::Mode::Execute).
class GcodeStream final : public ProgramStream {
 public:
  /// A file: owns its interpreter.
  GcodeStream(const gcode::Options& o, const std::string& path, const Pose& start, double tolerance_mm,
              std::shared_ptr<tools::ToolTableService> tools, const SourceParts& parts)
      : owned_(std::make_unique<gcode::Interpreter>(o)),
        interp_(owned_.get()),
        tools_(std::move(tools)),
        pipe_(*interp_, start, tolerance_mm, tools_.get(), parts) {
    tools_version_ = tools_ ? tools_->version() : 0;
    if (!begin_program(*interp_, pipe_, path, start, tolerance_mm)) fail();
  }
  /// A file resumed at segment `first`: the interpreter runs it from the start, placed at
  /// `program_start` (where the program first started), and everything before the segment is
  /// replayed quietly (canon::ReplayFilter); the moves begin at `start` with the rest of it.
  GcodeStream(const gcode::Options& o, const std::string& path, const Pose& program_start, const Pose& start,
              canon::SegmentId first, double tolerance_mm, std::shared_ptr<tools::ToolTableService> tools,
              const SourceParts& parts)
      : owned_(std::make_unique<gcode::Interpreter>(o)),
        interp_(owned_.get()),
        tools_(std::move(tools)),
        pipe_(*interp_, start, tolerance_mm, tools_.get(), parts) {
    tools_version_ = tools_ ? tools_->version() : 0;
    replay_ = std::make_unique<canon::ReplayFilter>(pipe_.sink(), first);
    first_segment_ = first;
    if (!begin_program(*interp_, pipe_, path, program_start, tolerance_mm)) fail();
  }
  /// An MDI line on the session's interpreter (already placed and up to date).
  GcodeStream(gcode::Interpreter& session, std::string line, const Pose& start, double tolerance_mm,
              std::shared_ptr<tools::ToolTableService> tools, const SourceParts& parts)
      : interp_(&session),
        tools_(std::move(tools)),
        pipe_(session, start, tolerance_mm, tools_.get(), parts),
        mdi_line_(std::move(line)),
        mdi_(true) {
    tools_version_ = tools_ ? tools_->version() : 0;
    first_diagnostic_ = interp_->diagnostics().items().size();
    replay_state();
  }

  const canon::Program& program() const override { return pipe_.program(); }
  StreamState state() const override { return state_; }
  const SyncRequest& sync_request() const override { return sync_; }
  const Diagnostics& diagnostics() const override { return diags_; }

  StreamState read(std::size_t more_moves) override {
    if (state_ != StreamState::Reading) return state_;
    if (mdi_) return read_mdi();
    const std::size_t target = program().size() + more_moves;
    std::uint64_t blocks = 0;
    while (state_ == StreamState::Reading && program().size() < target && blocks < kReadBlockBudget) {
      blocks += kBlocksPerCall;
      on_status(interp_->run(sink(), kBlocksPerCall));
    }
    return state_;
  }

  void answer(const SyncAnswer& a) override {
    if (state_ != StreamState::Sync) return;
    gcode::SyncValues v;
    v.kind = interp_->pending_sync();
    v.probe_tripped = a.probe_tripped;
    v.probe_position = interp_->program_position(a.probe_position);
    v.position = interp_->program_position(a.position);
    v.input_value = a.input_value;
    // What the operator changed in the tool table while the program waited counts from here on.
    if (tools_ && tools_->version() != tools_version_) {
      interp_->set_tool_table(tools_->snapshot());
      tools_version_ = tools_->version();
    }
    interp_->sync(v);
    sync_ = SyncRequest{};
    state_ = StreamState::Reading;
    if (interp_->pending_sync() != gcode::SyncKind::None) enter_sync();  // a stop after the feedback
  }

  void restart_at(const Pose& start, std::size_t /*from_move*/) override { pipe_.restart(start); }

  void release(std::size_t move, std::size_t action) override {
    pipe_.builder().program().release_before(move, action);
  }

  SourceLocation location() const override {
    const canon::BlockOrigin& o = pipe_.builder().origin();
    return locate(program().sources(), o.context, o.line);
  }
  SourceLocation location_of(std::size_t move) const override {
    const canon::Move& m = program().move(move);
    return locate(program().sources(), m.context, m.line);
  }

 private:
  StreamState read_mdi() {
    const gcode::RunStatus s =
        mdi_started_ ? interp_->continue_mdi(pipe_.sink()) : interp_->execute_mdi(mdi_line_, pipe_.sink());
    mdi_started_ = true;
    // The line is done once it ran through (an MDI error leaves the session usable).
    on_status(s == gcode::RunStatus::Ok ? gcode::RunStatus::Finished : s);
    return state_;
  }

  void on_status(gcode::RunStatus s) {
    if (s != gcode::RunStatus::Ok) pipe_.flush();
    if (!pipe_.writer().failures().items().empty() || pipe_.passes_failed()) {
      append(diags_, pipe_.writer().failures());
      pipe_.append_pass_failures(diags_);
      state_ = StreamState::Error;
      return;
    }
    switch (s) {
      case gcode::RunStatus::Ok:
        return;
      case gcode::RunStatus::Finished:
        if (replay_ && !replay_->live()) {
          diags_.error("", 0, 0, fmt::format("cannot resume at segment {}: the program ends after {} segments",
                                             first_segment_, interp_->segments()),
                       "control.resume-past-end");
          state_ = StreamState::Error;
          return;
        }
        state_ = StreamState::Finished;
        collect_diagnostics();
        return;
      case gcode::RunStatus::NeedSync:
        enter_sync();
        return;
      case gcode::RunStatus::Error:
        fail();
        return;
    }
  }

  /// Where the interpreter writes: the pipeline, through the replay filter while resuming.
  canon::Sink& sink() {
    if (!replay_) return pipe_.sink();
    replay_->set_next(pipe_.sink());
    return *replay_;
  }

  /// A sync point before the segment a resumed program starts at: a stop or a tool change goes
  /// on (the program went on from it when it ran); a probe result or an input value is not
  /// known again, so the program cannot be resumed past it.
  bool replay_sync() {
    const gcode::SyncKind k = interp_->pending_sync();
    if (k == gcode::SyncKind::Probe || k == gcode::SyncKind::Input) {
      const SourceLocation where = location();
      diags_.error(where.file, where.line, 0,
                   fmt::format("cannot resume at segment {}: the program reads the machine's {} at {} before it, "
                               "which a replay does not know",
                               first_segment_, k == gcode::SyncKind::Probe ? "probe result" : "input",
                               to_string(where)),
                   "control.resume-past-sync");
      state_ = StreamState::Error;
      return true;
    }
    gcode::SyncValues v;
    v.kind = k;
    v.position = interp_->state().position.current;
    interp_->sync(v);
    return true;
  }

  void enter_sync() {
    if (replay_ && !replay_->live() && replay_sync()) return;
    state_ = StreamState::Sync;
    sync_.kind = from_gcode(interp_->pending_sync());
    sync_.where = location();
    sync_.contact_required = interp_->sync_request().contact_required;
  }

  void fail() {
    state_ = StreamState::Error;
    collect_diagnostics();
    if (!diags_.has_errors()) diags_.error("", 0, 0, "the program cannot be read", "control.program");
  }

  void collect_diagnostics() {
    append(diags_, interp_->diagnostics(), first_diagnostic_);
    first_diagnostic_ = interp_->diagnostics().items().size();
  }

  // The builder of an MDI line starts from the state the session's earlier lines left: units,
  // offsets, rotation, plane, feed, path control (the interpreter repeats a setting only when it
  // changes, and every line gets a fresh program).
  void replay_state() {
    const gcode::InterpState s = interp_->state();
    const gcode::ModalState& m = s.modal;
    canon::ProgramBuilder& b = pipe_.builder();
    b.use_length_units(m.units);
    b.set_g5x_offset(m.coord_system, s.position.origin_offset);
    b.set_g92_offset(s.position.axis_offset);
    b.set_xy_rotation(s.position.rotation_xy_deg);
    b.use_tool_length_offset(s.position.tool_offset);
    b.select_plane(m.plane);
    b.set_feed_mode(0, m.feed_mode);
    b.set_feed_rate(m.feed_rate);
    pipe_.sink().set_motion_control_mode(m.control, m.path_tolerance);  // the default tolerance, if it applies
    b.set_naivecam_tolerance(m.naivecam_tolerance);
    if (!m.feed_override) b.disable_feed_override();
    if (!m.feed_hold) b.disable_feed_hold();
  }

  std::unique_ptr<gcode::Interpreter> owned_;
  gcode::Interpreter* interp_;
  std::shared_ptr<tools::ToolTableService> tools_;
  std::uint64_t tools_version_ = 0;
  Pipeline pipe_;
  StreamState state_ = StreamState::Reading;
  SyncRequest sync_;
  Diagnostics diags_;
  std::size_t first_diagnostic_ = 0;
  std::string mdi_line_;
  bool mdi_ = false, mdi_started_ = false;
  std::unique_ptr<canon::ReplayFilter> replay_;  ///< resuming: what comes before the first segment
  canon::SegmentId first_segment_ = 0;
};

// --- the preflight scan --------------------------------------------------------------------------

/// One scan of a file (gcode::Mode::Scan) into a window of moves.
class Scan {
 public:
  Scan(const gcode::Options& o, const std::string& path, const Pose& start, double tolerance_mm,
       const SourceParts& parts, ScanCancel cancel = {})
      : interp_(o), pipe_(interp_, start, tolerance_mm, nullptr, parts), cancel_(cancel) {
    ok_ = begin_program(interp_, pipe_, path, start, tolerance_mm);
    done_ = !ok_;
  }
  /// Reads until `moves` moves exist or the scan ends (or is cancelled).
  void read_to(std::size_t moves) {
    while (!done_ && program().size() < moves) {
      if (cancel_.requested()) {
        cancelled_ = true;
        done_ = true;
        ok_ = false;
        return;
      }
      const gcode::RunStatus s = interp_.run(pipe_.sink(), kBlocksPerCall);
      if (s != gcode::RunStatus::Ok) pipe_.flush();
      if (s == gcode::RunStatus::Error) ok_ = false;
      if (s == gcode::RunStatus::Error || s == gcode::RunStatus::Finished) done_ = true;
    }
  }
  const canon::Program& program() const noexcept { return pipe_.program(); }
  bool done() const noexcept { return done_; }
  bool ok() const noexcept { return ok_; }
  bool cancelled() const noexcept { return cancelled_; }
  const Diagnostics& diagnostics() const noexcept { return interp_.diagnostics(); }
  void append_pass_failures(Diagnostics& to) const { pipe_.append_pass_failures(to); }
  void release(std::size_t move, std::size_t action) { pipe_.builder().program().release_before(move, action); }

 private:
  gcode::Interpreter interp_;
  Pipeline pipe_;
  ScanCancel cancel_;
  bool ok_ = true, done_ = false, cancelled_ = false;
};

/// Whether move k is the same in two scans: kind, line, end points, feed and (arcs) geometry.
bool same_move(const canon::Program& a, const canon::Program& b, canon::SegmentId k) {
  const canon::Move& ma = a.move(k);
  const canon::Move& mb = b.move(k);
  if (ma.kind != mb.kind || ma.line != mb.line || ma.context != mb.context || ma.flags != mb.flags) return false;
  // The start too: a move from an assumed point to a certain one still crosses what lies between.
  if (a.start_of(k) != b.start_of(k) || a.end(k) != b.end(k) || a.feed(k) != b.feed(k)) return false;
  if (ma.kind != canon::MoveKind::Arc) return true;
  const canon::ArcGeometry& ga = a.arc(k);
  const canon::ArcGeometry& gb = b.arc(k);
  return ga.turns == gb.turns && ga.plane == gb.plane && ga.center == gb.center && ga.normal == gb.normal;
}

/// The sync point an action or a move stands for (None if it is none).
SyncKind sync_of(canon::ActionKind k) {
  switch (k) {
    case canon::ActionKind::WaitInput:
      return SyncKind::Input;
    case canon::ActionKind::ChangeTool:
      return SyncKind::ToolChange;
    case canon::ActionKind::ProgramStop:
    case canon::ActionKind::OptionalStop:
      return SyncKind::ProgramStop;
    default:
      return SyncKind::None;
  }
}

/// Checks the moves of a scan as they come, adds them up, notes the sync points; with a second
/// scan that assumes other answers, tells the moves that rest on an assumed answer.
class PreflightRun {
 public:
  PreflightRun(MoveCheck& check, Preflight& out) : check_(check), out_(out) {}

  /// Handles moves [checked, scan.size()) and the actions before them; `other` (may be null)
  /// is the scan with other answers, read at least as far where it can.
  void take(Scan& scan, Scan* other) {
    const canon::Program& p = scan.program();
    for (; checked_ < p.size(); ++checked_) {
      note_actions(p, checked_);
      if (p.move(checked_).kind == canon::MoveKind::Probe) note_sync(p, SyncKind::Probe, p.move(checked_).context,
                                                                   p.move(checked_).line);
      bool assumed = false;
      if (other != nullptr) {
        assumed = diverged_ || checked_ >= other->program().size() || !same_move(p, other->program(), checked_);
        if (assumed && checked_ >= other->program().size()) diverged_ = true;
      }
      check_move(p, checked_, assumed);
      add_to_summary(p, checked_);
    }
    note_actions(p, p.size());
  }

  std::size_t checked() const noexcept { return checked_; }
  std::size_t actions_seen() const noexcept { return next_action_; }

 private:
  void note_sync(const canon::Program& p, SyncKind k, std::uint32_t context, std::uint32_t line) {
    PreflightSummary& s = out_.summary;
    ++s.sync_points;
    last_sync_ = locate(p.sources(), context, line);
    last_sync_kind_ = k;
    if (s.sync_list.size() < PreflightSummary::kMaxListed) s.sync_list.emplace_back(k, last_sync_);
  }

  void note_actions(const canon::Program& p, std::size_t before_move) {
    while (next_action_ < p.action_count() && p.action(next_action_).before_move <= before_move) {
      const canon::Action& a = p.action(next_action_++);
      if (const SyncKind k = sync_of(a.kind); k != SyncKind::None) note_sync(p, k, a.context, a.line);
    }
  }

  void check_move(const canon::Program& p, canon::SegmentId k, bool assumed) {
    if (!assumed) {
      check_.check(p, k, out_.diagnostics);
      return;
    }
    ++out_.summary.assumed_moves;
    const canon::Move& m = p.move(k);
    const SourceLocation where = locate(p.sources(), m.context, m.line);
    if (where.line != last_assumed_line_ || where.file != last_assumed_file_) {
      last_assumed_line_ = where.line;
      last_assumed_file_ = where.file;
      if (out_.summary.assumed_lines.size() < PreflightSummary::kMaxListed) out_.summary.assumed_lines.push_back(where);
    }
    // What fails under the assumed answer may pass with the real one: a warning now, the check
    // again (an error then) before the move runs.
    Diagnostics d;
    check_.check(p, k, d);
    for (Diagnostic x : d.items()) {
      if (x.severity == Severity::Error) {
        x.severity = Severity::Warning;
        x.message += fmt::format(" — with the {} assumed at {}; checked again with the machine's answer before the "
                                 "move runs",
                                 to_string(last_sync_kind_), to_string(last_sync_));
      }
      out_.diagnostics.add(std::move(x));
    }
  }

  void add_to_summary(const canon::Program& p, canon::SegmentId k) {
    PreflightSummary& s = out_.summary;
    ++s.moves;
    s.path_length_mm += move_length(p, k);
    const Extent e = move_extent(p, k);
    for (int i = 0; i < kAxisCount; ++i) {
      s.min[i] = s.has_moves ? std::min(s.min[i], e.min[i]) : e.min[i];
      s.max[i] = s.has_moves ? std::max(s.max[i], e.max[i]) : e.max[i];
    }
    s.has_moves = true;
  }

  MoveCheck& check_;
  Preflight& out_;
  std::size_t checked_ = 0, next_action_ = 0;
  bool diverged_ = false;
  SourceLocation last_sync_;
  SyncKind last_sync_kind_ = SyncKind::None;
  std::uint32_t last_assumed_line_ = 0;
  std::string last_assumed_file_;
};

/// One preflight pass; with `classify`, a second scan with other answers runs in step with it.
Preflight preflight_pass(const gcode::Options& o, const std::string& path, const Pose& start,
                         double tolerance_mm, const SourceParts& parts, MoveCheck& check, bool classify,
                         ScanCancel cancel) {
  Preflight out;
  gcode::Options main = o;
  main.mode = gcode::Mode::Scan;
  main.scan_assumption = gcode::ScanAssumption::Rs274;
  Scan scan(main, path, start, tolerance_mm, parts, cancel);
  std::unique_ptr<Scan> other;
  if (classify) {
    gcode::Options alt = main;
    alt.scan_assumption = gcode::ScanAssumption::Other;
    other = std::make_unique<Scan>(alt, path, start, tolerance_mm, parts);
  }
  PreflightRun run(check, out);
  while (!scan.done() || run.checked() < scan.program().size()) {
    scan.read_to(scan.program().size() + kScanBatch);
    if (other) other->read_to(scan.program().size());
    run.take(scan, other.get());
    // Everything checked is summed up: keep one move for the next one's start.
    scan.release(run.checked(), run.actions_seen());
    if (other) other->release(std::min(run.checked(), other->program().size()), other->program().action_count());
    if (scan.done() && run.checked() >= scan.program().size()) break;
  }
  append(out.diagnostics, scan.diagnostics());
  scan.append_pass_failures(out.diagnostics);
  if (scan.cancelled())
    out.diagnostics.error(path, 0, 0, "the check was cancelled: an e-stop, machine off or abort was sent",
                          "control.cancelled");
  if (!scan.ok() && !out.diagnostics.has_errors())
    out.diagnostics.error(path, 0, 0, "the program cannot be read", "control.program");
  check.finish(out.diagnostics);
  return out;
}

}  // namespace

// --- the source ------------------------------------------------------------------------------

std::shared_ptr<GcodeProgramSource> GcodeProgramSource::create(const config::MachineProfile& profile,
                                                               Diagnostics& diags) {
  std::optional<GcodeSourceConfig> c = config_for(profile, diags);
  return c ? std::make_shared<GcodeProgramSource>(std::move(*c)) : nullptr;
}

std::optional<GcodeSourceConfig> GcodeProgramSource::config_for(const config::MachineProfile& profile,
                                                                Diagnostics& diags) {
  GcodeSourceConfig c;
  gcode::Options& o = c.options;
  o.dialect = profile.interpreter.dialect == config::Dialect::Fanuc ? gcode::Dialect::Fanuc
                                                                    : gcode::Dialect::LinuxCnc;
  o.machine = profile.interpreter.machine == config::MachineKind::Lathe ? gcode::MachineKind::Lathe
                                                                        : gcode::MachineKind::Mill;
  o.axes = profile.axis_mask();
  o.axis_map = profile.interpreter.axis_map;
  o.subroutine_path = profile.interpreter.subroutine_path;
  o.user_units = canon::Units::Mm;
  o.initial_units = canon::Units::Mm;
  o.optional_stop = true;  // M1 always reaches the servo, which decides with the live switch
  o.spindle = profile.spindle.present;
  o.tool_change.axes = profile.tool_change.axes;
  o.tool_change.machine = profile.tool_change.position;
  o.tool_change.z_first = profile.tool_change.z_first;
  o.limits.max_seconds = profile.interpreter.max_scan_s;  // scans only: a run goes on for hours
  if (!profile.interpreter.tool_table.empty()) {
    c.tools = tools::FileToolTable::open(profile.interpreter.tool_table, diags);
    if (!c.tools) return std::nullopt;
  }
  c.default_tolerance_mm = profile.planner.default_tolerance;
  return c;
}

GcodeProgramSource::GcodeProgramSource(GcodeSourceConfig config) : config_(std::move(config)) {}

GcodeProgramSource::~GcodeProgramSource() = default;

// A program opened after this reads with the parts for the new profile; the MDI session starts
// afresh at its next line when a part changed (its interpreter holds the modules it was made with).
void GcodeProgramSource::profile_changed(const config::MachineProfile& profile) {
  bool changed = false;
  std::lock_guard lock(parts_mutex_);
  for (std::shared_ptr<const SourcePart>& part : config_.parts) {
    if (std::shared_ptr<const SourcePart> next = part->for_profile(profile)) {
      part = std::move(next);
      changed = true;
    }
  }
  if (changed) ++parts_changed_;
}

gcode::Options GcodeProgramSource::options_for(const std::string& path, const LoadOptions& options) const {
  gcode::Options o = config_.options;
  if (!path.empty()) o.dialect = gcode::dialect_marker(path).value_or(o.dialect);
  o.extensions = gcode::standard_extensions(o.dialect);
  for (const auto& part : parts()) o.extensions = part->modules(o.dialect, o.extensions);
  o.block_delete = options.block_delete;
  if (config_.tools) o.tool_table = config_.tools->snapshot();
  return o;
}

Preflight GcodeProgramSource::preflight(const std::string& path, const Pose& start, const LoadOptions& options,
                                        MoveCheck& check) {
  const gcode::Options o = options_for(path, options);
  Preflight first =
      preflight_pass(o, path, start, config_.default_tolerance_mm, parts(), check, false, options.cancel);
  if (first.summary.sync_points == 0 || options.cancel.requested()) return first;
  // Sync points: the checks of the moves after them rest on assumed answers. A second pass, beside
  // a scan with other answers, tells which moves those are.
  Preflight second =
      preflight_pass(o, path, start, config_.default_tolerance_mm, parts(), check, true, options.cancel);
  return second;
}

std::unique_ptr<ProgramStream> GcodeProgramSource::execute(const std::string& path, const Pose& start,
                                                           const LoadOptions& options) {
  gcode::Options o = options_for(path, options);
  o.mode = gcode::Mode::Execute;
  // As LinuxCNC's task runs it, M99 in the main program starts it again until the operator
  // stops the run (the preflight scans it once, as rs274 reads it).
  o.main_m99 = gcode::MainM99::Repeat;
  return std::make_unique<GcodeStream>(o, path, start, config_.default_tolerance_mm, config_.tools, parts());
}

std::unique_ptr<ProgramStream> GcodeProgramSource::resume(const std::string& path, const Pose& program_start,
                                                          const Pose& start, canon::SegmentId segment,
                                                          const LoadOptions& options) {
  gcode::Options o = options_for(path, options);
  o.mode = gcode::Mode::Execute;
  return std::make_unique<GcodeStream>(o, path, program_start, start, segment, config_.default_tolerance_mm,
                                       config_.tools, parts());
}

std::unique_ptr<ProgramStream> GcodeProgramSource::mdi(std::string_view line, const Pose& start) {
  if (mdi_ && mdi_parts_ != parts_changed_) mdi_.reset();
  if (!mdi_) {
    mdi_parts_ = parts_changed_;
    gcode::Options o = options_for("", {});
    o.mode = gcode::Mode::Execute;
    mdi_ = std::make_unique<gcode::Interpreter>(o);
    canon::Sink quiet;
    mdi_->start(quiet);
    mdi_tools_version_ = config_.tools ? config_.tools->version() : 0;
  }
  if (config_.tools && config_.tools->version() != mdi_tools_version_) {
    mdi_->set_tool_table(config_.tools->snapshot());
    mdi_tools_version_ = config_.tools->version();
  }
  mdi_->set_machine_position(start);
  auto stream = std::make_unique<GcodeStream>(*mdi_, std::string(line), start, config_.default_tolerance_mm,
                                              config_.tools, parts());
  return stream;
}

std::vector<std::shared_ptr<const SourcePart>> GcodeProgramSource::parts() const {
  std::lock_guard lock(parts_mutex_);
  return config_.parts;
}

Diagnostics GcodeProgramSource::scan(const std::string& path, const Pose& start, const LoadOptions& options,
                                     ScanReader& reader) const {
  gcode::Options o = options_for(path, options);
  o.mode = gcode::Mode::Scan;
  o.scan_assumption = gcode::ScanAssumption::Rs274;
  Scan scan(o, path, start, config_.default_tolerance_mm, parts(), options.cancel);
  std::size_t next_move = 0, next_action = 0;
  bool more = true;
  while (more) {
    scan.read_to(scan.program().size() + kScanBatch);
    const canon::Program& p = scan.program();
    for (; more && next_move < p.size(); ++next_move) {
      for (; more && next_action < p.action_count() && p.action(next_action).before_move <= next_move;
           ++next_action)
        more = reader.action(p, next_action);
      if (more) more = reader.move(p, next_move);
    }
    if (scan.done()) {
      for (; more && next_action < p.action_count(); ++next_action) more = reader.action(p, next_action);
      break;
    }
    scan.release(next_move, next_action);  // the last move seen is kept: the next one starts there
  }
  Diagnostics out;
  append(out, scan.diagnostics());
  scan.append_pass_failures(out);
  return out;
}

// --- locations -------------------------------------------------------------------------------

SourceLocation locate(const canon::SourceMap& map, std::uint32_t context, std::uint32_t line) {
  SourceLocation l;
  l.line = line;
  const std::uint32_t file = context == 0 ? 0 : map.context_info(context).body_file;
  if (file < map.file_count()) l.file = map.file(file);
  for (std::uint32_t c : map.stack(context)) {
    const canon::SourceMap::Context& info = map.context_info(c);
    const std::string site = info.call_site.file < map.file_count() ? map.file(info.call_site.file) : "?";
    l.calls.push_back(fmt::format("{} called at {}:{}", info.name, site, info.call_site.line));
  }
  return l;
}

std::string to_string(const SourceLocation& l) {
  std::string out = fmt::format("{}:{}", l.file, l.line);
  for (auto it = l.calls.rbegin(); it != l.calls.rend(); ++it) out += fmt::format(" (in {})", *it);
  return out;
}

const char* to_string(SyncKind k) noexcept {
  switch (k) {
    case SyncKind::None:
      return "";
    case SyncKind::Probe:
      return "probe result";
    case SyncKind::Input:
      return "input value";
    case SyncKind::ToolChange:
      return "tool change";
    case SyncKind::ProgramStop:
      return "program stop";
  }
  return "";
}

}  // namespace opencnc::controller
