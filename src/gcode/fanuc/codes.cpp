// SPDX-License-Identifier: GPL-3.0-or-later
// The Fanuc dialect's M codes: M31 counts parts; M codes a machine builder defines (gear
// ranges, chip conveyors, through-spindle coolant, ...) pass as comments.
#include "codes.hpp"

#include <fmt/format.h>

#include <memory>

#include "parser.hpp"

namespace opencnc::gcode {

namespace {

constexpr int kPartsCount = 3901;  // Fanuc's parts-count variable

// M31: one more part counted (#3901), and a comment saying so; no motion, no I/O.
class PartsCounter final : public CodeHandler {
 public:
  void execute(ExecContext& ctx, const Block&, int) override {
    double& parts = ctx.state().parameters[kPartsCount];
    parts += 1.0;
    ctx.output().comment(fmt::format("fanuc: M31 parts counter: {}", parts));
  }
};

// An M code the machine builder defines: this controller has nothing to switch, so the code
// is kept visible in the output as a comment.
class MachineFunction final : public CodeHandler {
 public:
  void execute(ExecContext& ctx, const Block&, int code) override {
    ctx.output().comment(fmt::format("fanuc: M{} is a machine function (no action here)", code));
  }
};

}  // namespace

void add_fanuc_codes(Extensions& ext) {
  add_transform_codes(ext);
  add_fanuc_lathe_cycles(ext);
  add_fanuc_roughing_cycles(ext);
  auto machine = std::make_shared<MachineFunction>();
  for (int code = 0; code < 100; ++code) {
    if (m_group(code) < 0 && code != 98 && !ext.m[static_cast<std::size_t>(code)])
      ext.m[static_cast<std::size_t>(code)] = machine;
  }
  ext.m[31] = std::make_shared<PartsCounter>();
}

}  // namespace opencnc::gcode
