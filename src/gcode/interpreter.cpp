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
SyncKind Interpreter::pending_sync() const noexcept { return engine_->pending_sync(); }
void Interpreter::sync(const SyncValues& values) { engine_->sync(values); }
InterpState Interpreter::state() const { return engine_->snapshot(); }
canon::SegmentId Interpreter::segments() const noexcept { return engine_->segments(); }
const Diagnostics& Interpreter::diagnostics() const noexcept { return engine_->diagnostics(); }
std::shared_ptr<canon::SourceMap> Interpreter::sources() const noexcept { return engine_->sources(); }
const Options& Interpreter::options() const noexcept { return engine_->options(); }

}  // namespace opencnc::gcode
