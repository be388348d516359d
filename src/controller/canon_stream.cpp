// SPDX-License-Identifier: GPL-3.0-or-later
// A whole canonical program (built by a generator or a test) as a stream: all there, never waiting.
#include "opencnc/canon/program_tail.hpp"
#include "opencnc/controller/program_source.hpp"

namespace opencnc::controller {

namespace {

class CanonStream final : public ProgramStream {
 public:
  CanonStream(std::shared_ptr<const canon::Program> program, const Pose& start) : program_(std::move(program)) {
    if (program_->start() != start) program_ = canon::program_tail(*program_, 0, start);
  }
  const canon::Program& program() const override { return *program_; }
  StreamState read(std::size_t /*more_moves*/) override { return StreamState::Finished; }
  StreamState state() const override { return StreamState::Finished; }
  const SyncRequest& sync_request() const override { return sync_; }
  void answer(const SyncAnswer& /*a*/) override {}
  void restart_at(const Pose& start, std::size_t from_move) override {
    program_ = canon::program_tail(*program_, from_move, start);
  }
  void release(std::size_t /*move*/, std::size_t /*action*/) override {}  // shared: it may run again
  const Diagnostics& diagnostics() const override { return diags_; }
  SourceLocation location() const override {
    return program_->empty() ? SourceLocation{} : location_of(program_->size() - 1);
  }
  SourceLocation location_of(std::size_t move) const override {
    const canon::Move& m = program_->move(move);
    return locate(program_->sources(), m.context, m.line);
  }

 private:
  std::shared_ptr<const canon::Program> program_;
  SyncRequest sync_;
  Diagnostics diags_;
};

}  // namespace

std::unique_ptr<ProgramStream> canon_stream(std::shared_ptr<const canon::Program> program, const Pose& start) {
  return std::make_unique<CanonStream>(std::move(program), start);
}

}  // namespace opencnc::controller
