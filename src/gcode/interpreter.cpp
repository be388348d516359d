// SPDX-License-Identifier: GPL-3.0-or-later
// gcode::Interpreter: the public face of the engine.
#include "opencnc/gcode/interpreter.hpp"

#include "engine.hpp"

namespace opencnc::gcode {

Interpreter::Interpreter(Options options) : engine_(std::make_unique<Engine>(std::move(options))) {}
Interpreter::~Interpreter() = default;

bool Interpreter::open(const std::string& path) { return engine_->open_file(path); }
void Interpreter::open_text(std::string name, std::string text) { engine_->open_text(std::move(name), std::move(text)); }
RunStatus Interpreter::start(canon::Sink& sink) { return engine_->begin(sink); }
RunStatus Interpreter::run(canon::Sink& sink) { return engine_->run(sink); }
RunStatus Interpreter::step(canon::Sink& sink) { return engine_->step(sink); }
RunStatus Interpreter::execute_mdi(std::string_view line, canon::Sink& sink) { return engine_->mdi(line, sink); }
RunStatus Interpreter::run(canon::Sink& sink, std::uint64_t max_blocks) { return engine_->run_some(sink, max_blocks); }
RunStatus Interpreter::continue_mdi(canon::Sink& sink) { return engine_->mdi_continue(sink); }
SyncKind Interpreter::pending_sync() const noexcept { return engine_->pending_sync(); }
void Interpreter::sync(const SyncValues& values) { engine_->sync(values); }
const SyncValues& Interpreter::sync_request() const noexcept { return engine_->sync_request(); }
void Interpreter::set_machine_position(const Pose& machine_mm) { engine_->set_machine_position(machine_mm); }
Pose Interpreter::program_position(const Pose& machine_mm) const { return engine_->program_position(machine_mm); }
void Interpreter::set_tool_table(const std::shared_ptr<const tools::ToolTable>& table) {
  engine_->set_tool_table(table);
}

const char* to_string(SyncKind k) noexcept {
  switch (k) {
    case SyncKind::None:
      return "";
    case SyncKind::Probe:
      return "probe";
    case SyncKind::Input:
      return "input";
    case SyncKind::ToolChange:
      return "tool change";
    case SyncKind::ProgramStop:
      return "program stop";
  }
  return "";
}
InterpState Interpreter::state() const { return engine_->snapshot(); }
canon::SegmentId Interpreter::segments() const noexcept { return engine_->segments(); }
const Diagnostics& Interpreter::diagnostics() const noexcept { return engine_->diagnostics(); }
std::shared_ptr<canon::SourceMap> Interpreter::sources() const noexcept { return engine_->sources(); }
const Options& Interpreter::options() const noexcept { return engine_->options(); }

}  // namespace opencnc::gcode
