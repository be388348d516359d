// SPDX-License-Identifier: GPL-3.0-or-later
// ExtensionContext — what the code handlers and the compensator see of one engine
// (ExecContext, extension.hpp); extension_context.cpp.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <string_view>

#include "opencnc/gcode/extension.hpp"

namespace opencnc::gcode {

class Engine;

/// The engine's ExecContext. Reaches the engine's state through `e_` (a friend of the engine).
/// Interpreter thread.
class ExtensionContext final : public ExecContext {
 public:
  explicit ExtensionContext(Engine& e) noexcept : e_(e) {}
  ExtensionContext(const ExtensionContext&) = delete;
  ExtensionContext& operator=(const ExtensionContext&) = delete;

  InterpState& state() override;
  const Options& options() const override;
  Pose end_point(const Block& block) override;
  canon::Sink& output() override;
  void straight(bool rapid, const Pose& end) override;
  void arc(const canon::ArcFeed& arc) override;
  ArcCentre arc_centre(const Block& block, int motion, const Pose& start, const Pose& end) override;
  void programmed_move(int motion, const Block& words) override;
  void read_subprogram(const std::string& name, std::uint32_t extra_letters,
                       const std::function<void(const Block&)>& visit) override;
  void read_block_range(std::int64_t first, std::int64_t last, std::string_view what,
                        const std::function<void(const Block&)>& visit) override;
  void open_queue() override;
  void flush_queue() override;
  std::size_t queued() const override;
  void move_queued_end(canon::Plane plane, double first, double second) override;
  void request_sync(const SyncValues& assumed) override;
  [[noreturn]] void error(ErrorCode code, const std::string& message) override;

 private:
  Engine& e_;
};

}  // namespace opencnc::gcode
