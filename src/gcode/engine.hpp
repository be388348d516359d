// SPDX-License-Identifier: GPL-3.0-or-later
// Engine — the interpreter's internals: reading, checking and executing blocks. Its
// member functions are split by stage over the files of this folder (see
// docs/interpreter.md for the order a block goes through them).
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "check.hpp"
#include "control_flow.hpp"
#include "dialect_hooks.hpp"
#include "extension_context.hpp"
#include "gcode_error.hpp"
#include "line_bounds.hpp"
#include "mcodes.hpp"
#include "modal_codes.hpp"
#include "motion_codes.hpp"
#include "offsets.hpp"
#include "opencnc/canon/source_map.hpp"
#include "opencnc/core/diagnostic.hpp"
#include "opencnc/gcode/block.hpp"
#include "opencnc/gcode/extension.hpp"
#include "opencnc/gcode/interpreter.hpp"
#include "opencnc/gcode/options.hpp"
#include "opencnc/gcode/state.hpp"
#include "output.hpp"
#include "params.hpp"
#include "parser.hpp"
#include "source_file.hpp"
#include "sync_points.hpp"

namespace opencnc::gcode {

/// Axis index (0..8) of an axis word letter, -1 for other letters.
constexpr int axis_of_letter(char c) noexcept {
  switch (c) {
    case 'x': return 0; case 'y': return 1; case 'z': return 2;
    case 'a': return 3; case 'b': return 4; case 'c': return 5;
    case 'u': return 6; case 'v': return 7; case 'w': return 8;
    default: return -1;
  }
}
/// (x, y) turned by `degrees` counterclockwise about the origin (G68 rotation, motion.cpp).
void rotate_xy(double& x, double& y, double degrees) noexcept;

inline constexpr char kAxisWordLetters[kAxisCount] = {'x', 'y', 'z', 'a', 'b', 'c', 'u', 'v', 'w'};

/// "sub", "while", ... for a label kind; the keyword that ends its block; "o100" or
/// "o<name>" for a label key ("sub#100").
const char* label_kind_name(LabelKind k) noexcept;
const char* label_end_keyword(LabelKind k) noexcept;
std::string label_text(std::string_view key);

/// The line being executed: where it is, its text as read and as the parser reads it.
struct CurrentLine {
  std::uint32_t number = 0;  ///< its line number
  std::uint32_t file = 0;    ///< its file (SourceMap index)
  std::uint64_t offset = 0;  ///< its byte offset
  std::string raw;           ///< the raw line (for messages and N labels)
  std::vector<char> norm;    ///< normalised text (lower case, no spaces); norm_len chars of it
  std::size_t norm_len = 0;
};

/// The MDI line being run, and the source-map file that stands for MDI.
struct MdiInput {
  bool active = false;     ///< lines come from `line`, not from the program's files
  std::string line;        ///< the operator's line
  std::uint32_t file = 0;  ///< "<mdi>" in the source map, once `registered`
  bool registered = false;
};

class Engine final {
  // The engine's parts, each a file of this folder, reach its state as friends.
  friend class FanucDialect;  // the Fanuc dialect's hooks run the engine's lines and calls
  friend class FlowControl;
  friend class BlockChecks;
  friend class ExtensionContext;
  friend class ParameterHost;
  friend class ModalCodes;
  friend class Offsets;
  friend class MCodes;
  friend class MotionCodes;

 public:
  explicit Engine(Options options);
  ~Engine();

  // --- driving (engine.cpp) --------------------------------------------------------------
  bool open_file(const std::string& path);
  void open_text(std::string name, std::string text);
  RunStatus begin(canon::Sink& sink);
  RunStatus run(canon::Sink& sink);
  RunStatus step(canon::Sink& sink);
  RunStatus mdi(std::string_view line, canon::Sink& sink);
  RunStatus run_some(canon::Sink& sink, std::uint64_t max_blocks);
  RunStatus mdi_continue(canon::Sink& sink);
  SyncKind pending_sync() const noexcept { return sync_.pending(); }
  const SyncValues& sync_request() const noexcept { return sync_.request(); }
  void sync(const SyncValues& values);
  void set_machine_position(const Pose& machine_mm);
  Pose program_position(const Pose& machine_mm) const;
  void set_tool_table(const std::shared_ptr<const tools::ToolTable>& table);
  /// M0, M1, M60 and the stops inside cycles: in execute mode the interpreter waits for the
  /// operator's cycle start there (offsets and tools may change meanwhile).
  void request_stop_sync();
  /// The block needs machine feedback before the next one (ExecContext::request_sync).
  void request_sync(const SyncValues& assumed);
  InterpState snapshot() const;
  std::uint64_t segments() const noexcept { return out_.segments(); }
  const Diagnostics& diagnostics() const noexcept { return diags_; }
  std::shared_ptr<canon::SourceMap> sources() const noexcept { return sources_; }
  const Options& options() const { return opt_; }
  /// The dialect's own state (DialectHooks::make_state), for its hooks.
  DialectState* dialect_state() noexcept { return dialect_state_.get(); }

