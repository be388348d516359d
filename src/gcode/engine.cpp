// SPDX-License-Identifier: GPL-3.0-or-later
// The interpreter's main loop: start-up, reading lines, dispatching blocks, errors, sync.
#include "engine.hpp"

#include <cstring>

#include "lexer.hpp"

namespace opencnc::gcode {

Engine::Engine(Options options) : opt_(std::move(options)), sources_(std::make_shared<canon::SourceMap>()) {
  ext_ = opt_.extensions.get();
  out_.configure(opt_);
  out_.track(&st_.position);
  norm_.resize(1 << 12);
  raw_.reserve(512);
  st_.modal.units = opt_.initial_units;
  update_unit_factor();
  st_.parameters[5220] = 1.0;   // G54
  st_.parameters[5599] = 1.0;   // (DEBUG,...) messages on
  st_.frames.emplace_back();
  // Tool table copy: entry 0 is the spindle (empty), entries 1..n the table in load order.
  st_.tool.table.emplace_back();
  if (opt_.tool_table) {
    for (const auto& e : opt_.tool_table->entries()) st_.tool.table.push_back(e);
  }
  set_tool_parameters();
  letters_ = 0;
  for (char c : std::string_view("defghijklmpqrst")) letters_ |= 1u << (c - 'a');
  for (int i = 0; i < kAxisCount; ++i) {
    if (opt_.axes.has(static_cast<Axis>(i))) letters_ |= 1u << (kAxisWordLetters[i] - 'a');
  }
}

Engine::~Engine() = default;

// --- program sources --------------------------------------------------------------------

bool Engine::open_file(const std::string& path) {
  auto file = SourceFile::open(path);
  if (!file) {
    diags_.error(path, 0, 0, "cannot open the program file", std::string(error_id(ErrorCode::CannotOpenFile)));
    failed_ = true;
    return false;
  }
  const std::uint32_t index = sources_->add_file(path);
  if (files_.size() <= index) files_.resize(index + 1);
  files_[index] = std::move(file);
  st_.next = {index, 0, 1};
  need_seek_ = true;
  has_program_ = true;
  return true;
}

void Engine::open_text(std::string name, std::string text) {
  const std::uint32_t index = sources_->add_file(name);
  if (files_.size() <= index) files_.resize(index + 1);
  files_[index] = SourceFile::from_text(std::move(text));
  st_.next = {index, 0, 1};
  need_seek_ = true;
  has_program_ = true;
}

SourceFile& Engine::current_file() {
  auto& f = files_.at(st_.next.file);
  if (!f) {
    // A file left earlier (a subprogram's caller): open it again.
    f = SourceFile::open(sources_->file(st_.next.file));
    if (!f) fail(ErrorCode::CannotOpenFile, "cannot reopen {}", sources_->file(st_.next.file));
    need_seek_ = true;
  }
  return *f;
}

void Engine::jump_to(const SourcePosition& pos) {
  st_.next = pos;
  need_seek_ = true;
}

// --- start-up ---------------------------------------------------------------------------

void Engine::start() {
  started_ = true;
  if (opt_.dialect != Dialect::LinuxCnc) fail(ErrorCode::Unsupported, "the Fanuc dialect is not supported yet");
  out_.set_origin(canon::BlockOrigin{});
  // The canonical setup LinuxCNC's interpreter makes when it initialises.
  const int system = st_.modal.coord_system;
  const int base = 5200 + 20 * system;
  for (int i = 0; i < kAxisCount; ++i) {
    const bool linear = !is_rotary(static_cast<Axis>(i));
    const double o = st_.parameters[static_cast<std::size_t>(base + 1 + i)];
    const double g = st_.parameters[static_cast<std::size_t>(5211 + i)];
    st_.position.origin_offset[i] = linear ? user_to_program(o) : o;
    st_.position.axis_offset[i] = linear ? user_to_program(g) : g;
  }
  st_.position.rotation_xy_deg = st_.parameters[static_cast<std::size_t>(base + 10)];
  out_.use_length_units(st_.modal.units);
  out_.set_g5x_offset(system, st_.position.origin_offset);
  out_.set_g92_offset(st_.position.axis_offset);
  out_.set_xy_rotation(st_.position.rotation_xy_deg);
  out_.set_feed_reference(canon::FeedReference::Xyz);
  if (!has_program_) return;
  // A program whose first non-blank line is a lone '%' must end with another '%'.
  SourceFile& f = current_file();
  f.seek(0);
  RawLine line;
  std::uint32_t n = 0;
  for (;;) {
    if (!f.next(line)) {
      line_ = n;
      fail(ErrorCode::FileEndedNoPercent, "the program file is empty");
    }
    ++n;
    if (line.text.size() + (line.newline ? 1 : 0) > kMaxLineLength) {
      line_ = n;
      fail(ErrorCode::LineTooLong, "line longer than {} characters", kMaxLineLength - 1);
    }
    if (!trim_raw_line(line.text).empty()) break;
  }
  std::string_view first = trim_raw_line(line.text);
  while (!first.empty() && (first.front() == ' ' || first.front() == '\t')) first.remove_prefix(1);
  if (first == "%") {
    st_.percent_delimited = true;
    st_.next = {st_.next.file, f.tell(), 2};   // LinuxCNC counts the '%' line as line 1
  } else {
    st_.next = {st_.next.file, 0, 1};
  }
  need_seek_ = true;
}

// --- driving ----------------------------------------------------------------------------

RunStatus Engine::guarded(canon::Sink& sink, bool (Engine::*body)()) {
  out_.attach(&sink);
  if (failed_) return RunStatus::Error;
  if (pending_sync_ != SyncKind::None) return RunStatus::NeedSync;
  if (st_.ended && started_) return RunStatus::Finished;
  try {
    if (!started_) start();
    const bool more = (this->*body)();
    if (pending_sync_ != SyncKind::None) return RunStatus::NeedSync;
    return more ? RunStatus::Ok : RunStatus::Finished;
  } catch (const GcodeError& e) {
    report(e);
    failed_ = true;
    return RunStatus::Error;
  }
}

RunStatus Engine::step(canon::Sink& sink) {
  if (!has_program_ && !failed_) {
    diags_.error("", 0, 0, "no program is open", std::string(error_id(ErrorCode::NoProgram)));
    failed_ = true;
  }
  return guarded(sink, &Engine::step_block);
}

RunStatus Engine::begin(canon::Sink& sink) { return guarded(sink, &Engine::nothing); }

RunStatus Engine::run(canon::Sink& sink) {
  for (;;) {
    const RunStatus s = step(sink);
    if (s != RunStatus::Ok) return s;
  }
}

bool Engine::step_block() {
  if (st_.ended) return false;
  process_line();
  return !st_.ended;
}

RunStatus Engine::mdi(std::string_view line, canon::Sink& sink) {
  if (!in_mdi_file_) {
    mdi_file_ = sources_->add_file("<mdi>");
    in_mdi_file_ = true;
  }
  mdi_line_.assign(line);
  in_mdi_ = true;
  st_.ended = false;   // MDI also works after a program end
  const RunStatus s = guarded(sink, &Engine::process_line);
  in_mdi_ = false;
  if (s == RunStatus::Error) failed_ = false;   // an MDI error does not end the session
  return s == RunStatus::Finished ? RunStatus::Ok : s;
}

ParseEnv Engine::parse_env() const noexcept {
  ParseEnv env;
  env.parameters = st_.parameters.data();
  env.host = const_cast<Engine*>(this);
  env.letters = letters_;
  env.lathe_diameter = st_.modal.lathe_diameter;
  env.comp_on = st_.modal.cutter_comp != CutterComp::Off;
  env.call_level = static_cast<int>(st_.frames.size()) - 1;
  env.call_sub = st_.frames.back().sub;
  env.defining_sub = st_.control.defining_sub;
  env.defining_name = st_.control.defining_name;
  env.skipping_to = st_.control.skipping_to;
  return env;
}

// Reads the next line into raw_/norm_; false at the end of the file.
bool Engine::read_line() {
  update_position_parameters();
  if (in_mdi_) {
    line_file_ = mdi_file_;
    line_ = 1;
    line_offset_ = 0;
    raw_.assign(trim_raw_line(mdi_line_));
    if (mdi_line_.size() > kMaxLineLength) fail(ErrorCode::LineTooLong, "line longer than {} characters", kMaxLineLength - 1);
    return true;
  }
  SourceFile& f = current_file();
  if (need_seek_) {
    f.seek(st_.next.offset);
    need_seek_ = false;
  }
  RawLine line;
  if (!f.next(line)) return false;
  line_file_ = st_.next.file;
  line_ = st_.next.line;
  line_offset_ = line.offset;
  st_.next.offset = f.tell();
  ++st_.next.line;
  raw_.assign(trim_raw_line(line.text));
  if (line.text.size() + (line.newline ? 1 : 0) > kMaxLineLength)
    fail(ErrorCode::LineTooLong, "line longer than {} characters", kMaxLineLength - 1);
  return true;
}

void Engine::set_origin_from_line() {
  canon::BlockOrigin o;
  o.file = line_file_;
  o.line = line_;
  o.context = st_.frames.back().context;
  std::string_view digits;
  if (leading_n_digits(raw_, digits)) {
    o.n_present = true;
    const std::size_t n = std::min(digits.size(), sizeof(o.n_digits));
    std::memcpy(o.n_digits, digits.data(), n);
    o.n_length = static_cast<std::uint8_t>(n);
  }
  out_.set_origin(o);
}

// Reads and executes one line. Returns when the line is done (or the program ended).
bool Engine::process_line() {
  if (!read_line()) {
    line_ = st_.next.line;
    if (!st_.control.seeking_sub.empty())
      fail(ErrorCode::SubNotFound, "end of {} while looking for o<{}> (called on line {})",
           sources_->file(st_.next.file), st_.control.seeking_sub, st_.control.skip_start_line);
    if (st_.percent_delimited) fail(ErrorCode::FileEndedNoPercent, "the file ends without the closing '%'");
    fail(ErrorCode::FileEndedNoEnd, "the file ends without M2, M30 or a closing '%'");
  }
  if (norm_.size() < raw_.size() + 1) norm_.resize(raw_.size() + 1);
  set_origin_from_line();
  norm_len_ = normalize_line(raw_, norm_.data());
  const std::string_view text(norm_.data(), norm_len_);
  if (text == "%" && st_.percent_delimited && !in_mdi_) {
    out_.finish();
    st_.ended = true;
    return false;
  }
  if (text.empty() || (text.front() == '/' && opt_.block_delete)) return true;

  const bool skipping = !st_.control.skipping_to.empty();
  if (skipping) {
    if (opt_.limits.max_skipped_lines != 0 && ++skipped_lines_ > opt_.limits.max_skipped_lines)
      fail(ErrorCode::LimitSkippedLines, "more than {} lines passed over while looking for a label (limit max_skipped_lines)",
           opt_.limits.max_skipped_lines);
  } else if (opt_.limits.max_blocks != 0 && ++st_.blocks_executed > opt_.limits.max_blocks) {
    fail(ErrorCode::LimitBlocks, "more than {} blocks executed (limit max_blocks)", opt_.limits.max_blocks);
  }
  parser_.parse(text, parse_env(), block_);
  if (!skipping) {
    enhance_block();
    check_block();
  }
  if (block_.o_type != OWord::None) {
    if (in_mdi_ && block_.o_type != OWord::Call)
      fail(ErrorCode::OWordSyntax, "only 'call' O-words can be used in MDI");
    control_flow();
    if (in_mdi_) {
      // An MDI call runs its subprogram to the end here.
      while (st_.frames.size() > 1 && !failed_) {
        in_mdi_ = false;
        process_line();
        in_mdi_ = true;
      }
    }
    return true;
  }
  if (!st_.control.skipping_to.empty()) return true;
  apply_assignments();
  execute_block();
  if (block_sync_pending_) {
    block_sync_pending_ = false;
    if (block_sync_.kind == SyncKind::ToolChange) block_sync_.position = st_.position.canon_position;
    apply_sync(block_sync_);
  }
  return true;
}

// --- errors -------------------------------------------------------------------------------

void Engine::report(const GcodeError& e) {
  std::uint32_t col = 0;
  if (e.position() >= 0) {
    col = raw_column(raw_, e.position());
  } else {
    const std::size_t first = raw_.find_first_not_of(" \t");
    col = first == std::string::npos ? 1 : static_cast<std::uint32_t>(first + 1);
  }
  const std::string file = line_file_ < sources_->file_count() ? sources_->file(line_file_) : std::string();
  diags_.error(file, line_, line_ == 0 ? 0 : col, e.message(), std::string(error_id(e.code())));
}

void Engine::warn_once(bool& done, ErrorCode code, std::string_view message) {
  if (done) return;
  done = true;
  const std::size_t first = raw_.find_first_not_of(" \t");
  const auto col = first == std::string::npos ? 1u : static_cast<std::uint32_t>(first + 1);
  const std::string file = line_file_ < sources_->file_count() ? sources_->file(line_file_) : std::string();
  diags_.warning(file, line_, col, std::string(message), std::string(error_id(code)));
}

// Habits of a program that LinuxCNC accepts but a preflight should point out (once each).
void Engine::check_motion_habits(bool feed) {
  if (in_mdi_) return;
  if (!units_programmed_)
    warn_once(warned_units_, ErrorCode::UnitsNotProgrammed,
              "motion before any G20/G21: the program relies on the machine's default units");
  if (feed && st_.modal.spindle == canon::SpindleDirection::Stopped)
    warn_once(warned_spindle_, ErrorCode::FeedWithSpindleStopped, "feed move while the spindle is stopped");
}

// --- sync points --------------------------------------------------------------------------

void Engine::request_sync(const SyncValues& assumed) {
  if (opt_.mode == Mode::Execute) {
    pending_sync_ = assumed.kind;
    return;
  }
  // Scan mode: the assumed feedback arrives when the block is done (LinuxCNC reads it
  // before the next block), so later codes of the same block do not see it.
  block_sync_ = assumed;
  block_sync_pending_ = true;
}

void Engine::sync(const SyncValues& values) {
  if (pending_sync_ == SyncKind::None) return;
  apply_sync(values);
  pending_sync_ = SyncKind::None;
}

void Engine::apply_sync(const SyncValues& values) {
  auto& p = st_.parameters;
  switch (values.kind) {
    case SyncKind::Probe:
      for (int i = 0; i < kAxisCount; ++i) p[static_cast<std::size_t>(5061 + i)] = values.probe_position[i];
      p[5070] = values.probe_tripped ? 1.0 : 0.0;
      st_.position.current = values.position;
      break;
    case SyncKind::Input:
      p[5399] = values.input_value;
      break;
    case SyncKind::ToolChange:
      st_.position.current = values.position;
      break;
    case SyncKind::None:
      break;
  }
}

// --- extension facade ---------------------------------------------------------------------

void Engine::straight(bool rapid, const Pose& end) { emit_straight(rapid, end); }
void Engine::arc(const canon::ArcFeed& a) { emit_arc(a); }

InterpState Engine::snapshot() const {
  InterpState s = st_;
  s.segments = out_.segments();
  return s;
}

}  // namespace opencnc::gcode
