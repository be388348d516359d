// SPDX-License-Identifier: GPL-3.0-or-later
// The Fanuc dialect's program flow: O-numbered programs (later in the same file or in O<n>.nc
// files on the search path), M98 and G65 calls with repeat counts, M99 returns, GOTO n and
// WHILE [..] DO m .. END m. Like LinuxCNC's O-words, all of it runs by seeking to remembered
// lines; FanucIndex says where a program's sequence numbers and loop ends are.
#include <fmt/format.h>

#include <cstdlib>

#include "engine.hpp"
#include "numeric.hpp"

namespace opencnc::gcode {

void Engine::fanuc_start() {
  if (opt_.machine != MachineKind::Lathe) return;
  // Fanuc lathes start in the ZX plane, with X as a diameter and feed per revolution (G99).
  st_.modal.plane = canon::Plane::XZ;
  out_.select_plane(canon::Plane::XZ);
  st_.modal.lathe_diameter = true;
  st_.modal.feed_mode = canon::FeedMode::UnitsPerRevolution;
  out_.set_feed_mode(0, canon::FeedMode::UnitsPerRevolution);
}

std::string Engine::fanuc_program_name(const FanucFrame& f) const {
  return f.program != 0 ? fmt::format("O{:04}", f.program) : std::string("the main program");
}

// A lone '%' line: a subprogram file's opening line is passed over; met later, the file ended
// without M99. In the main program LinuxCNC's rules apply (false).
bool Engine::fanuc_percent_line() {
  if (st_.frames.size() == 1) return false;
  const FanucFrame& f = st_.frames.back().fanuc;
  if (!f.started) return true;
  fail(ErrorCode::FanucProgramEndMissing, "{} ends at the '%' line without M99", fanuc_program_name(f));
}

void Engine::fanuc_end_of_file() {
  if (st_.frames.size() == 1) return;   // the main program: LinuxCNC's end-of-file errors
  fail(ErrorCode::FanucProgramEndMissing, "{} ends without M99 (end of {})", fanuc_program_name(st_.frames.back().fanuc),
       sources_->file(st_.next.file));
}

// An O line: the program's own number comes before its first block; any other starts the
// next program, which the running one must not fall into.
void Engine::fanuc_program_line() {
  FanucFrame& f = st_.frames.back().fanuc;
  const auto number = static_cast<std::uint32_t>(std::strtoul(block_.o_name.c_str(), nullptr, 10));
  if (!f.started) {
    if (st_.frames.size() == 1) f.program = number;
    return;
  }
  fail(ErrorCode::FanucProgramEndMissing, "O{:04} starts the next program: {} ends without M30, M02 or M99", number,
       fanuc_program_name(f));
}

void Engine::fanuc_control_flow() {
  switch (block_.o_type) {
    case OWord::Goto: return fanuc_goto(trunc_to_int(block_.o_value));
    case OWord::FanucWhile: return fanuc_while();
    case OWord::FanucEnd: return fanuc_end();
    case OWord::MacroCall: return fanuc_call(static_cast<std::uint32_t>(block_.o_value), block_.repeat, true);
    case OWord::BlockRange: return fanuc_range();
    default: return;
  }
}

const FanucIndex::Region& Engine::fanuc_region(const SourcePosition& start) {
  const FanucIndex::Region& r = fanuc_index_.region(start, source_at(start.file));
  need_seek_ = true;   // the index read the file: the next line comes from st_.next again
  return r;
}

// The first line numbered N`n` in the program that starts at `program_start`.
SourcePosition Engine::fanuc_sequence(const SourcePosition& program_start, std::int64_t n, std::string_view what) {
  const FanucIndex::Region& r = fanuc_region(program_start);
  const auto it = r.first_n.find(n);
  if (it == r.first_n.end()) {
    const FanucFrame* owner = nullptr;
    for (const CallFrame& c : st_.frames) {
      if (c.fanuc.body == program_start) owner = &c.fanuc;
    }
    fail(ErrorCode::FanucGotoTargetMissing, "{}{}: no block is numbered N{} in {}", what, n, n,
         owner != nullptr ? fanuc_program_name(*owner) : std::string("the program"));
  }
  return it->second;
}

void Engine::fanuc_goto(std::int64_t n) {
  const SourcePosition to = fanuc_sequence(st_.frames.back().fanuc.body, n, "GOTO ");
  // Loops the jump leaves are over (GOTO may leave loops, not enter them).
  auto& loops = st_.frames.back().fanuc.loops;
  while (!loops.empty() && !(loops.back().start.offset <= to.offset && to.offset < loops.back().after_end.offset))
    loops.pop_back();
  count_loop();
  jump_to(to);
}

void Engine::fanuc_while() {
  const SourcePosition here{line_file_, line_offset_, line_};
  const int id = block_.loop_id;
  auto& loops = st_.frames.back().fanuc.loops;
  if (!loops.empty() && loops.back().start == here) loops.pop_back();   // a GOTO back to its own WHILE
  const FanucIndex::Region& r = fanuc_region(st_.frames.back().fanuc.body);
  const FanucIndex::LoopMark* end = nullptr;
  for (const FanucIndex::LoopMark& m : r.loops) {
    if (m.end && m.id == id && m.at.file == here.file && m.at.offset > here.offset) {
      end = &m;
      break;
    }
  }
  if (end == nullptr)
    fail(ErrorCode::FanucDoWithoutEnd, "DO {} is never closed: no END {} follows it in {}", id, id,
         fanuc_program_name(st_.frames.back().fanuc));
  if (block_.o_value == 0.0) {
    jump_to(end->after);
    return;
  }
  for (const FanucLoop& outer : loops) {
    if (outer.id == id)
      fail(ErrorCode::FanucLoopStructure, "DO {} inside the DO {} of line {}: nested loops need different numbers", id, id,
           outer.start.line);
    if (end->after.offset > outer.after_end.offset)
      fail(ErrorCode::FanucLoopStructure, "DO {} ends (line {}) after the END {} of the loop around it: loops must nest", id,
           end->at.line, outer.id);
  }
  loops.push_back({id, here, end->after});
}

void Engine::fanuc_end() {
  const int id = block_.loop_id;
  auto& loops = st_.frames.back().fanuc.loops;
  std::size_t k = loops.size();
  while (k > 0 && loops[k - 1].id != id) --k;
  if (k == 0) fail(ErrorCode::FanucEndWithoutDo, "END {} without a running WHILE [..] DO {}", id, id);
  const FanucLoop loop = loops[k - 1];
  if (loop.after_end.file != st_.next.file || loop.after_end.offset != st_.next.offset)
    fail(ErrorCode::FanucLoopStructure, "END {} on line {} does not close the DO {} of line {}", id, line_, id,
         loop.start.line);
  loops.resize(k - 1);   // the loop and any left inside it by a GOTO
  count_loop();
  jump_to(loop.start);   // its WHILE decides whether it runs again
}

// M98 P (count = L or the Fanuc 0 form's leading digits) and G65 P L (macro = true: the
// block's arguments become the macro's local variables #1..#26, the others vacant).
void Engine::fanuc_call(std::uint32_t program, int count, bool macro) {
  if (count <= 0) return;   // L0: the program is not run
  if (opt_.limits.max_repeat_count != 0 && static_cast<std::uint64_t>(count) > opt_.limits.max_repeat_count)
    fail(ErrorCode::LimitRepeatCount, "L{} is more than {} (limit max_repeat_count)", count, opt_.limits.max_repeat_count);
  const auto depth = static_cast<std::uint32_t>(st_.frames.size());
  const std::uint32_t max_depth = opt_.limits.max_call_depth == 0 ? 10 : opt_.limits.max_call_depth;
  if (depth >= max_depth)
    fail(ErrorCode::LimitCallDepth, "O{:04} called deeper than {} levels (limit max_call_depth)", program, max_depth - 1);
  const SourcePosition at = fanuc_find_program(program);
  CallFrame frame;
  frame.sub = fmt::format("O{:04}", program);
  frame.return_to = st_.next;
  frame.fanuc.body = at;
  frame.fanuc.program = program;
  frame.fanuc.repeats_left = static_cast<std::uint32_t>(count - 1);
  frame.fanuc.macro = macro;
  if (macro) {
    auto& vacant = st_.fanuc.vacant;
    for (std::size_t i = 1; i <= kFanucLocalCount; ++i) {
      frame.fanuc.saved_locals[i - 1] = st_.parameters[i];
      frame.fanuc.saved_vacant[i] = vacant[i];
      const bool given = i <= 26 && ((block_.arg_given >> (i - 1)) & 1u) != 0;
      st_.parameters[i] = given ? block_.args[i - 1] : 0.0;
      vacant[i] = !given;
    }
  }
  const std::uint32_t parent = st_.frames.back().context;
  frame.context = sources_->context(parent, canon::SourceRef{line_file_, line_, 1}, at.file, frame.sub);
  st_.frames.push_back(std::move(frame));
  jump_to(at);
}

// G70 P Q (finishing): the blocks numbered P to Q of this program run as written (their F,
// S, T and compensation included), then the tool goes back to where G70 started and the
// program continues after the G70 block.
void Engine::fanuc_range() {
  const FanucFrame& caller = st_.frames.back().fanuc;
  // Saturated: a number past the int range names no block and fails as a missing target.
  const std::int64_t first = trunc_to_int(block_.args[0]), last = trunc_to_int(block_.args[1]);
  const SourcePosition from = fanuc_sequence(caller.body, first, "G70 P");
  const SourcePosition to = fanuc_sequence(caller.body, last, "G70 Q");
  if (to.file != from.file || to.offset < from.offset)
    fail(ErrorCode::FanucGotoTargetMissing, "G70 P{} Q{}: block N{} comes before N{}", first, last, last, first);
  const auto depth = static_cast<std::uint32_t>(st_.frames.size());
  const std::uint32_t max_depth = opt_.limits.max_call_depth == 0 ? 10 : opt_.limits.max_call_depth;
  if (depth >= max_depth) fail(ErrorCode::LimitCallDepth, "G70 nested deeper than {} levels (limit max_call_depth)", max_depth - 1);
  if ((block_.arg_given & 4u) != 0) {
    st_.modal.feed_rate = block_.args[2];
    out_.set_feed_rate(block_.args[2]);
  }
  CallFrame frame;
  frame.sub = "G70";
  frame.return_to = st_.next;
  frame.fanuc = FanucFrame{};
  frame.fanuc.body = caller.body;
  frame.fanuc.program = caller.program;
  frame.fanuc.started = true;
  frame.fanuc.range = true;
  frame.fanuc.range_end = to;
  frame.fanuc.range_return = st_.position.current;
  frame.context = sources_->context(st_.frames.back().context, canon::SourceRef{line_file_, line_, 1}, from.file, "G70");
  st_.frames.push_back(std::move(frame));
  jump_to(from);
}

// True when the lines from `from` up to `to` (same file, `to` not before `from`) hold
// nothing but blanks and comments.
bool Engine::only_comments_between(const SourcePosition& from, const SourcePosition& to) {
  if (from.file != to.file || to.offset < from.offset) return false;
  SourceFile& f = source_at(from.file);
  f.seek(from.offset);
  need_seek_ = true;
  RawLine l;
  while (f.next(l) && l.offset < to.offset) {
    int depth = 0;
    for (const char c : l.text) {
      if (c == '(') ++depth;
      else if (c == ')' && depth > 0) --depth;
      else if (depth == 0 && c == ';') break;
      else if (depth == 0 && c != ' ' && c != '\t' && c != '\r') return false;
    }
  }
  return true;
}

// After each block: the end of a G70 run.
void Engine::fanuc_block_done() {
  if (st_.frames.size() < 2) return;
  const FanucFrame& f = st_.frames.back().fanuc;
  if (!f.range || line_file_ != f.range_end.file || line_offset_ != f.range_end.offset) return;
  emit_straight(true, f.range_return);
  jump_to(st_.frames.back().return_to);
  leave_frame();
}

// M99: the next run of an M98 L / G65 L repeat, or back to the caller (to its block N P with
// a P word). In the main program Fanuc starts the program again (or at N P); a scan, which
// must end, runs it once.
void Engine::fanuc_return() {
  const auto target = static_cast<std::int64_t>(fanuc_p_ >= 0 ? round_to_int(fanuc_p_) : -1);
  if (st_.frames.size() == 1) {
    FanucFrame& f = st_.frames.front().fanuc;
    const SourcePosition to = target > 0 ? fanuc_sequence(f.body, target, "M99 P") : f.body;
    if (opt_.mode == Mode::Scan) {
      out_.comment("fanuc: M99 ends the main program here; on the machine it runs again");
      end_program(2);
      return;
    }
    f.loops.clear();
    f.started = target > 0;
    count_loop();
    jump_to(to);
    return;
  }
  FanucFrame& f = st_.frames.back().fanuc;
  if (f.repeats_left > 0) {
    --f.repeats_left;
    f.loops.clear();
    f.started = false;
    jump_to(f.body);
    return;
  }
  if (f.macro) {
    auto& vacant = st_.fanuc.vacant;
    for (std::size_t i = 1; i <= kFanucLocalCount; ++i) {
      st_.parameters[i] = f.saved_locals[i - 1];
      vacant[i] = f.saved_vacant[i];
    }
  }
  SourcePosition to = st_.frames.back().return_to;
  if (target > 0) to = fanuc_sequence(st_.frames[st_.frames.size() - 2].fanuc.body, target, "M99 P");
  leave_frame();
  auto& loops = st_.frames.back().fanuc.loops;
  while (!loops.empty() && !(loops.back().start.offset <= to.offset && to.offset < loops.back().after_end.offset))
    loops.pop_back();
  jump_to(to);
}

// Where O`program` starts: a program line in the file being read or in the main program's
// file, or a file O<program>.nc on the subroutine path.
SourcePosition Engine::fanuc_find_program(std::uint32_t program) {
  for (const std::uint32_t file : {line_file_, st_.frames.front().fanuc.body.file}) {
    if (file >= files_.size() || (in_mdi_file_ && file == mdi_file_)) continue;   // MDI lines: no file
    const auto& programs = fanuc_index_.programs(file, source_at(file));
    need_seek_ = true;
    for (const FanucIndex::Program& p : programs) {
      if (p.number == program) return p.at;
    }
  }
  SourcePosition at;
  if (fanuc_program_file(program, at)) return at;
  fail(ErrorCode::FanucProgramNotFound, "O{:04} is neither in this file nor in a file O{:04}.nc on the subroutine path",
       program, program);
}

bool Engine::fanuc_program_file(std::uint32_t program, SourcePosition& at) {
  if (const auto it = fanuc_programs_.find(program); it != fanuc_programs_.end()) {
    at = it->second;
    return true;
  }
  const std::string padded = fmt::format("{:04}", program), plain = std::to_string(program);
  for (const std::string& dir : opt_.subroutine_path) {
    for (const std::string& number : {padded, plain}) {
      for (const char* name : {"O{}.nc", "o{}.nc", "O{}.ngc", "o{}.ngc"}) {
        const std::string file_name = fmt::format(fmt::runtime(name), number);
        const std::string path = dir.empty() ? file_name : dir + "/" + file_name;
        auto file = SourceFile::open(path);
        if (!file) continue;
        const std::uint32_t index = sources_->add_file(path);
        if (files_.size() <= index) files_.resize(index + 1);
        files_[index] = std::move(file);
        const auto& programs = fanuc_index_.programs(index, *files_[index]);
        need_seek_ = true;
        at = {index, 0, 1};
        bool found = programs.empty();   // a file without a program line is the program
        for (const FanucIndex::Program& p : programs) {
          if (p.number == program) {
            at = p.at;
            found = true;
            break;
          }
        }
        if (!found) fail(ErrorCode::FanucProgramNotFound, "{} does not hold O{:04}", path, program);
        fanuc_programs_.emplace(program, at);
        return true;
      }
      if (padded == plain) break;
    }
  }
  return false;
}

}  // namespace opencnc::gcode
