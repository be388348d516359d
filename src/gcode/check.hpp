// SPDX-License-Identifier: GPL-3.0-or-later
// BlockChecks — LinuxCNC's rules for a block read, applied before anything executes: which
// motion the block performs and which words it uses (check.cpp).
#pragma once

#include <cstdint>

namespace opencnc::gcode {

class Engine;
struct Block;
class CodeHandler;

/// Completes and checks the engine's block. Reaches the engine's state through `e_` (a friend
/// of the engine). Interpreter thread.
class BlockChecks {
 public:
  explicit BlockChecks(Engine& e) noexcept : e_(e) {}
  BlockChecks(const BlockChecks&) = delete;
  BlockChecks& operator=(const BlockChecks&) = delete;

  /// The block's motion (its own or the modal one) and polar end points (LinuxCNC's
  /// enhance_block).
  void enhance_block();
  /// The rules every block meets (LinuxCNC's check_items), an extension's own checks.
  void check_block();

 private:
  // What the extension codes of a block claim (CodeHandler::Traits).
  struct ExtensionClaims {
    std::uint32_t words = 0;
    bool axis_words = false;
    bool all_words = false;
  };
  void check_g_codes();
  void check_g10();
  void check_other_codes();
  void check_p_word();
  void check_m98(const Block& b);
  void check_extension(int code, int position);  ///< `code` must have a handler
  /// The extension's handler of G code `code` (×10), nullptr if none (or code < 0).
  const CodeHandler* extension_handler(int code) const noexcept;
  void check_word_rules(const Block& b);
  void check_per_turn(const Block& b);
  ExtensionClaims extension_claims() const;

  Engine& e_;
};

}  // namespace opencnc::gcode
