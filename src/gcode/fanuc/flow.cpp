// SPDX-License-Identifier: GPL-3.0-or-later
// The Fanuc dialect's program flow: O-numbered programs (later in the same file or in O<n>.nc
// files on the search path), M98 and G65 calls with repeat counts, M99 returns, GOTO n and
// WHILE [..] DO m .. END m. Like LinuxCNC's O-words, all of it runs by seeking to remembered
// lines; FanucIndex says where a program's sequence numbers and loop ends are.
#include <fmt/format.h>

#include <cstdlib>

#include "dialect.hpp"
#include "numeric.hpp"

namespace opencnc::gcode {

void FanucDialect::start() {
  if (e_.opt_.machine != MachineKind::Lathe) return;
  // Fanuc lathes start in the ZX plane, with X as a diameter and feed per revolution (G99).
  e_.st_.modal.plane = canon::Plane::XZ;
  e_.out_.select_plane(canon::Plane::XZ);
  e_.st_.modal.lathe_diameter = true;
  e_.st_.modal.feed_mode = canon::FeedMode::UnitsPerRevolution;
  e_.out_.set_feed_mode(0, canon::FeedMode::UnitsPerRevolution);
}

std::string FanucDialect::program_name(const FanucFrame& f) const {
  return f.program != 0 ? fmt::format("O{:04}", f.program) : std::string("the main program");
}

// A lone '%' line: a subprogram file's opening line is passed over; met later, the file ended
// without M99. In the main program LinuxCNC's rules apply (false).
bool FanucDialect::percent_line() {
  if (e_.st_.frames.size() == 1) return false;
  const FanucFrame& f = e_.st_.frames.back().fanuc;
  if (!f.started) return true;
  fail(ErrorCode::FanucProgramEndMissing, "{} ends at the '%' line without M99", program_name(f));
}

void FanucDialect::end_of_file() {
  if (e_.st_.frames.size() == 1) return;  // the main program: LinuxCNC's end-of-file errors
  fail(ErrorCode::FanucProgramEndMissing, "{} ends without M99 (end of {})",
       program_name(e_.st_.frames.back().fanuc), e_.sources_->file(e_.st_.next.file));
}

// An O line: the program's own number comes before its first block; any other starts the
// next program, which the running one must not fall into.
void FanucDialect::program_line() {
  FanucFrame& f = e_.st_.frames.back().fanuc;
  const auto number = static_cast<std::uint32_t>(std::strtoul(e_.block_.o_name.c_str(), nullptr, 10));
  if (!f.started) {
    if (e_.st_.frames.size() == 1) f.program = number;
    return;
  }
  fail(ErrorCode::FanucProgramEndMissing, "O{:04} starts the next program: {} ends without M30, M02 or M99",
       number, program_name(f));
}

void FanucDialect::control_flow() {
  switch (e_.block_.o_type) {
    case OWord::Program:
      return program_line();
    case OWord::Goto:
      return go_to(trunc_to_int(e_.block_.o_value));
    case OWord::FanucWhile:
      return while_do();
    case OWord::FanucEnd:
      return end_do();
    case OWord::MacroCall:
      return call(static_cast<std::uint32_t>(e_.block_.o_value), e_.block_.repeat, true);
    case OWord::BlockRange:
      return range();
    default:
      return;
  }
}

const FanucIndex::Region& FanucDialect::region(const SourcePosition& start) {
  const FanucIndex::Region& r = index_.region(start, e_.source_at(start.file));
  e_.need_seek_ = true;  // the index read the file: the next line comes from st_.next again
  return r;
}

// The first line numbered N`n` in the program that starts at `program_start`.
SourcePosition FanucDialect::sequence(const SourcePosition& program_start, std::int64_t n,
                                      std::string_view what) {
  const FanucIndex::Region& r = region(program_start);
  const auto it = r.first_n.find(n);
  if (it == r.first_n.end()) {
    const FanucFrame* owner = nullptr;
    for (const CallFrame& c : e_.st_.frames) {
      if (c.fanuc.body == program_start) owner = &c.fanuc;
    }
    fail(ErrorCode::FanucGotoTargetMissing, "{}{}: no block is numbered N{} in {}", what, n, n,
         owner != nullptr ? program_name(*owner) : std::string("the program"));
  }
  return it->second;
}

void FanucDialect::go_to(std::int64_t n) {
  const SourcePosition to = sequence(e_.st_.frames.back().fanuc.body, n, "GOTO ");
  // Loops the jump leaves are over (GOTO may leave loops, not enter them).
  auto& loops = e_.st_.frames.back().fanuc.loops;
  while (!loops.empty() &&
         !(loops.back().start.offset <= to.offset && to.offset < loops.back().after_end.offset))
    loops.pop_back();
  e_.flow_.count_loop();
  e_.jump_to(to);
}

void FanucDialect::while_do() {
  const SourcePosition here{e_.line_.file, e_.line_.offset, e_.line_.number};
  const int id = e_.block_.loop_id;
  auto& loops = e_.st_.frames.back().fanuc.loops;
  if (!loops.empty() && loops.back().start == here) loops.pop_back();  // a GOTO back to its own WHILE
  const FanucIndex::Region& r = region(e_.st_.frames.back().fanuc.body);
  const FanucIndex::LoopMark* end = nullptr;
  for (const FanucIndex::LoopMark& m : r.loops) {
    if (m.end && m.id == id && m.at.file == here.file && m.at.offset > here.offset) {
      end = &m;
      break;
    }
  }
  if (end == nullptr)
    fail(ErrorCode::FanucDoWithoutEnd, "DO {} is never closed: no END {} follows it in {}", id, id,
         program_name(e_.st_.frames.back().fanuc));
  if (e_.block_.o_value == 0.0) {
    e_.jump_to(end->after);
    return;
  }
  for (const FanucLoop& outer : loops) {
    if (outer.id == id)
      fail(ErrorCode::FanucLoopStructure,
           "DO {} inside the DO {} of line {}: nested loops need different numbers", id, id,
           outer.start.line);
    if (end->after.offset > outer.after_end.offset)
      fail(ErrorCode::FanucLoopStructure,
           "DO {} ends (line {}) after the END {} of the loop around it: loops must nest", id, end->at.line,
           outer.id);
  }
  loops.push_back({id, here, end->after});
}

void FanucDialect::end_do() {
  const int id = e_.block_.loop_id;
  auto& loops = e_.st_.frames.back().fanuc.loops;
  std::size_t k = loops.size();
  while (k > 0 && loops[k - 1].id != id) --k;
  if (k == 0) fail(ErrorCode::FanucEndWithoutDo, "END {} without a running WHILE [..] DO {}", id, id);
  const FanucLoop loop = loops[k - 1];
  if (loop.after_end.file != e_.st_.next.file || loop.after_end.offset != e_.st_.next.offset)
    fail(ErrorCode::FanucLoopStructure, "END {} on line {} does not close the DO {} of line {}", id,
         e_.line_.number, id, loop.start.line);
  loops.resize(k - 1);  // the loop and any left inside it by a GOTO
  e_.flow_.count_loop();
  e_.jump_to(loop.start);  // its WHILE decides whether it runs again
}

// M98 P (count = L or the Fanuc 0 form's leading digits) and G65 P L (macro = true: the
// block's arguments become the macro's local variables #1..#26, the others vacant).
void FanucDialect::call(std::uint32_t program, int count, bool macro) {
  if (count <= 0) return;  // L0: the program is not run
  if (e_.opt_.limits.max_repeat_count != 0 &&
      static_cast<std::uint64_t>(count) > e_.opt_.limits.max_repeat_count)
    fail(ErrorCode::LimitRepeatCount, "L{} is more than {} (limit max_repeat_count)", count,
         e_.opt_.limits.max_repeat_count);
  const auto depth = static_cast<std::uint32_t>(e_.st_.frames.size());
  const std::uint32_t max_depth = e_.opt_.limits.max_call_depth == 0 ? 10 : e_.opt_.limits.max_call_depth;
  if (depth >= max_depth)
    fail(ErrorCode::LimitCallDepth, "O{:04} called deeper than {} levels (limit max_call_depth)", program,
         max_depth - 1);
  const SourcePosition at = find_program(program);
  CallFrame frame;
  frame.sub = fmt::format("O{:04}", program);
  frame.return_to = e_.st_.next;
  frame.fanuc.body = at;
  frame.fanuc.program = program;
  frame.fanuc.repeats_left = static_cast<std::uint32_t>(count - 1);
  frame.fanuc.macro = macro;
  if (macro) {
    auto& vacant = e_.st_.fanuc.vacant;
    for (std::size_t i = 1; i <= kFanucLocalCount; ++i) {
      frame.fanuc.saved_locals[i - 1] = e_.st_.parameters[i];
      frame.fanuc.saved_vacant[i] = vacant[i];
      const bool given = i <= 26 && ((e_.block_.arg_given >> (i - 1)) & 1u) != 0;
      e_.st_.parameters[i] = given ? e_.block_.args[i - 1] : 0.0;
      vacant[i] = !given;
    }
  }
  const std::uint32_t parent = e_.st_.frames.back().context;
  frame.context =
      e_.sources_->context(parent, canon::SourceRef{e_.line_.file, e_.line_.number, 1}, at.file, frame.sub);
  e_.st_.frames.push_back(std::move(frame));
  e_.jump_to(at);
}

// G70 P Q (finishing): the blocks numbered P to Q of this program run as written (their F,
// S, T and compensation included), then the tool goes back to where G70 started and the
// program continues after the G70 block.
void FanucDialect::range() {
  const FanucFrame& caller = e_.st_.frames.back().fanuc;
  // Saturated: a number past the int range names no block and fails as a missing target.
  const std::int64_t first = trunc_to_int(e_.block_.args[0]), last = trunc_to_int(e_.block_.args[1]);
  const SourcePosition from = sequence(caller.body, first, "G70 P");
  const SourcePosition to = sequence(caller.body, last, "G70 Q");
  if (to.file != from.file || to.offset < from.offset)
    fail(ErrorCode::FanucGotoTargetMissing, "G70 P{} Q{}: block N{} comes before N{}", first, last, last,
         first);
  const auto depth = static_cast<std::uint32_t>(e_.st_.frames.size());
  const std::uint32_t max_depth = e_.opt_.limits.max_call_depth == 0 ? 10 : e_.opt_.limits.max_call_depth;
  if (depth >= max_depth)
    fail(ErrorCode::LimitCallDepth, "G70 nested deeper than {} levels (limit max_call_depth)", max_depth - 1);
  if ((e_.block_.arg_given & 4u) != 0) {
    e_.st_.modal.feed_rate = e_.block_.args[2];
    e_.out_.set_feed_rate(e_.block_.args[2]);
  }
  CallFrame frame;
  frame.sub = "G70";
  frame.return_to = e_.st_.next;
  frame.fanuc = FanucFrame{};
  frame.fanuc.body = caller.body;
  frame.fanuc.program = caller.program;
  frame.fanuc.started = true;
  frame.fanuc.range = true;
  frame.fanuc.range_end = to;
  frame.fanuc.range_return = e_.st_.position.current;
  frame.context = e_.sources_->context(e_.st_.frames.back().context,
                                       canon::SourceRef{e_.line_.file, e_.line_.number, 1}, from.file, "G70");
  e_.st_.frames.push_back(std::move(frame));
  e_.jump_to(from);
}

// True when the lines from `from` up to `to` (same file, `to` not before `from`) hold
// nothing but blanks and comments.
bool FanucDialect::only_comments_between(const SourcePosition& from, const SourcePosition& to) {
  if (from.file != to.file || to.offset < from.offset) return false;
  SourceFile& f = e_.source_at(from.file);
  f.seek(from.offset);
  e_.need_seek_ = true;
  RawLine l;
  while (f.next(l) && l.offset < to.offset) {
    int depth = 0;
    for (const char c : l.text) {
      if (c == '(')
        ++depth;
      else if (c == ')' && depth > 0)
        --depth;
      else if (depth == 0 && c == ';')
        break;
      else if (depth == 0 && c != ' ' && c != '\t' && c != '\r')
        return false;
    }
  }
  return true;
}

// After each block: the end of a G70 run.
void FanucDialect::block_done() {
  if (e_.st_.frames.size() < 2) return;
  const FanucFrame& f = e_.st_.frames.back().fanuc;
  if (!f.range || e_.line_.file != f.range_end.file || e_.line_.offset != f.range_end.offset) return;
  e_.motion_.emit_straight(true, f.range_return);
  e_.jump_to(e_.st_.frames.back().return_to);
  e_.flow_.leave_frame();
}

// M99: the next run of an M98 L / G65 L repeat, or back to the caller (to its block N P with
// a P word). In the main program Fanuc starts the program again (or at N P); a scan, which
// must end, runs it once.
void FanucDialect::return_from_call() {
  const auto target = static_cast<std::int64_t>(p_ >= 0 ? round_to_int(p_) : -1);
  if (e_.st_.frames.size() == 1) {
    FanucFrame& f = e_.st_.frames.front().fanuc;
    const SourcePosition to = target > 0 ? sequence(f.body, target, "M99 P") : f.body;
    if (e_.opt_.mode == Mode::Scan) {
      e_.out_.comment("fanuc: M99 ends the main program here; on the machine it runs again");
      e_.mcodes_.end_program(2);
      return;
    }
    f.loops.clear();
    f.started = target > 0;
    e_.flow_.count_loop();
    e_.jump_to(to);
    return;
  }
  FanucFrame& f = e_.st_.frames.back().fanuc;
  if (f.repeats_left > 0) {
    --f.repeats_left;
    f.loops.clear();
    f.started = false;
    e_.jump_to(f.body);
    return;
  }
  if (f.macro) {
    auto& vacant = e_.st_.fanuc.vacant;
    for (std::size_t i = 1; i <= kFanucLocalCount; ++i) {
      e_.st_.parameters[i] = f.saved_locals[i - 1];
      vacant[i] = f.saved_vacant[i];
    }
  }
  SourcePosition to = e_.st_.frames.back().return_to;
  if (target > 0) to = sequence(e_.st_.frames[e_.st_.frames.size() - 2].fanuc.body, target, "M99 P");
  e_.flow_.leave_frame();
  auto& loops = e_.st_.frames.back().fanuc.loops;
  while (!loops.empty() &&
         !(loops.back().start.offset <= to.offset && to.offset < loops.back().after_end.offset))
    loops.pop_back();
  e_.jump_to(to);
}

// Where O`program` starts: a program line in the file being read or in the main program's
// file, or a file O<program>.nc on the subroutine path.
SourcePosition FanucDialect::find_program(std::uint32_t program) {
  for (const std::uint32_t file : {e_.line_.file, e_.st_.frames.front().fanuc.body.file}) {
    if (file >= e_.files_.size() || (e_.mdi_.registered && file == e_.mdi_.file))
      continue;  // MDI lines: no file
    const auto& programs = index_.programs(file, e_.source_at(file));
    e_.need_seek_ = true;
    for (const FanucIndex::Program& p : programs) {
      if (p.number == program) return p.at;
    }
  }
  SourcePosition at;
  if (program_file(program, at)) return at;
  fail(ErrorCode::FanucProgramNotFound,
       "O{:04} is neither in this file nor in a file O{:04}.nc on the subroutine path", program, program);
}

bool FanucDialect::program_file(std::uint32_t program, SourcePosition& at) {
  if (const auto it = programs_.find(program); it != programs_.end()) {
    at = it->second;
    return true;
  }
  const std::string padded = fmt::format("{:04}", program), plain = std::to_string(program);
  for (const std::string& dir : e_.opt_.subroutine_path) {
    for (const std::string& number : {padded, plain}) {
      for (const char* name : {"O{}.nc", "o{}.nc", "O{}.ngc", "o{}.ngc"}) {
        const std::string file_name = fmt::format(fmt::runtime(name), number);
        const std::string path = dir.empty() ? file_name : dir + "/" + file_name;
        auto file = SourceFile::open(path);
        if (!file) continue;
        const std::uint32_t index = e_.sources_->add_file(path);
        if (e_.files_.size() <= index) e_.files_.resize(index + 1);
        e_.files_[index] = std::move(file);
        const auto& programs = index_.programs(index, *e_.files_[index]);
        e_.need_seek_ = true;
        at = {index, 0, 1};
        bool found = programs.empty();  // a file without a program line is the program
        for (const FanucIndex::Program& p : programs) {
          if (p.number == program) {
            at = p.at;
            found = true;
            break;
          }
        }
        if (!found) fail(ErrorCode::FanucProgramNotFound, "{} does not hold O{:04}", path, program);
        programs_.emplace(program, at);
        return true;
      }
      if (padded == plain) break;
    }
  }
  return false;
}

}  // namespace opencnc::gcode