 private:
  // Points the errors an extension raises through error() at `at` while it runs (an outer
  // site, such as the code handler that made a move, takes precedence).
  class ExtensionSite {
   public:
    ExtensionSite(Engine& e, int at) noexcept : slot_(e.extension_at_), saved_(e.extension_at_) {
      if (slot_ == -1) slot_ = at;
    }
    ~ExtensionSite() { slot_ = saved_; }
    ExtensionSite(const ExtensionSite&) = delete;
    ExtensionSite& operator=(const ExtensionSite&) = delete;

   private:
    int& slot_;
    int saved_;
  };

  // The executing block's line, put aside while an extension reads other lines (the G7x
  // profiles) and put back afterwards with the N label `n_from` (engine.cpp).
  struct SavedLine {
    Block block;
    CurrentLine line;
    canon::BlockOrigin origin;
  };
  SavedLine save_line();
  void restore_line(SavedLine& saved, const canon::BlockOrigin& n_from);

  // engine.cpp: start, lines, errors
  void start();
  void require_program();
  RunStatus guarded(canon::Sink& sink, bool (Engine::*body)());
  bool step_block();
  bool run_blocks();
  bool run_budget();
  bool nothing() { return true; }
  bool continue_mdi_call() {
    finish_mdi_call();
    return true;
  }
  bool read_line();
  enum class LineKind : std::uint8_t { Block, Empty, ProgramEnd };
  // Inlined into its two callers in engine.cpp: as a call it cost 2-3 % of gcode_bench's
  // lines/s on the per-line path.
  [[gnu::always_inline]] inline LineKind read_block();
  LineKind next_block();  ///< read_block() out of line, for a dialect reading a block range
  bool process_line();
  void finish_mdi_call();
  void report(const GcodeError& e);
  [[noreturn]] void sub_not_found();
  [[noreturn]] void unclosed_block();
  void reject_foreign_syntax(std::string_view text) const;
  [[noreturn]] void line_too_long() const;
  void warn_once(bool& done, ErrorCode code, std::string_view message);
  void set_origin_from_line();
  SourceFile& current_file() {
    const std::uint32_t file = st_.next.file;
    return file < files_.size() && files_[file] ? *files_[file] : source_at(file);
  }
  SourceFile& source_at(std::uint32_t file);
  void jump_to(const SourcePosition& pos);
  ParseEnv parse_env() const noexcept;

  // execute.cpp: order of execution within a block
  void execute_block();
  void apply_assignments();
  void convert_g();
  bool run_extension_g(int code);
  bool run_extension_m(int code);
  [[noreturn]] void unsupported_g(int code, int at);
  void check_spindle_number(bool all_allowed) const;
  void convert_extension_groups();

  // params.cpp
  void update_position_parameters();

  Options opt_;
  const Extensions* ext_ = nullptr;
  std::uint32_t extension_groups_ = 0;   ///< bit per G group that can hold a code with a handler
  InterpState st_;
  Output out_;
  Parser parser_;
  Block block_;
  Diagnostics diags_;
  std::shared_ptr<canon::SourceMap> sources_;
  std::vector<std::unique_ptr<SourceFile>> files_;   ///< by SourceMap file index
  bool started_ = false;
  bool has_program_ = false;
  bool need_seek_ = true;
  bool failed_ = false;
  MdiInput mdi_;                    ///< the operator's line, when MDI runs
  SyncPoints sync_;                 ///< what the machine must answer, or scan mode assumes
  std::uint64_t block_budget_ = 0;  ///< run_some(): blocks left to execute
  std::uint32_t letters_ = 0;       ///< letter words with a reader (axis mask applied)
  int extension_at_ = -1;  ///< where the code of the running extension starts (its errors point there)
  std::uint32_t mapped_away_ = 0;   ///< axis letters the axis map sends to a missing axis
  LineBounds bounds_;               ///< the runaway program's limits
  CurrentLine line_;                ///< the line being executed: where, raw and normalised
  DialectHooks dialect_;  ///< chosen when the program opens (Options::dialect); a copy, read without a pointer
  std::unique_ptr<DialectState> dialect_state_;  ///< the dialect's own (null: none)
  FlowControl flow_{*this};      ///< O-words and call frames
  BlockChecks checks_{*this};    ///< LinuxCNC's checks of a block read
  ExtensionContext ctx_{*this};  ///< what the extensions see
  ParameterHost params_{*this};  ///< named parameters, the parser's host
  ModalCodes modes_{*this};      ///< modal settings
  Offsets offsets_{*this};       ///< units and coordinate transforms
  MCodes mcodes_{*this};         ///< M codes and tools
  MotionCodes motion_{*this};    ///< end points, moves, arcs
};

}  // namespace opencnc::gcode
