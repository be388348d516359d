// SPDX-License-Identifier: GPL-3.0-or-later
// The interpreter's main loop: start-up, reading lines, dispatching blocks, errors, sync.
#include "engine.hpp"

#include <algorithm>
#include <cstring>
#include <utility>

#include "lexer.hpp"

namespace opencnc::gcode {

Engine::Engine(Options options)
    : opt_(std::move(options)),
      sources_(std::make_shared<canon::SourceMap>()),
      dialect_(dialect_hooks(opt_.dialect)) {
  ext_ = opt_.extensions.get();
  // The G groups where a code with an extension handler can stand (its core group, else the
  // one its traits name): check_block looks for handlers in these only.
  for (int code = 0; ext_ != nullptr && code < static_cast<int>(ext_->g.size()); ++code) {
    const CodeHandler* h = ext_->g[static_cast<std::size_t>(code)].get();
    const int group = h == nullptr ? -1 : g_group(code) >= 0 ? g_group(code) : h->traits(code).group;
    if (group >= 0) extension_groups_ |= 1u << group;
  }
  out_.configure(opt_);
  out_.track(&st_.position);
  out_.transform_state(&st_);
  line_.norm.resize(1 << 12);
  line_.raw.reserve(512);
  st_.modal.units = opt_.initial_units;
  offsets_.update_unit_factor();
  st_.parameters[5220] = 1.0;   // G54
  st_.parameters[5599] = 1.0;   // (DEBUG,...) messages on
  st_.frames.emplace_back();
  // Tool table copy: entry 0 is the spindle (empty), entries 1..n the table in load order.
  st_.tool.table.emplace_back();
  if (opt_.tool_table) {
    for (const auto& e : opt_.tool_table->entries()) st_.tool.table.push_back(e);
  }
  mcodes_.set_tool_parameters();
  letters_ = 0;
  for (char c : std::string_view("defghijklmpqrst")) letters_ |= 1u << (c - 'a');
  // A program letter reads if the machine has the axis the axis map sends it to.
  for (int i = 0; i < kAxisCount; ++i) {
    const std::uint32_t bit = 1u << (kAxisWordLetters[i] - 'a');
    if (opt_.axes.has(opt_.axis_map[static_cast<std::size_t>(i)])) letters_ |= bit;
    else if (opt_.axes.has(static_cast<Axis>(i))) mapped_away_ |= bit;
  }
  if (dialect_.make_state) dialect_state_ = dialect_.make_state(*this);
}

Engine::~Engine() = default;

// --- program sources --------------------------------------------------------------------

bool Engine::open_file(const std::string& path) {
  std::string why;
  auto file = SourceFile::open(path, &why);
  if (!file) {
    diags_.error(path, 0, 0, "cannot open the program file: " + why,
                 std::string(error_id(ErrorCode::CannotOpenFile)));
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

SourceFile& Engine::source_at(std::uint32_t file) {
  // Lines of no open file: a jump from an MDI line (M99 P, GOTO) or a call it could not place.
  if (file >= files_.size())
    fail(ErrorCode::OwordInMdi, "this needs the lines of a program file, and an MDI line has none");
  auto& f = files_[file];
  if (!f) {
    // A file left earlier (a subprogram's caller): open it again.
    std::string why;
    f = SourceFile::open(sources_->file(file), &why);
    if (!f) fail(ErrorCode::CannotOpenFile, "cannot reopen {}: {}", sources_->file(file), why);
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
  out_.set_origin(canon::BlockOrigin{});
  // The canonical setup LinuxCNC's interpreter makes when it initialises.
  const int system = st_.modal.coord_system;
  const int base = 5200 + 20 * system;
  for (int i = 0; i < kAxisCount; ++i) {
    const bool linear = !is_rotary(static_cast<Axis>(i));
    const double o = st_.parameters[static_cast<std::size_t>(base + 1 + i)];
    const double g = st_.parameters[static_cast<std::size_t>(5211 + i)];
    st_.position.origin_offset[i] = linear ? offsets_.user_to_program(o) : o;
    st_.position.axis_offset[i] = linear ? offsets_.user_to_program(g) : g;
  }
  st_.position.rotation_xy_deg = st_.parameters[static_cast<std::size_t>(base + 10)];
  out_.use_length_units(st_.modal.units);
  out_.set_g5x_offset(system, st_.position.origin_offset);
  out_.set_g92_offset(st_.position.axis_offset);
  out_.set_xy_rotation(st_.position.rotation_xy_deg);
  out_.set_feed_reference(canon::FeedReference::Xyz);
  if (dialect_.start) dialect_.start(*this);
  if (!has_program_) return;
  // A program whose first non-blank line is a lone '%' must end with another '%'.
  SourceFile& f = current_file();
  f.seek(0);
  line_.file = st_.next.file;
  RawLine line;
  std::uint32_t n = 0;
  // The first line that is not blank, false at the end of the file.
  const auto next_text = [&]() {
    while (f.next(line)) {
      ++n;
      if (line.text.size() + (line.newline ? 1 : 0) > kMaxLineLength) {
        line_.number = n;
        line_too_long();
      }
      if (!trim_raw_line(line.text).empty()) return true;
    }
    return false;
  };
  // An empty program is reported on its first line, as every other error is placed.
  const auto empty = [&](std::string_view what) {
    line_.number = 1;
    line_.raw.clear();
    fail(ErrorCode::ProgramEmpty, "the program file {}: there is nothing to run", what);
  };
  if (!next_text()) empty(n == 0 ? "is empty" : "holds blank lines only");
  std::string_view first = trim_raw_line(line.text);
  while (!first.empty() && (first.front() == ' ' || first.front() == '\t')) first.remove_prefix(1);
  if (first == "%") {
    const std::uint64_t body = f.tell();
    if (!next_text()) empty("holds a '%' line and nothing else");
    st_.percent_delimited = true;
    st_.next = {st_.next.file, body, 2};  // LinuxCNC counts the '%' line as line 1
  } else {
    // A dialect's header: "%O1000(NAME)" opens the tape and numbers the program on one line.
    st_.percent_delimited = dialect_.program_header != nullptr && dialect_.program_header(first);
    st_.next = {st_.next.file, 0, 1};
  }
  st_.frames.front().fanuc.body = st_.next;
  st_.control.main_start = st_.next;
  need_seek_ = true;
}

// --- driving ----------------------------------------------------------------------------

RunStatus Engine::guarded(canon::Sink& sink, bool (Engine::*body)()) {
  out_.attach(&sink);
  if (failed_) return RunStatus::Error;
  if (sync_.pending() != SyncKind::None) return RunStatus::NeedSync;
  if (st_.ended && started_) return RunStatus::Finished;
  try {
    if (!started_) start();
    const bool more = (this->*body)();
    if (sync_.pending() != SyncKind::None) return RunStatus::NeedSync;
    return more ? RunStatus::Ok : RunStatus::Finished;
  } catch (const GcodeError& e) {
    report(e);
    failed_ = true;
    return RunStatus::Error;
  }
}

void Engine::require_program() {
  if (!has_program_ && !failed_) {
    diags_.error("", 0, 0, "no program is open", std::string(error_id(ErrorCode::NoProgram)));
    failed_ = true;
  }
}

RunStatus Engine::step(canon::Sink& sink) {
  require_program();
  return guarded(sink, &Engine::step_block);
}

RunStatus Engine::begin(canon::Sink& sink) { return guarded(sink, &Engine::nothing); }

RunStatus Engine::run(canon::Sink& sink) {
  require_program();
  return guarded(sink, &Engine::run_blocks);
}

RunStatus Engine::run_some(canon::Sink& sink, std::uint64_t max_blocks) {
  require_program();
  block_budget_ = max_blocks;
  return guarded(sink, &Engine::run_budget);
}

// run_blocks() with a budget: a caller that streams the program asks for so much at a time.
bool Engine::run_budget() {
  while (!st_.ended && block_budget_ > 0) {
    --block_budget_;
    process_line();
    if (sync_.pending() != SyncKind::None) return true;
  }
  return !st_.ended;
}

// After a sync point inside a subprogram an MDI line called: the call runs on to its return.
RunStatus Engine::mdi_continue(canon::Sink& sink) {
  mdi_.active = true;
  const RunStatus s = guarded(sink, &Engine::continue_mdi_call);
  mdi_.active = false;
  if (s == RunStatus::Error) {
    failed_ = false;
    flow_.abandon_calls();
  }
  return s == RunStatus::Finished ? RunStatus::Ok : s;
}

bool Engine::step_block() {
  if (st_.ended) return false;
  process_line();
  return !st_.ended;
}

// What run() does: step_block() until the end or a sync point, inside one guarded() (whose
// checks a step repeats for every block).
bool Engine::run_blocks() {
  while (!st_.ended) {
    process_line();
    if (sync_.pending() != SyncKind::None) return true;
  }
  return false;
}

RunStatus Engine::mdi(std::string_view line, canon::Sink& sink) {
  if (!mdi_.registered) {
    mdi_.file = sources_->add_file("<mdi>");
    mdi_.registered = true;
  }
  mdi_.line.assign(line);
  mdi_.active = true;
  st_.ended = false;   // MDI also works after a program end
  const RunStatus s = guarded(sink, &Engine::process_line);
  mdi_.active = false;
  if (s == RunStatus::Error) {   // an MDI error does not end the session
    failed_ = false;
    flow_.abandon_calls();
  }
  return s == RunStatus::Finished ? RunStatus::Ok : s;
}

ParseEnv Engine::parse_env() const noexcept {
  ParseEnv env;
  env.parameters = st_.parameters.data();
  env.host = const_cast<ParameterHost*>(&params_);
  env.letters = letters_;
  env.mapped_away = mapped_away_;
  env.lathe_diameter = st_.modal.lathe_diameter;
  env.comp_on = st_.modal.cutter_comp != CutterComp::Off;
  env.call_level = static_cast<int>(st_.frames.size()) - 1;
  env.call_sub = st_.frames.back().sub;
  env.defining_sub = st_.control.defining_sub;
  env.defining_name = st_.control.defining_name;
  env.skipping_to = st_.control.skipping_to;
  env.syntax = dialect_.syntax;
  env.ext = ext_;
  env.vacant = &st_.fanuc.vacant;
  return env;
}

// Reads the next line into line_.raw/line_.norm; false at the end of the file.
bool Engine::read_line() {
  update_position_parameters();
  if (mdi_.active) {
    line_.file = mdi_.file;
    line_.number = 1;
    line_.offset = 0;
    line_.raw.assign(trim_raw_line(mdi_.line));
    if (mdi_.line.size() > kMaxLineLength) line_too_long();
    return true;
  }
  SourceFile& f = current_file();
  if (need_seek_) {
    f.seek(st_.next.offset);
    need_seek_ = false;
  }
  RawLine line;
  if (!f.next(line)) return false;
  line_.file = st_.next.file;
  line_.number = st_.next.line;
  line_.offset = line.offset;
  st_.next.offset = f.tell();
  ++st_.next.line;
  line_.raw.assign(trim_raw_line(line.text));
  if (line.text.size() + (line.newline ? 1 : 0) > kMaxLineLength) line_too_long();
  return true;
}

// Points at the first character beyond the limit.
void Engine::line_too_long() const {
  throw GcodeError(ErrorCode::LineTooLong,
                   fmt::format("a line longer than {} characters: split it", kMaxLineLength - 1), -1,
                   Where{line_.file, line_.number, static_cast<std::uint32_t>(kMaxLineLength)});
}

// Written in place: an origin built on the stack and copied costs a failed store forwarding
// (a wide load of narrow stores just made) on every line.
void Engine::set_origin_from_line() {
  canon::BlockOrigin& o = out_.new_origin();
  o.file = line_.file;
  o.line = line_.number;
  o.context = st_.frames.back().context;
  std::memset(o.n_digits, 0, sizeof o.n_digits);
  std::string_view digits;
  o.n_present = leading_n_digits(line_.raw, digits);
  o.n_length = 0;
  if (o.n_present) {
    const std::size_t n = std::min(digits.size(), sizeof(o.n_digits));
    std::memcpy(o.n_digits, digits.data(), n);
    o.n_length = static_cast<std::uint8_t>(n);
  }
}

// Reads the next line into block_ (parsed and checked unless a label is being sought).
Engine::LineKind Engine::read_block() {
  if (!read_line()) {
    line_.file = st_.next.file;
    line_.number = st_.next.line;
    line_.raw.clear();
    if (dialect_.end_of_file) dialect_.end_of_file(*this);
    if (!st_.control.seeking_sub.empty()) sub_not_found();
    if (!st_.control.skipping_to.empty()) unclosed_block();
    if (st_.percent_delimited)
      fail(ErrorCode::MissingClosingPercent,
           "the file ends without the closing '%' line that its opening '%' (line 1) calls for");
    fail(ErrorCode::MissingProgramEnd,
         "the file ends without a program end: finish the program with M2 or M30");
  }
  if (line_.norm.size() < line_.raw.size() + 1) line_.norm.resize(line_.raw.size() + 1);
  set_origin_from_line();
  line_.norm_len = normalize_line(line_.raw, line_.norm.data(), dialect_.syntax.nested_comments);
  const std::string_view text(line_.norm.data(), line_.norm_len);
  if (text == "%" && dialect_.percent_line && !mdi_.active && dialect_.percent_line(*this))
    return LineKind::Empty;
  if (text == "%" && st_.percent_delimited && !mdi_.active) {
    // Nothing after the closing '%' belongs to the program, not even a subprogram (LinuxCNC).
    if (!st_.control.seeking_sub.empty()) sub_not_found();
    return LineKind::ProgramEnd;
  }
  if (text.empty() || (text.front() == '/' && opt_.block_delete)) return LineKind::Empty;
  const bool foreign_start = text.front() == '$' || text.front() == '%';  // tested first: most lines are not
  if (foreign_start && dialect_.foreign_syntax != nullptr) dialect_.foreign_syntax(*this);

  const bool skipping = !st_.control.skipping_to.empty();
  bounds_.count(opt_, skipping, st_.blocks_executed);
  if (!skipping && foreign_start && dialect_.foreign_syntax == nullptr)
    reject_foreign_syntax(text);
  parser_.parse(text, parse_env(), block_);
  if (dialect_.translate) dialect_.translate(*this);
  if (!skipping) {
    checks_.enhance_block();
    checks_.check_block();
  }
  return LineKind::Block;
}

Engine::LineKind Engine::next_block() {
  return read_block();
}

// Reads and executes one line. Returns when the line is done (or the program ended).
bool Engine::process_line() {
  switch (read_block()) {
    case LineKind::ProgramEnd:
      out_.finish();
      st_.ended = true;
      return false;
    case LineKind::Empty: return true;
    case LineKind::Block: break;
  }
  if (block_.o_type != OWord::None) {
    if (mdi_.active && block_.o_type != OWord::Call && block_.o_type != OWord::MacroCall &&
        block_.o_type != OWord::M98)
      fail(ErrorCode::OwordInMdi,
           "only 'call' O-words and subprogram calls can be used in MDI: control flow needs a program file");
    flow_.control_flow();
    if (dialect_.block_done && block_.o_type != OWord::BlockRange) dialect_.block_done(*this, true);
    if (mdi_.active) finish_mdi_call();
    return true;
  }
  if (!st_.control.skipping_to.empty()) return true;
  const DialectHooks& dialect = dialect_;
  if (dialect.assignments != nullptr) {
    dialect.assignments(*this);
  } else {
    apply_assignments();
  }
  execute_block();
  if (dialect.block_done != nullptr) {
    dialect.block_done(*this, false);
    if (mdi_.active) finish_mdi_call();
  }
  sync_.end_of_block(st_);
  return true;
}

// An MDI line that called a subprogram runs it to the end before returning.
void Engine::finish_mdi_call() {
  while (st_.frames.size() > 1 && !failed_ && !st_.ended && sync_.pending() == SyncKind::None) {
    mdi_.active = false;
    process_line();
    mdi_.active = true;
  }
}

// --- errors -------------------------------------------------------------------------------

// Program headers and commands of other controllers, which no line of this dialect starts
// with: named, so that the reader knows the file is not LinuxCNC G-code at all.
void Engine::reject_foreign_syntax(std::string_view text) const {
  std::string_view raw = line_.raw;
  raw.remove_prefix(std::min(raw.size(), raw.find_first_not_of(" \t")));
  const std::string_view token = raw.substr(0, raw.find_first_of(" \t(;"));
  auto foreign = [&](std::string_view what) {
    fail_at(0, ErrorCode::DialectUnsupported, "'{}' is {}, not G-code of the LinuxCNC dialect", token, what);
  };
  if (text.front() == '%') {
    if (text.size() == 1 || text[1] == '(' || text[1] == ';') return;  // the parser judges a lone '%'
    if (text.starts_with("%_n_")) foreign("a Siemens Sinumerik program header");
    foreign("the program header of another controller");
  }
  const char next = text.size() > 1 ? text[1] : '\0';
  std::size_t digits = 1;
  while (digits < text.size() && text[digits] >= '0' && text[digits] <= '9') ++digits;
  if (text.back() == '%' && next >= 'a' && next <= 'z') foreign("an Okuma OSP program header");
  if ((next >= 'a' && next <= 'z') || next == '$' || next == '#') foreign("a grbl command");
  if (digits > 1 && digits < text.size() && text[digits] == '=') foreign("a grbl setting");
}

// The file ended while a call looked for its subprogram: the error belongs to the call.
void Engine::sub_not_found() {
  const std::string& name = st_.control.seeking_sub;
  const std::string searched = sources_->file(st_.next.file);
  const canon::SourceRef call = sources_->context_info(st_.frames.back().context).call_site;
  const bool own_file = call.file == st_.next.file;
  const bool m98 = st_.frames.back().kind == CallKind::Numbered;
  std::string message;
  if (m98) {
    message = own_file ? fmt::format(
                             "M98 P{}: no O{} line follows in this program, and no {}.ngc is on the "
                             "subroutine path (a numbered subprogram comes after its first call)",
                             name, name, name)
                       : fmt::format("M98 P{}: {} has no O{} line", name, searched, name);
  } else {
    message = own_file ? fmt::format(
                             "o<{}> call: no 'o<{}> sub' follows in this file, and no {}.ngc is on the "
                             "subroutine path",
                             name, name, name)
                       : fmt::format("o<{}> call: {} does not define o<{}> (its sub line must name it)", name,
                                     searched, name);
  }
  throw GcodeError(ErrorCode::OwordSubNotFound, message, -1, Where{call.file, call.line, call.col});
}

// The file ended while passing over a block to its end label: the block was never closed.
void Engine::unclosed_block() {
  const std::string& key = st_.control.skipping_to;
  const LabelInfo* l = flow_.find_label(key);
  if (l == nullptr)
    fail(ErrorCode::OwordUnclosed, "the file ends inside an O-word block that is never closed");
  const char* kind = label_kind_name(l->kind);
  const std::string label = label_text(key);
  // The column of the opening line: its first word (re-read from the file; the run is over).
  std::uint32_t col = 0;
  if (l->at.file == st_.next.file) {
    SourceFile& f = current_file();
    f.seek(l->at.offset);
    need_seek_ = true;
    if (RawLine opening; f.next(opening)) {
      const std::size_t first = opening.text.find_first_not_of(" \t");
      col = first == std::string_view::npos ? 1 : static_cast<std::uint32_t>(first + 1);
    }
  }
  throw GcodeError(ErrorCode::OwordUnclosed,
                   fmt::format("'{} {}' is never closed: the file ends before '{} {}'", label, kind, label,
                               label_end_keyword(l->kind)),
                   -1, Where{l->at.file, l->at.line, col});
}

void Engine::report(const GcodeError& e) {
  std::uint32_t file_index = line_.file;
  std::uint32_t line = line_.number;
  std::uint32_t col = 0;
  if (const auto& w = e.where()) {
    file_index = w->file;
    line = w->line;
    col = w->col;
  } else if (e.position() >= 0) {
    col = raw_column(line_.raw, e.position(), dialect_.syntax.nested_comments);
  } else {
    const std::size_t first = line_.raw.find_first_not_of(" \t");
    col = first == std::string::npos ? 1 : static_cast<std::uint32_t>(first + 1);
  }
  const std::string file = file_index < sources_->file_count() ? sources_->file(file_index) : std::string();
  diags_.error(file, line, line == 0 ? 0 : col, e.message(), std::string(error_id(e.code())));
}

void Engine::warn_once(bool& done, ErrorCode code, std::string_view message) {
  if (done) return;
  done = true;
  const std::size_t first = line_.raw.find_first_not_of(" \t");
  const auto col = first == std::string::npos ? 1u : static_cast<std::uint32_t>(first + 1);
  const std::string file = line_.file < sources_->file_count() ? sources_->file(line_.file) : std::string();
  diags_.warning(file, line_.number, col, std::string(message), std::string(error_id(code)));
}

// --- sync points --------------------------------------------------------------------------

void Engine::request_sync(const SyncValues& assumed) {
  sync_.ask(assumed, opt_.mode);
}

void Engine::sync(const SyncValues& values) {
  const SyncPoints::Answer answer = sync_.answer(values, st_);
  if (answer == SyncPoints::Answer::Done) return;
  // The probe block is still the current line: the error points at it. LinuxCNC's words for it.
  report(GcodeError(ErrorCode::ProbeNoContact, answer == SyncPoints::Answer::NoContact
                                                   ? "G38.2 move finished without making contact"
                                                   : "G38.4 move finished without breaking contact"));
  failed_ = true;
}

void Engine::request_stop_sync() {
  SyncValues stop;
  stop.kind = SyncKind::ProgramStop;
  request_sync(stop);
}

// The machine's axes, mm → the program's letters and units, then every offset off.
Pose Engine::program_position(const Pose& machine_mm) const {
  const double unit = canon::mm_per_unit(st_.modal.units);
  Pose m;
  for (int i = 0; i < kAxisCount; ++i) {
    const double v = machine_mm[opt_.axis_map[static_cast<std::size_t>(i)]];
    const bool linear = i < 3 || i >= 6;
    m[i] = linear ? v / unit : v;
  }
  return offsets_.machine_to_program(m);
}

void Engine::set_machine_position(const Pose& machine_mm) {
  if (st_.modal.cutter_comp != CutterComp::Off) return;  // it cannot have moved under compensation
  const Pose p = program_position(machine_mm);
  st_.position.current = p;
  st_.position.canon_position = p;
}

void Engine::set_tool_table(const std::shared_ptr<const tools::ToolTable>& table) {
  auto& t = st_.tool.table;
  t.resize(1);
  if (table) {
    for (const auto& e : table->entries()) t.push_back(e);
  }
  // The spindle's entry follows its tool's new values (a tool measured while the program waited).
  const int index = st_.tool.current_index;
  if (index > 0 && static_cast<std::size_t>(index) < t.size() && t[static_cast<std::size_t>(index)].tool == t[0].tool)
    t[0] = t[static_cast<std::size_t>(index)];
  opt_.tool_table = table;
  mcodes_.set_tool_parameters();
}

Engine::SavedLine Engine::save_line() {
  // The block's comment views the old buffer: it moves out with it.
  std::vector<char> norm = std::exchange(line_.norm, std::vector<char>(line_.norm.size()));
  CurrentLine line{line_.number, line_.file, line_.offset, line_.raw, std::move(norm), line_.norm_len};
  return SavedLine{block_, std::move(line), out_.origin()};
}

void Engine::restore_line(SavedLine& saved, const canon::BlockOrigin& n_from) {
  canon::BlockOrigin origin = saved.origin;
  origin.n_present = n_from.n_present;
  origin.n_length = n_from.n_length;
  std::memcpy(origin.n_digits, n_from.n_digits, sizeof origin.n_digits);
  block_ = std::move(saved.block);
  line_ = std::move(saved.line);
  out_.set_origin(origin);
}

InterpState Engine::snapshot() const {
  InterpState s = st_;
  s.segments = out_.segments();
  return s;
}

}  // namespace opencnc::gcode
