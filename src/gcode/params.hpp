// SPDX-License-Identifier: GPL-3.0-or-later
// ParameterHost — the named parameters of one engine as the parser reads them: locals per call
// level, globals (#<_name>), LinuxCNC's read-only system parameters, the dialect's computed
// variables (params.cpp).
#pragma once

#include <string>
#include <string_view>

#include "parser.hpp"

namespace opencnc::gcode {

class Engine;

/// The parser's ParamHost for one engine. Reaches the engine's state through `e_` (a friend of
/// the engine). Interpreter thread.
class ParameterHost final : public ParamHost {
 public:
  explicit ParameterHost(Engine& e) noexcept : e_(e) {}
  ParameterHost(const ParameterHost&) = delete;
  ParameterHost& operator=(const ParameterHost&) = delete;

  bool named_value(std::string_view name, double& value) override;
  void declare_named(std::string_view name) override;
  bool computed_variable(int index, double& value) override;  ///< the dialect's (DialectHooks)
  /// #<name>=value once the line is read; read-only names fail.
  void store_named(const std::string& name, double value);

 private:
  bool predefined_value(std::string_view name, double& value) const;

  Engine& e_;
};

}  // namespace opencnc::gcode
