// SPDX-License-Identifier: GPL-3.0-or-later
// The extensions' view of the engine (ExecContext): moves through the engine's motion stage,
// the canonical output and its queue, subprograms and block ranges read for a cycle.
#include <functional>
#include <string>

#include "engine.hpp"

namespace opencnc::gcode {

InterpState& ExtensionContext::state() {
  return e_.st_;
}
const Options& ExtensionContext::options() const {
  return e_.opt_;
}
Pose ExtensionContext::end_point(const Block& block) {
  return e_.motion_.find_ends(block);
}
canon::Sink& ExtensionContext::output() {
  return e_.out_;
}
void ExtensionContext::open_queue() {
  e_.out_.open_queue();
}
void ExtensionContext::flush_queue() {
  e_.out_.flush_queue();
}
std::size_t ExtensionContext::queued() const {
  return e_.out_.queued();
}
void ExtensionContext::move_queued_end(canon::Plane plane, double first, double second) {
  e_.out_.move_queued_end(plane, first, second);
}
void ExtensionContext::request_sync(const SyncValues& assumed) {
  e_.request_sync(assumed);
}
void ExtensionContext::error(ErrorCode code, const std::string& message) {
  throw GcodeError(code, message, e_.extension_at_);
}
void ExtensionContext::straight(bool rapid, const Pose& end) {
  e_.motion_.emit_straight(rapid, end);
}
void ExtensionContext::arc(const canon::ArcFeed& a) {
  e_.motion_.emit_arc(a);
}

void ExtensionContext::programmed_move(int motion, const Block& words) {
  if (motion != 0 && motion != 10 && motion != 20 && motion != 30)
    fail(ErrorCode::Unsupported, "G{} cannot be programmed by an extension", motion / 10.0);
  // The handler's block is block_: lend block_ to the move and give it back afterwards.
  struct Restore {
    Block& target;
    Block saved;
    ~Restore() { target = std::move(saved); }
  } restore{e_.block_, e_.block_};
  e_.block_ = words;
  e_.block_.motion = motion;
  e_.motion_.convert_motion(motion);
}

void ExtensionContext::read_subprogram(const std::string& name, std::uint32_t extra_letters,
                                       const std::function<void(const Block&)>& visit) {
  // The executing block's line: the cycle's moves and errors belong to it afterwards.
  struct Modes {
    Engine& e;
    std::uint32_t letters;
    bool mdi;
    ~Modes() {  // also on errors: an MDI session goes on with the machine's letters
      e.letters_ = letters;
      e.mdi_.active = mdi;
    }
  } modes{e_, e_.letters_, e_.mdi_.active};
  Engine::SavedLine saved = e_.save_line();
  e_.letters_ |= extra_letters;
  const std::size_t depth = e_.st_.frames.size();
  e_.block_.clear();
  e_.block_.o_type = OWord::Call;
  e_.block_.o_name = name;
  e_.flow_.o_call();   // from MDI, a sub neither defined nor on the search path fails here
  e_.mdi_.active = false;  // the sub's lines come from its file, also when MDI calls the cycle
  while (e_.st_.frames.size() > depth) {
    const Engine::LineKind kind = e_.next_block();
    if (kind == Engine::LineKind::ProgramEnd)
      fail(ErrorCode::MissingProgramEnd, "the program ends inside the subprogram o<{}>", name);
    if (kind == Engine::LineKind::Empty) continue;
    if (e_.block_.o_type != OWord::None) {
      e_.flow_.control_flow();
      continue;
    }
    if (!e_.st_.control.skipping_to.empty()) continue;
    e_.apply_assignments();
    visit(e_.block_);
  }
  // rs274 labels the cycle's moves with the N word of the last line it read.
  const canon::BlockOrigin last = e_.out_.origin();
  e_.restore_line(saved, last);
}

// A dialect's block ranges (G71/G72 P Q): the program's own blocks read, not run.
void ExtensionContext::read_block_range(std::int64_t first, std::int64_t last, std::string_view what,
                                        const std::function<void(const Block&)>& visit) {
  if (!e_.dialect_.read_block_range)
    fail(ErrorCode::DialectUnsupported, "{} P Q reads numbered blocks, which this dialect does not have",
         what);
  e_.dialect_.read_block_range(e_, first, last, what, visit);
}

}  // namespace opencnc::gcode
